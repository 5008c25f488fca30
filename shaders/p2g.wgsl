// Stage `p2g`: mass and (predicted) momentum to the nodes.
// NPC: q_I += N m_p (v_p + (1 − γ) Δt a_p); FE and MUSL: q_I += N m_p v_p
// (MUSL also keeps the positions at the step's start in `x_start`).
// Scatter (one invocation per particle, float atomics) or, built with
// GATHER, node-centred: one invocation per node sums over the particles
// binned near it (shared/bins.wgsl, binned in `shape_eval`) and writes its
// sums once, without atomics; or, built with PATCH, one invocation per bin
// of particles sharing a stencil sums them in registers before the
// atomics. The sums are the same, in another order.
// CPU twin: src/cpu/p2g.rs (a scatter into private grids).
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

// The velocity a particle carries to the nodes.
fn p2g_velocity(p: u32) -> vec2<f32> {
#if NPC
    return v[p] + params.p2g_accel * sim.dt * a[p];
#else
    return v[p];
#endif
}

#if GATHER
#include "shared/bins.wgsl"
@group(0) @binding({{B_CELL_START}}) var<storage, read> cell_start: array<u32>;
@group(0) @binding({{B_CELL_ORDER}}) var<storage, read> cell_order: array<u32>;
@group(0) @binding({{B_NODE_ACC}}) var<storage, read_write> node_acc: array<f32>;

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let n = linear_index(gid, nwg);
    if sim.running == 0u || n >= params.n_nodes {
        return;
    }
    let i = n % params.nx;
    let j = n / params.nx;
    let cells = cells_reaching(i, j);
    // (mass, momentum x, momentum y)
    var sum = vec3<f32>(0.0);
    for (var cj = cells.lo.y; cj <= cells.hi.y; cj++) {
        let row = cj * (params.nx - 1u);
        let end = cell_start[row + cells.hi.x + 1u];
        for (var idx = cell_start[row + cells.lo.x]; idx < end; idx++) {
            let p = cell_order[idx];
            let w = shape_at(shape_ctx(p, x0[p] + u[p]), i, j);
            if !w.ok {
                continue;
            }
            let nm = w.n * mass[p];
            let vel = p2g_velocity(p);
            sum += vec3<f32>(nm, nm * vel.x, nm * vel.y);
        }
    }
    let base = n * NODE_STRIDE;
    node_acc[base] = sum.x;
    node_acc[base + 1u] = sum.y;
    node_acc[base + 2u] = sum.z;
}
#elif PATCH
#include "shared/bins.wgsl"
@group(0) @binding({{B_CELL_START}}) var<storage, read> cell_start: array<u32>;
@group(0) @binding({{B_CELL_ORDER}}) var<storage, read> cell_order: array<u32>;
@group(0) @binding({{B_NODE_ACC}}) var<storage, read_write> node_acc: array<{{ATOMIC_T}}>;

#include "shared/atomics.wgsl" ARR=node_acc FN=node_add

// One invocation per bin: its particles share their stencil (binned by its
// anchor), so their sums go to one patch of STENCIL nodes in registers,
// then one atomic per node and component, not one per particle.
@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let b = linear_index(gid, nwg);
    if sim.running == 0u || b >= bin_count_all() {
        return;
    }
    let end = cell_start[b + 1u];
    // (mass, momentum x, momentum y) per stencil slot.
    var sum: array<vec3<f32>, STENCIL>;
    var node: array<u32, STENCIL>;
    for (var k = 0u; k < STENCIL; k++) {
        node[k] = NO_PATCH_NODE;
    }
    for (var idx = cell_start[b]; idx < end; idx++) {
        let p = cell_order[idx];
        let c = shape_ctx(p, x0[p] + u[p]);
        if !shape_valid(c) {
            continue; // reported by bin_count
        }
        let m = mass[p];
        let vel = p2g_velocity(p);
        for (var k = 0u; k < STENCIL; k++) {
            let w = shape_node(c, k);
            if !w.ok {
                continue;
            }
            node[k] = w.node;
            let nm = w.n * m;
            sum[k] += vec3<f32>(nm, nm * vel.x, nm * vel.y);
        }
    }
    for (var k = 0u; k < STENCIL; k++) {
        if node[k] == NO_PATCH_NODE {
            continue;
        }
        let base = node[k] * NODE_STRIDE;
        node_add(base, sum[k].x);
        node_add(base + 1u, sum[k].y);
        node_add(base + 2u, sum[k].z);
    }
}
#else
@group(0) @binding({{B_NODE_ACC}}) var<storage, read_write> node_acc: array<{{ATOMIC_T}}>;

#include "shared/atomics.wgsl" ARR=node_acc FN=node_add

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let p = linear_index(gid, nwg);
    if sim.running == 0u || p >= params.n_particles {
        return;
    }
    let m = mass[p];
    let vel = p2g_velocity(p);
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
#endif
