// Stage `p2g`: mass and (predicted) momentum to the nodes.
// NPC: q_I += N m_p (v_p + (1 − γ) Δt a_p); FE and MUSL: q_I += N m_p v_p
// (MUSL also keeps the positions at the step's start in `x_start`).
// Scatter (one invocation per particle, float atomics) or, built with
// GATHER, node-centred: one invocation per node sums over the particles
// binned near it (shared/bins.wgsl, binned in `shape_eval`) and writes its
// sums once, without atomics; or, built with PATCH, one invocation per bin
// of particles sharing a stencil sums them in registers before the
// atomics. The sums are the same, in another order. The walks are
// shared/bins.wgsl's; this pass defines what a particle puts on a node.
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
@group(0) @binding({{B_NODE_ACC}}) var<storage, read_write> node_acc: array<f32>;
#else
@group(0) @binding({{B_NODE_ACC}}) var<storage, read_write> node_acc: array<{{ATOMIC_T}}>;

#include "shared/atomics.wgsl" ARR=node_acc FN=node_add

fn bin_add(node: u32, s: BinSum) {
    let base = node * NODE_STRIDE;
    node_add(base, s.x);
    node_add(base + 1u, s.y);
    node_add(base + 2u, s.z);
}
#endif

#include "shared/bins.wgsl"

// What the walks of shared/bins.wgsl sum per node: mass and momentum.
alias BinSum = vec3<f32>;

struct BinParticle {
    ok: bool,
    m: f32,
    vel: vec2<f32>,
}

fn bin_particle(p: u32, c: ShapeCtx) -> BinParticle {
    return BinParticle(shape_valid(c), mass[p], p2g_velocity(p));
}

fn bin_term(q: BinParticle, w: NodeW) -> BinSum {
    let nm = w.n * q.m;
    return vec3<f32>(nm, nm * q.vel.x, nm * q.vel.y);
}

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
#if GATHER
    let n = linear_index(gid, nwg);
    if sim.running == 0u || n >= params.n_nodes {
        return;
    }
    let sum = gather_node(n % params.nx, n / params.nx);
    let base = n * NODE_STRIDE;
    node_acc[base] = sum.x;
    node_acc[base + 1u] = sum.y;
    node_acc[base + 2u] = sum.z;
#elif PATCH
    // Particles outside the grid are reported by bin_count.
    scatter_bin(linear_index(gid, nwg));
#else
    let p = linear_index(gid, nwg);
    if sim.running == 0u || p >= params.n_particles {
        return;
    }
#if MUSL
    // The step's start positions, for the remap and the stress after g2p.
    x_start[p] = x0[p] + u[p];
#endif
    let c = shape_ctx(p, x0[p] + u[p]);
    if !shape_valid(c) {
        report_fault(FAULT_LEFT_GRID, p);
        return;
    }
    scatter_particle(c, bin_particle(p, c));
#endif
}
