// A compensated (Kahan) sum that survives drivers which reassociate float
// arithmetic. Written plainly, `lo = ((s + y) − s) − y` is folded to 0 by
// such a driver (llvmpipe does: its "compensated" sums were plain f32
// sums, tests/gpu_shaders.rs `compensated_sums_survive_the_driver`). Here
// the new sum and its difference from the old pass through an OR with
// `zero`, a value that is 0 at run time but unknown to the compiler (a
// uniform), so neither can be rewritten through the other.

struct Kahan2 {
    sum: vec2<f32>,
    lo: vec2<f32>,
}

fn opaque2(v: vec2<f32>, zero: u32) -> vec2<f32> {
    return bitcast<vec2<f32>>(bitcast<vec2<u32>>(v) | vec2<u32>(zero));
}

// (sum − lo) + x as a new (sum, lo); the value held is sum − lo.
fn kahan_add2(sum: vec2<f32>, lo: vec2<f32>, x: vec2<f32>, zero: u32) -> Kahan2 {
    let y = x - lo;
    let t = opaque2(sum + y, zero);
    return Kahan2(t, opaque2(t - sum, zero) - y);
}
