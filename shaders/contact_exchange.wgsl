// Stage `grid_update`, contact pairs only: the exchange, one invocation
// per grid node, after `predict` (and after `remap`'s predict in MUSL)
// and, built with CORRECT, after `correct`. At a node without a fixed
// component, for each two fields with mass in field order: a declared
// pair in contact there (`contact_detect`'s normal) applies its law
// (`pair_impulse`) while the bodies approach; two fields that are not a
// declared pair take their centre-of-mass velocity (as one shared field
// would). Each exchange adds Δp to one field and −Δp to the other. With
// CORRECT each m Δv also goes into the nodal force as m Δv / (γ Δt), so
// g2p sees it, and a pair's share into its reaction (the force on its
// first body).
// CPU twin: `exchange` in src/cpu/contact_exchange.rs.
#include "shared/common.wgsl"
#include "shared/contact.wgsl"
#include "shared/constraint_region.wgsl"

@group(0) @binding({{B_CONSTRAINTS}}) var<storage, read> constraints: array<Constraint>;
#if CONSTRAINT_POINTS
#include "shared/point_freed.wgsl"
#endif
@group(0) @binding({{B_NODE_ACC}}) var<storage, read_write> node_acc: array<f32>;
@group(0) @binding({{B_CONTACT_PAIRS}}) var<storage, read> contact_pairs: array<ContactPair>;
@group(0) @binding({{B_CONTACT_NORMAL}}) var<storage, read> contact_normal_in: array<f32>;
#if CORRECT
@group(0) @binding({{B_REACTIONS}}) var<storage, read_write> reactions: array<{{ATOMIC_T}}>;
#include "shared/atomics.wgsl" ARR=reactions FN=reaction_add
#endif

// Whether some constraint fixes a component of node (i, j) at time t (s)
// (the CPU's `fix[i] != 0`; grid_update.wgsl's `fix_bits` ≠ 0).
fn node_fixed(i: u32, j: u32, t: f32) -> bool {
    for (var g = 0u; g < params.n_groups; g++) {
        let c = constraints[g];
        if c.fix != 0u && in_region(c, i, j, t) {
#if CONSTRAINT_POINTS
            if freed(g, i, j) {
                continue;
            }
#endif
            return true;
        }
    }
    return false;
}

// The declared pair of fields fa and fb (either order), or N_PAIRS.
fn pair_of(fa: u32, fb: u32) -> u32 {
    for (var k = 0u; k < N_PAIRS; k++) {
        let f = contact_pairs[k].fields;
        if (f.x == fa && f.y == fb) || (f.x == fb && f.y == fa) {
            return k;
        }
    }
    return N_PAIRS;
}

fn velocity(node: u32) -> vec2<f32> {
    return vec2<f32>(node_acc[node * NODE_STRIDE + 1u], node_acc[node * NODE_STRIDE + 2u]);
}

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = linear_index(gid, nwg);
    if sim.running == 0u || i >= params.n_nodes {
        return;
    }
    if node_fixed(i % params.nx, i / params.nx, sim.t + sim.t_lo + sim.dt) {
        return;
    }
#if CORRECT
    let gdt = params.npc_gamma * sim.dt;
#endif
    for (var fa = 0u; fa < N_FIELDS; fa++) {
        let ia = fa * params.n_nodes + i;
        let ma = node_acc[ia * NODE_STRIDE];
        if ma <= params.mass_eps {
            continue;
        }
        for (var fb = fa + 1u; fb < N_FIELDS; fb++) {
            let ib = fb * params.n_nodes + i;
            let mb = node_acc[ib * NODE_STRIDE];
            if mb <= params.mass_eps {
                continue;
            }
            let va = velocity(ia);
            let vb = velocity(ib);
            let k = pair_of(fa, fb);
            var dp: vec2<f32>;
            var sign = 1.0;
            if k < N_PAIRS {
                let o = k * params.n_nodes + i;
                let n0 = vec2<f32>(contact_normal_in[3u * o], contact_normal_in[3u * o + 1u]);
                if all(n0 == vec2<f32>(0.0)) {
                    continue;
                }
                let pair = contact_pairs[k];
                // The normal points from the pair's first body to its second.
                if pair.fields.x != fa {
                    sign = -1.0;
                }
                dp = pair_impulse(pair.law, pair.mu, ma, va, mb, vb, sign * n0);
            } else {
                // Not a pair: one field (the centre-of-mass velocity).
                dp = -(ma * mb / (ma + mb)) * (va - vb);
            }
            if all(dp == vec2<f32>(0.0)) {
                continue;
            }
            let na = va + dp / ma;
            let nb = vb - dp / mb;
            node_acc[ia * NODE_STRIDE + 1u] = na.x;
            node_acc[ia * NODE_STRIDE + 2u] = na.y;
            node_acc[ib * NODE_STRIDE + 1u] = nb.x;
            node_acc[ib * NODE_STRIDE + 2u] = nb.y;
#if CORRECT
            let f = dp / gdt;
            node_acc[ia * NODE_STRIDE + 3u] += f.x;
            node_acc[ia * NODE_STRIDE + 4u] += f.y;
            node_acc[ib * NODE_STRIDE + 3u] -= f.x;
            node_acc[ib * NODE_STRIDE + 4u] -= f.y;
            if k < N_PAIRS {
                let r = contact_pairs[k].reaction;
                reaction_add(2u * r, sign * f.x);
                reaction_add(2u * r + 1u, sign * f.y);
            }
#endif
        }
    }
}
