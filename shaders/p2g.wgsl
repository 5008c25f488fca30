// Stage `p2g`: scatter mass and (predicted) momentum with atomics.
// NPC: q_I += N m_p (v_p + (1 − γ) Δt a_p); FE and MUSL: q_I += N m_p v_p
// (MUSL also keeps the positions at the step's start in `x_start`).
// CPU twin: src/cpu/p2g.rs.
#include "shared/common.wgsl"
#include "shared/shape_bindings.wgsl" LME_ACCESS=read
#include "shared/shape.wgsl"

@group(0) @binding({{B_X0}}) var<storage, read> x0: array<vec2<f32>>;
@group(0) @binding({{B_U}}) var<storage, read> u: array<vec2<f32>>;
@group(0) @binding({{B_V}}) var<storage, read> v: array<vec2<f32>>;
#if NPC
@group(0) @binding({{B_A}}) var<storage, read> a: array<vec2<f32>>;
#endif
@group(0) @binding({{B_MASS}}) var<storage, read> mass: array<f32>;
#if MUSL
@group(0) @binding({{B_X_START}}) var<storage, read_write> x_start: array<vec2<f32>>;
#endif
@group(0) @binding({{B_NODE_ACC}}) var<storage, read_write> node_acc: array<{{ATOMIC_T}}>;

#include "shared/atomics.wgsl" ARR=node_acc FN=node_add

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let p = linear_index(gid, nwg);
    if sim.running == 0u || p >= params.n_particles {
        return;
    }
    let m = mass[p];
    var vel = v[p];
#if NPC
    vel += params.p2g_accel * sim.dt * a[p];
#endif
#if MUSL
    // The step's start positions, for the remap and the stress after g2p.
    x_start[p] = x0[p] + u[p];
#endif
    let c = shape_ctx(p, x0[p] + u[p]);
    if !shape_valid(c) {
        report_fault(FAULT_LEFT_GRID, p);
        return;
    }
    for (var k = 0u; k < STENCIL; k++) {
        let w = shape_node(c, k);
        if !w.ok {
            continue;
        }
        let nm = w.n * m;
        let base = w.node * NODE_STRIDE;
        node_add(base, nm);
        node_add(base + 1u, nm * vel.x);
        node_add(base + 2u, nm * vel.y);
    }
}
