// Stage `grid_update`, contact pairs only, first of `detect`: per field
// node, the mass gradient Σ_p m_p ∇N_I(x_p) (it points out of the field's
// body) and the volume Σ_p N_I(x_p) V_p of the particles of the bodies in
// some pair (field 0 only merges, which needs no normal), scattered with
// float atomics; and the smallest half-width ½ sqrt(m_p / ρ_p) of all the
// particles (the gap test's slack), kept by atomicMin on its bits.
// `clear_grid` zeroes both.
// CPU twin: `grad` in src/cpu/contact_grad.rs (the slack: in `detect`,
// src/cpu/contact_detect.rs).
#include "shared/common.wgsl"
#include "shared/shape_bindings.wgsl" LME_ACCESS=read
#include "shared/shape.wgsl"

@group(0) @binding({{B_X0}}) var<storage, read> x0: array<vec2<f32>>;
@group(0) @binding({{B_U}}) var<storage, read> u: array<vec2<f32>>;
@group(0) @binding({{B_MASS}}) var<storage, read> mass: array<f32>;
@group(0) @binding({{B_RHO}}) var<storage, read> rho: array<f32>;
@group(0) @binding({{B_CONTACT_GRAD}}) var<storage, read_write> contact_grad: array<{{ATOMIC_T}}>;
@group(0) @binding({{B_CONTACT_SLACK}}) var<storage, read_write> contact_slack: array<atomic<u32>>;
#include "shared/atomics.wgsl" ARR=contact_grad FN=grad_add

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let p = linear_index(gid, nwg);
    if sim.running == 0u || p >= params.n_particles {
        return;
    }
    let m = mass[p];
    let vol = m / rho[p];
    // Positive floats order like their bits.
    atomicMin(&contact_slack[0], bitcast<u32>(0.5 * sqrt(vol)));
    if field[p] == 0u {
        return;
    }
    let c = shape_ctx(p, x0[p] + u[p]);
    if !shape_valid(c) {
        // p2g has reported it.
        return;
    }
    for (var r = 0u; r < SHAPE_ROWS; r++) {
        let span = shape_span(c, r);
        for (var k = span.x; k < span.y; k++) {
            let w = shape_node(c, k);
            if !w.ok {
                continue;
            }
            grad_add(3u * w.node, m * w.dn.x);
            grad_add(3u * w.node + 1u, m * w.dn.y);
            grad_add(3u * w.node + 2u, w.n * vol);
        }
    }
}
