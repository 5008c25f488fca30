// Stage `grid_update`, walls only, before `predict`: per node, the weight
// S_I = Σ_p N_Ip of the particles in contact with a wall, those whose
// (square) domain of half-width l_p = ½ sqrt(m_p / ρ_p) reaches past the
// wall's contact line: l_p (|n_x| + |n_y|) − (x_p − point)·n − offset > 0
// (a particle in contact with two walls counts twice). `wall_contact`
// reads it; `clear_grid` zeroes it. With GATES only the walls that act at
// the step's start time t (appear_at <= t < remove_at) are in contact.
// CPU twin: `wall_touch` in src/cpu/grid_update.rs.
#include "shared/common.wgsl"
#include "shared/shape_bindings.wgsl" LME_ACCESS=read
#include "shared/shape.wgsl"

@group(0) @binding({{B_X0}}) var<storage, read> x0: array<vec2<f32>>;
@group(0) @binding({{B_U}}) var<storage, read> u: array<vec2<f32>>;
@group(0) @binding({{B_MASS}}) var<storage, read> mass: array<f32>;
@group(0) @binding({{B_RHO}}) var<storage, read> rho: array<f32>;
@group(0) @binding({{B_WALLS}}) var<storage, read> walls: array<Wall>;
@group(0) @binding({{B_WALL_TOUCH}}) var<storage, read_write> wall_touch: array<{{ATOMIC_T}}>;
#include "shared/atomics.wgsl" ARR=wall_touch FN=touch_add

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let p = linear_index(gid, nwg);
    if sim.running == 0u || p >= params.n_particles {
        return;
    }
    let x = x0[p] + u[p];
    let lp = 0.5 * sqrt(mass[p] / rho[p]);
    var count = 0u;
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
        if lp * (abs(w.normal.x) + abs(w.normal.y)) - dot(x - w.point, w.normal) - w.offset > 0.0 {
            count += 1u;
        }
    }
    if count == 0u {
        return;
    }
    let c = shape_ctx(p, x);
    for (var r = 0u; r < SHAPE_ROWS; r++) {
        let span = shape_span(c, r);
        for (var k = span.x; k < span.y; k++) {
            let w = shape_node(c, k);
            if w.ok && w.n != 0.0 {
                touch_add(w.node, f32(count) * w.n);
            }
        }
    }
}
