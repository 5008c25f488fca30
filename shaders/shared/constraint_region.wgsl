// Whether node (i, j) lies in constraint c's region at time t (s): its box
// of nodes at t = 0 (i0..i1, j0..j1) shifted by the whole node spacings
// its velocity has moved it (the travel ∫ v dt on the fixed components
// over h, rounded halves up), a side on the grid's edge staying there.
// A group without velocity keeps its box. CPU twin:
// `ConstraintGroup::nodes_at` (src/model/mod.rs).
fn in_region(c: Constraint, i: u32, j: u32, t: f32) -> bool {
    var s = t;
    if c.ramp_time > 0.0 && t < c.ramp_time {
        s = t * t / (2.0 * c.ramp_time);
    } else {
        s = t - 0.5 * c.ramp_time;
    }
    var d = vec2<f32>(0.0);
    if (c.fix & 1u) != 0u {
        d.x = s * c.vx;
    }
    if (c.fix & 2u) != 0u {
        d.y = s * c.vy;
    }
    let k = vec2<i32>(floor(d * params.inv_h + 0.5));
    let lo = vec2<i32>(
        select(i32(c.i0) + k.x, 0, c.i0 == 0u),
        select(i32(c.j0) + k.y, 0, c.j0 == 0u),
    );
    let hi = vec2<i32>(
        select(i32(c.i1) + k.x, i32(params.nx) - 1, c.i1 + 1u == params.nx),
        select(i32(c.j1) + k.y, i32(params.ny) - 1, c.j1 + 1u == params.ny),
    );
    let p = vec2<i32>(i32(i), i32(j));
    return all(p >= lo) && all(p <= hi);
}
