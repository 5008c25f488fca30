// Stage `grid_update`, walls only, before `predict`: which walls each node
// touches this step. A particle whose (square) domain of half-width
// l_p = ½ sqrt(m_p / ρ_p) reaches a wall's line, (x_p − point)·n −
// l_p (|n_x| + |n_y|) ≤ WALL_TOUCH_SLACK l_p, sets the wall's bit on every node of its
// stencil (weight > 0); `predict` and `correct` apply a wall only on the
// nodes behind it that touch it. `clear_grid` zeroes the bits. With GATES
// only the walls that act at the step's start time t (appear_at <= t <
// remove_at) are touched.
// CPU twin: `wall_touch` and `touching_walls` in src/cpu/grid_update.rs.
#include "shared/common.wgsl"
#include "shared/shape_bindings.wgsl" LME_ACCESS=read
#include "shared/shape.wgsl"

@group(0) @binding({{B_X0}}) var<storage, read> x0: array<vec2<f32>>;
@group(0) @binding({{B_U}}) var<storage, read> u: array<vec2<f32>>;
@group(0) @binding({{B_MASS}}) var<storage, read> mass: array<f32>;
@group(0) @binding({{B_RHO}}) var<storage, read> rho: array<f32>;
@group(0) @binding({{B_WALLS}}) var<storage, read> walls: array<Wall>;
@group(0) @binding({{B_WALL_TOUCH}}) var<storage, read_write> wall_touch: array<atomic<u32>>;

// Keep in sync with `cpu::grid_update::WALL_TOUCH_SLACK`.
const WALL_TOUCH_SLACK: f32 = 1e-3;

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let p = linear_index(gid, nwg);
    if sim.running == 0u || p >= params.n_particles {
        return;
    }
    let x = x0[p] + u[p];
    let lp = 0.5 * sqrt(mass[p] / rho[p]);
    var bits = 0u;
#if GATES
    let t = sim.t + sim.t_lo;
#endif
    for (var k = 0u; k < arrayLength(&walls); k++) {
        let w = walls[k];
#if GATES
        if t < w.appear_at || t >= w.remove_at {
            continue;
        }
#endif
        let d = dot(x - w.point, w.normal);
        if d - lp * (abs(w.normal.x) + abs(w.normal.y)) <= WALL_TOUCH_SLACK * lp {
            bits |= 1u << k;
        }
    }
    if bits == 0u {
        return;
    }
    let c = shape_ctx(p, x);
    for (var r = 0u; r < SHAPE_ROWS; r++) {
        let span = shape_span(c, r);
        for (var k = span.x; k < span.y; k++) {
            let w = shape_node(c, k);
            if w.ok && w.n > 0.0 {
                atomicOr(&wall_touch[w.node], bits);
            }
        }
    }
}
