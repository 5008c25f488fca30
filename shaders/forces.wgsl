// Stage `forces`: f_I += −V_p σ_p ∇N_I + N_I m_p b(t + Δt) with atomics,
// V_p = m_p/ρ_p; b is gravity plus, with MMS, the manufactured solution's
// source term. The stress is already at the step's end, so are the loads.
// CPU twin: src/cpu/forces.rs.
#include "shared/common.wgsl"
#include "shared/shape_bindings.wgsl" LME_ACCESS=read
#include "shared/shape.wgsl"

@group(0) @binding({{B_X0}}) var<storage, read> x0: array<vec2<f32>>;
@group(0) @binding({{B_U}}) var<storage, read> u: array<vec2<f32>>;
@group(0) @binding({{B_MASS}}) var<storage, read> mass: array<f32>;
@group(0) @binding({{B_RHO}}) var<storage, read> rho: array<f32>;
@group(0) @binding({{B_STRESS}}) var<storage, read> stress: array<f32>;
@group(0) @binding({{B_NODE_ACC}}) var<storage, read_write> node_acc: array<{{ATOMIC_T}}>;

#include "shared/atomics.wgsl" ARR=node_acc FN=node_add

#include "shared/body_force.wgsl"

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let p = linear_index(gid, nwg);
    if sim.running == 0u || p >= params.n_particles {
        return;
    }
    let m = mass[p];
    let vol = m / rho[p];
    let s = vec3<f32>(stress[3u * p], stress[3u * p + 1u], stress[3u * p + 2u]);
#if MUSL
    // MUSL: forces from σ^t, so the loads at t (eq. 24).
    let b = m * body_force(p, sim.t + sim.t_lo);
#else
    let b = m * body_force(p, sim.t + sim.t_lo + sim.dt);
#endif
    let c = shape_ctx(p, x0[p] + u[p]);
    add_particle_forces(c, vol, s, b);
}
