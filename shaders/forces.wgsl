// Stage `forces`: f_I += −V_p σ_p ∇N_I + N_I m_p b(t + Δt), V_p = m_p/ρ_p;
// b is gravity plus, with MMS, the manufactured solution's source term. The
// stress is already at the step's end, so are the loads.
// Scatter (one invocation per particle, float atomics) or, built with
// GATHER, node-centred: one invocation per node sums over the particles
// binned near it (shared/bins.wgsl, binned in `shape_eval`), without atomics;
// or, built with PATCH, one invocation per bin summing in registers first.
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
#include "shared/bins.wgsl"
@group(0) @binding({{B_CELL_START}}) var<storage, read> cell_start: array<u32>;
@group(0) @binding({{B_CELL_ORDER}}) var<storage, read> cell_order: array<u32>;
@group(0) @binding({{B_NODE_ACC}}) var<storage, read_write> node_acc: array<f32>;
#elif PATCH
#include "shared/bins.wgsl"
@group(0) @binding({{B_CELL_START}}) var<storage, read> cell_start: array<u32>;
@group(0) @binding({{B_CELL_ORDER}}) var<storage, read> cell_order: array<u32>;
@group(0) @binding({{B_NODE_ACC}}) var<storage, read_write> node_acc: array<{{ATOMIC_T}}>;

#include "shared/atomics.wgsl" ARR=node_acc FN=node_add
#else
@group(0) @binding({{B_NODE_ACC}}) var<storage, read_write> node_acc: array<{{ATOMIC_T}}>;

#include "shared/atomics.wgsl" ARR=node_acc FN=node_add
#endif

#include "shared/body_force.wgsl"

// The load time: MUSL takes its forces from σ^t, so the loads at t (eq. 24).
fn load_time() -> f32 {
#if MUSL
    return sim.t + sim.t_lo;
#else
    return sim.t + sim.t_lo + sim.dt;
#endif
}

#if GATHER
@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let n = linear_index(gid, nwg);
    if sim.running == 0u || n >= params.n_nodes {
        return;
    }
    let i = n % params.nx;
    let j = n / params.nx;
    let t = load_time();
    let cells = cells_reaching(i, j);
    var f = vec2<f32>(0.0);
    for (var cj = cells.lo.y; cj <= cells.hi.y; cj++) {
        let row = cj * (params.nx - 1u);
        let end = cell_start[row + cells.hi.x + 1u];
        for (var idx = cell_start[row + cells.lo.x]; idx < end; idx++) {
            let p = cell_order[idx];
            let w = shape_at(shape_ctx(p, x0[p] + u[p]), i, j);
            if !w.ok {
                continue;
            }
            let m = mass[p];
            let vol = m / rho[p];
            let s = vec3<f32>(stress[3u * p], stress[3u * p + 1u], stress[3u * p + 2u]);
            f += node_force(w, vol, s, m * body_force(p, t));
        }
    }
    node_acc[n * NODE_STRIDE + 3u] = f.x;
    node_acc[n * NODE_STRIDE + 4u] = f.y;
}
#elif PATCH
// One invocation per bin of particles sharing a stencil (p2g.wgsl's PATCH).
@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let b = linear_index(gid, nwg);
    if sim.running == 0u || b >= bin_count_all() {
        return;
    }
    let t = load_time();
    let end = cell_start[b + 1u];
    var f: array<vec2<f32>, STENCIL>;
    var node: array<u32, STENCIL>;
    for (var k = 0u; k < STENCIL; k++) {
        node[k] = NO_PATCH_NODE;
    }
    for (var idx = cell_start[b]; idx < end; idx++) {
        let p = cell_order[idx];
        let m = mass[p];
        let vol = m / rho[p];
        let s = vec3<f32>(stress[3u * p], stress[3u * p + 1u], stress[3u * p + 2u]);
        let mb = m * body_force(p, t);
        let c = shape_ctx(p, x0[p] + u[p]);
        for (var k = 0u; k < STENCIL; k++) {
            let w = shape_node(c, k);
            if !w.ok {
                continue;
            }
            node[k] = w.node;
            f[k] += node_force(w, vol, s, mb);
        }
    }
    for (var k = 0u; k < STENCIL; k++) {
        if node[k] == NO_PATCH_NODE {
            continue;
        }
        node_add(node[k] * NODE_STRIDE + 3u, f[k].x);
        node_add(node[k] * NODE_STRIDE + 4u, f[k].y);
    }
}
#else
@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let p = linear_index(gid, nwg);
    if sim.running == 0u || p >= params.n_particles {
        return;
    }
    let m = mass[p];
    let vol = m / rho[p];
    let s = vec3<f32>(stress[3u * p], stress[3u * p + 1u], stress[3u * p + 2u]);
    let b = m * body_force(p, load_time());
    let c = shape_ctx(p, x0[p] + u[p]);
    add_particle_forces(c, vol, s, b);
}
#endif
