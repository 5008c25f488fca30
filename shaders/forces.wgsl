// Stage `forces`: f_I += −V_p σ_p ∇N_I + N_I m_p b(t + Δt), V_p = m_p/ρ_p;
// b is gravity plus, with MMS, the manufactured solution's source term. The
// stress is already at the step's end, so are the loads.
// Scatter (one invocation per particle, float atomics) or, built with
// GATHER, node-centred: one invocation per node sums over the particles
// binned near it (shared/bins.wgsl, binned in `shape_eval`), without atomics;
// or, built with PATCH, one invocation per bin summing in registers first.
// The walks are shared/bins.wgsl's; the force per node, shared/body_force.wgsl's.
// CPU twin: src/cpu/forces.rs (a scatter into private grids).
#include "shared/common.wgsl"
#include "shared/shape_bindings.wgsl" LME_ACCESS=read
#include "shared/shape.wgsl"

@group(0) @binding({{B_X0}}) var<storage, read> x0: array<vec2<f32>>;
@group(0) @binding({{B_U}}) var<storage, read> u: array<vec2<f32>>;
@group(0) @binding({{B_MASS}}) var<storage, read> mass: array<f32>;
@group(0) @binding({{B_RHO}}) var<storage, read> rho: array<f32>;
@group(0) @binding({{B_STRESS}}) var<storage, read> stress: array<f32>;

#if GATHER
@group(0) @binding({{B_NODE_ACC}}) var<storage, read_write> node_acc: array<f32>;
#else
@group(0) @binding({{B_NODE_ACC}}) var<storage, read_write> node_acc: array<{{ATOMIC_T}}>;

#include "shared/atomics.wgsl" ARR=node_acc FN=node_add
#endif

#include "shared/bins.wgsl"
#include "shared/body_force.wgsl"

#if MLS_FORCE
// solver.mls_scope = "force": the particles' part of the corrected internal
// force, −V_p (σ_p − σ_h(x_p)) ∇N_I(x_p), σ_h(x_p) from mls_fit.wgsl, in
// the integration cells whose fits are all regular (mls_occ == 1); the
// Gauss points' part is mls_force_gauss.wgsl.
#include "shared/mls.wgsl"
@group(0) @binding({{B_MLS_OCC}}) var<storage, read> mls_occ: array<u32>;
@group(0) @binding({{B_MLS_FIT}}) var<storage, read> mls_fit: array<f32>;
#endif

// The load time: MUSL takes its forces from σ^t, so the loads at t (eq. 24).
fn load_time() -> f32 {
#if MUSL
    return sim.t + sim.t_lo;
#else
    return sim.t + sim.t_lo + sim.dt;
#endif
}

fn bin_particle(p: u32, c: ShapeCtx) -> BinParticle {
    let m = mass[p];
    var s = vec3<f32>(stress[3u * p], stress[3u * p + 1u], stress[3u * p + 2u]);
#if MLS_FORCE
    let q = (x0[p] + u[p]) * params.inv_h;
    let span = mls_span_of(q.y, params.mls_spans_y) * params.mls_spans_x + mls_span_of(q.x, params.mls_spans_x);
    if mls_occ[span] == 1u {
        s -= vec3<f32>(mls_fit[6u * p], mls_fit[6u * p + 1u], mls_fit[6u * p + 2u]);
    }
#endif
    return BinParticle(true, m / rho[p], s, m * body_force(p, load_time()));
}

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
#if GATHER
    let n = linear_index(gid, nwg);
    if sim.running == 0u || n >= params.n_nodes {
        return;
    }
    let f = gather_node(n % params.nx, n / params.nx);
    node_acc[n * NODE_STRIDE + 3u] = f.x;
    node_acc[n * NODE_STRIDE + 4u] = f.y;
#elif PATCH
    scatter_bin(linear_index(gid, nwg));
#else
    let p = linear_index(gid, nwg);
    if sim.running == 0u || p >= params.n_particles {
        return;
    }
    let c = shape_ctx(p, x0[p] + u[p]);
    scatter_particle(c, bin_particle(p, c));
#endif
}
