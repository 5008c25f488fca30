// Stage `remap` of MUSL (B-spline paper eqs. 31–33), without MLS: the
// particles' new velocities back to the nodes with the weights of the
// step's start, q_I = Σ N_I(x_p^t) m_p v_p^{t+1}, into the momentum slots
// (the masses stay m_I^t); the pass `grid_update` (predict) then divides by
// the mass and applies the walls and Dirichlet conditions. Positions at the
// step's start come from `x_start` (written by p2g or bin_count), since g2p
// has moved the particles. Built with CLEAR: one invocation per node zeroes
// its momentum first (also before `mls_remap`).
// CPU twin: src/cpu/remap.rs (with MLS: `Mls::remap` in src/cpu/mls.rs).
#include "shared/common.wgsl"
#if CLEAR
@group(0) @binding({{B_NODE_ACC}}) var<storage, read_write> node_acc: array<f32>;

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = linear_index(gid, nwg);
#if CONTACT
    if sim.running == 0u || i >= field_nodes() {
        return;
    }
#else
    if sim.running == 0u || i >= params.n_nodes {
        return;
    }
#endif
    node_acc[i * NODE_STRIDE + 1u] = 0.0;
    node_acc[i * NODE_STRIDE + 2u] = 0.0;
}
#else
#include "shared/shape_bindings.wgsl" LME_ACCESS=read
#include "shared/shape.wgsl"

@group(0) @binding({{B_X_START}}) var<storage, read> x_start: array<vec2<f32>>;
@group(0) @binding({{B_V}}) var<storage, read> v: array<vec2<f32>>;
@group(0) @binding({{B_MASS}}) var<storage, read> mass: array<f32>;
@group(0) @binding({{B_NODE_ACC}}) var<storage, read_write> node_acc: array<{{ATOMIC_T}}>;

#include "shared/atomics.wgsl" ARR=node_acc FN=node_add

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let p = linear_index(gid, nwg);
    if sim.running == 0u || p >= params.n_particles {
        return;
    }
    let m = mass[p];
    let vel = v[p];
    let c = shape_ctx(p, x_start[p]);
    for (var k = 0u; k < STENCIL; k++) {
        let w = shape_node(c, k);
        if !w.ok {
            continue;
        }
        let nm = w.n * m;
        let base = w.node * NODE_STRIDE;
        node_add(base + 1u, nm * vel.x);
        node_add(base + 2u, nm * vel.y);
    }
}
#endif
