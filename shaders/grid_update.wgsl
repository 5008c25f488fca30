// Stage `grid_update`, two entry points around the force computation.
// `predict`: v_I = q_I / m_I, then the fixed components set to their
// constraint's prescribed velocity at the step's end (zero by default).
// `correct`: the walls' forces (`wall_contact.wgsl`) added to f_I, then
// reactions (−f on fixed components, summed per constraint), those
// components zeroed (a constraint wins over a wall), then
// v_I += γ Δt f_I / m_I (FE: γ = 1).
// With LOCAL_DAMPING, before the update each force component of a node
// with mass (the walls' forces included) loses α |f_i| sign(v_i), v the
// predicted nodal velocity (Cundall).
// With CONSTRAINT_POINTS a group leaves out the region nodes its points
// freed (`constraint_points.wgsl` holds the body there instead, after
// each entry point).
// With CONTACT, one invocation per node of every field (the constraints
// act on each field's copy of their nodes); `contact_exchange.wgsl`
// follows each entry point.
// A group with a velocity moves its region with it (`in_region`).
// CPU twin: src/cpu/grid_update.rs.
#include "shared/common.wgsl"
#include "shared/constraint_region.wgsl"

@group(0) @binding({{B_CONSTRAINTS}}) var<storage, read> constraints: array<Constraint>;
#if CONSTRAINT_POINTS
#include "shared/point_freed.wgsl"
#endif
#if CORRECT
#if WALLS
@group(0) @binding({{B_WALL_FORCE}}) var<storage, read> wall_force: array<f32>;
#endif
@group(0) @binding({{B_NODE_ACC}}) var<storage, read_write> node_acc: array<f32>;
@group(0) @binding({{B_REACTIONS}}) var<storage, read_write> reactions: array<{{ATOMIC_T}}>;
#include "shared/atomics.wgsl" ARR=reactions FN=reaction_add
#else
@group(0) @binding({{B_NODE_ACC}}) var<storage, read_write> node_acc: array<f32>;
#endif

// Fixed directions of node (i, j) at time t (s): bit 1 = x, bit 2 = y.
fn fix_bits(i: u32, j: u32, t: f32) -> u32 {
    var f = 0u;
    for (var g = 0u; g < params.n_groups; g++) {
        let c = constraints[g];
        if in_region(c, i, j, t) {
#if CONSTRAINT_POINTS
            if freed(g, i, j) {
                continue;
            }
#endif
            f |= c.fix;
        }
    }
    return f;
}

#if !CORRECT
// Prescribed velocities at time t (s) on the fixed components of node
// (i, j); later groups win, as on the CPU.
fn prescribe(i: u32, j: u32, v_in: vec2<f32>, t: f32) -> vec2<f32> {
    var v = v_in;
    for (var g = 0u; g < params.n_groups; g++) {
        let c = constraints[g];
        if in_region(c, i, j, t) {
#if CONSTRAINT_POINTS
            if freed(g, i, j) {
                continue;
            }
#endif
            var r = 1.0;
            if c.ramp_time > 0.0 {
                r = clamp(t / c.ramp_time, 0.0, 1.0);
            }
            if (c.fix & 1u) != 0u {
                v.x = r * c.vx;
            }
            if (c.fix & 2u) != 0u {
                v.y = r * c.vy;
            }
        }
    }
    return v;
}
#endif

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let n = linear_index(gid, nwg);
#if CONTACT
    if sim.running == 0u || n >= field_nodes() {
        return;
    }
    let i = n % params.n_nodes % params.nx;
    let j = n % params.n_nodes / params.nx;
#else
    if sim.running == 0u || n >= params.n_nodes {
        return;
    }
    let i = n % params.nx;
    let j = n / params.nx;
#endif
    let b = n * NODE_STRIDE;
    let m = node_acc[b];
    // The step's end: where the regions are and their velocities taken.
    let t = sim.t + sim.t_lo + sim.dt;
#if CORRECT
    var f = vec2<f32>(node_acc[b + 3u], node_acc[b + 4u]);
#if WALLS
    f += vec2<f32>(wall_force[2u * n], wall_force[2u * n + 1u]);
#endif
    for (var g = 0u; g < params.n_groups; g++) {
        let c = constraints[g];
        if in_region(c, i, j, t) {
#if CONSTRAINT_POINTS
            if freed(g, i, j) {
                continue;
            }
#endif
            if (c.fix & 1u) != 0u && f.x != 0.0 {
                reaction_add(2u * g, -f.x);
            }
            if (c.fix & 2u) != 0u && f.y != 0.0 {
                reaction_add(2u * g + 1u, -f.y);
            }
        }
    }
    let fix = fix_bits(i, j, t);
    if (fix & 1u) != 0u {
        f.x = 0.0;
    }
    if (fix & 2u) != 0u {
        f.y = 0.0;
    }
    if m > params.mass_eps {
        let gdt = params.npc_gamma * sim.dt;
#if LOCAL_DAMPING
        f -= params.local_damping * abs(f) * sign(vec2<f32>(node_acc[b + 1u], node_acc[b + 2u]));
#endif
        var v = vec2<f32>(node_acc[b + 1u], node_acc[b + 2u]) + gdt / m * f;
        node_acc[b + 1u] = v.x;
        node_acc[b + 2u] = v.y;
    }
    node_acc[b + 3u] = f.x;
    node_acc[b + 4u] = f.y;
#else
    var vel = vec2<f32>(0.0);
    if m > params.mass_eps {
        vel = vec2<f32>(node_acc[b + 1u], node_acc[b + 2u]) / m;
        let fix = fix_bits(i, j, t);
        if (fix & 1u) != 0u {
            vel.x = 0.0;
        }
        if (fix & 2u) != 0u {
            vel.y = 0.0;
        }
        vel = prescribe(i, j, vel, t);
    }
    node_acc[b + 1u] = vel.x;
    node_acc[b + 2u] = vel.y;
#endif
}
