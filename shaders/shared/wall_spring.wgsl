// The walls' contact spring, shared by `wall_touch.wgsl` and
// `wall_contact.wgsl` (which declare `walls` and `mass`, and include the
// shape functions), and whether a contact's friction acts on the wall's
// line (`line_weights_positive`): the normal force
// of particle p on wall k before damping, the penalty k pen 2 l_p (pen:
// how far its domain reaches past the contact line, negative once clear)
// plus, with WALL_PRELOAD, the preload of a particle that started flush
// with the wall and compressed across it:
// 2 l_p (min(τ0, −σ_nn / PRELOAD_HOLD) + ρ max(0, −g·n) d), its initial
// traction (followed down by its normal stress once that has lost more
// than 1 − PRELOAD_HOLD of it) and the
// weight of its material between its centre and the line (d:
// `wall_depth`), times 2 l_p. In contact while positive.
// CPU twins: `contact_spring` in src/cpu/wall_touch.rs and
// `preload_force` in src/model/walls.rs.
#if WALL_PRELOAD
@group(0) @binding({{B_STRESS}}) var<storage, read> stress: array<f32>;
@group(0) @binding({{B_WALL_PRELOAD}}) var<storage, read> wall_preload: array<f32>;
#endif

// How far (m) the particle's centre is in front of the wall's line,
// clamped to [0, l_p (|n_x| + |n_y|)]: where the wall's traction acts.
fn wall_depth(x: vec2<f32>, lp: f32, w: Wall) -> f32 {
    return clamp(dot(x - w.point, w.normal), 0.0, lp * (abs(w.normal.x) + abs(w.normal.y)));
}

// The share of τ0 the normal stress may lose before the preload follows
// it down (`PRELOAD_HOLD` in src/model/walls.rs: at min(τ0, −σ_nn) a body
// at rest sat on the kink and grew from round-off).
const PRELOAD_HOLD: f32 = 0.99;

// Round-off allowance of `line_weights_positive` (f32 weights of O(1)).
// Keep in sync with src/cpu/wall_touch.rs.
const LINE_WEIGHT_EPS: f32 = 1e-6;

// Whether the particle's weights at the wall's line, N − d n·∇N (d:
// `wall_depth`), are all non-negative (linear shapes while the line is in
// the particle's cell): its friction then acts on the line.
// CPU twin: `line_weights_positive` in src/cpu/wall_touch.rs.
fn line_weights_positive(c: ShapeCtx, n: vec2<f32>, d: f32) -> bool {
    var positive = true;
    for (var r = 0u; r < SHAPE_ROWS; r++) {
        let span = shape_span(c, r);
        for (var s = span.x; s < span.y; s++) {
            let nw = shape_node(c, s);
            if nw.ok && nw.n - d * dot(n, nw.dn) < -LINE_WEIGHT_EPS {
                positive = false;
            }
        }
    }
    return positive;
}

#if WALL_PRE_FIT
// Whether the preload's fit to the body's discrete reaction acts in this
// step: while every wall that stood at the start stands (with GATES, at
// the step's start time). CPU twin: `Walls::fit_at` in src/model/walls.rs.
fn pre_fit_on() -> bool {
#if GATES
    let t = sim.t + sim.t_lo;
    for (var k = 0u; k < arrayLength(&walls); k++) {
        if walls[k].appear_at <= 0.0 && t >= walls[k].remove_at {
            return false;
        }
    }
#endif
    return true;
}
#endif

// (spring force, preload) in N per unit thickness.
fn contact_spring(p: u32, k: u32, w: Wall, x: vec2<f32>, lp: f32) -> vec2<f32> {
    let pen = lp * (abs(w.normal.x) + abs(w.normal.y)) - dot(x - w.point, w.normal) - w.offset;
    var pre = 0.0;
#if WALL_PRELOAD
    let tau0 = wall_preload[p * arrayLength(&walls) + k];
    if tau0 > 0.0 {
        let n = w.normal;
        let snn = stress[3u * p] * n.x * n.x + 2.0 * stress[3u * p + 2u] * n.x * n.y
            + stress[3u * p + 1u] * n.y * n.y;
        let traction = min(tau0, max(-snn, 0.0) / PRELOAD_HOLD);
        let weight = max(-dot(params.gravity, n), 0.0);
        pre = 2.0 * lp * traction + mass[p] * weight * wall_depth(x, lp, w) / (2.0 * lp);
    }
#endif
    return vec2<f32>(w.stiffness * pen * 2.0 * lp + pre, pre);
}
