// The device's clock (src/gpu/layout.rs `Clock`): the time as an unsigned
// 64-bit count of ticks of 2^-params.tick_exp s, held as vec2<u32>(low,
// high). Integer sums cannot be reassociated by a driver, unlike a
// compensated float sum.

fn ticks_add(a: vec2<u32>, b: vec2<u32>) -> vec2<u32> {
    let lo = a.x + b.x;
    return vec2<u32>(lo, a.y + b.y + select(0u, 1u, lo < a.x));
}

// a − b for a ≥ b.
fn ticks_sub(a: vec2<u32>, b: vec2<u32>) -> vec2<u32> {
    return vec2<u32>(a.x - b.x, a.y - b.y - select(0u, 1u, a.x < b.x));
}

fn ticks_le(a: vec2<u32>, b: vec2<u32>) -> bool {
    return a.y < b.y || (a.y == b.y && a.x <= b.x);
}

// Ticks in seconds, rounded to f32.
fn ticks_seconds(v: vec2<u32>) -> f32 {
    return ldexp(f32(v.y), 32 - params.tick_exp) + ldexp(f32(v.x), -params.tick_exp);
}

// x ≥ 0 seconds in ticks, rounded to the nearest (exact when x is at least
// 2^23 ticks); saturates beyond 2^64 ticks.
fn ticks_of(x: f32) -> vec2<u32> {
    let bits = bitcast<u32>(x);
    let be = i32((bits >> 23u) & 0xffu);
    if x <= 0.0 || be == 0 {
        return vec2<u32>(0u, 0u);
    }
    let m = (bits & 0x7fffffu) | 0x800000u;
    // x = m · 2^(be − 150) s = m · 2^s ticks.
    let s = be - 150 + params.tick_exp;
    if s > 40 {
        return vec2<u32>(0xffffffffu, 0xffffffffu);
    }
    if s >= 32 {
        return vec2<u32>(0u, m << u32(s - 32));
    }
    if s > 0 {
        return vec2<u32>(m << u32(s), m >> u32(32 - s));
    }
    if s == 0 {
        return vec2<u32>(m, 0u);
    }
    if s >= -24 {
        let k = u32(-s);
        return vec2<u32>((m + (1u << (k - 1u))) >> k, 0u);
    }
    return vec2<u32>(0u, 0u);
}

// Ticks as a two-float sum hi + lo (s) for the stages that read the time.
fn ticks_split(v: vec2<u32>) -> vec2<f32> {
    let hi = ticks_seconds(v);
    // Exact: hi's spacing is at least one tick wherever it is above 2^23.
    let back = ticks_of(hi);
    if ticks_le(back, v) {
        return vec2<f32>(hi, ticks_seconds(ticks_sub(v, back)));
    }
    return vec2<f32>(hi, -ticks_seconds(ticks_sub(back, v)));
}
