// Stage `grid_update`, two entry points around the force computation.
// `predict`: v_I = q_I / m_I, then each wall's contact rule (the walls the
// node is behind and touches, `wall_touch.wgsl`, in scene order), then the fixed components set to their
// constraint's prescribed velocity at the step's end (zero by default): a
// constraint wins over a wall.
// `correct`: reactions (−f on fixed components, summed per constraint),
// those components zeroed, then v_I += γ Δt f_I / m_I (FE: γ = 1); then the
// walls' rules on the corrected velocity, whose change Δv is the wall's
// force m Δv / (γ Δt), added to f_I and to the wall's reaction. With
// LOCAL_DAMPING, before the update each force component of a node with mass
// loses α |f_i| sign(v_i), v the predicted nodal velocity (Cundall).
// CPU twin: src/cpu/grid_update.rs.
#include "shared/common.wgsl"

@group(0) @binding({{B_CONSTRAINTS}}) var<storage, read> constraints: array<Constraint>;
#if WALLS
@group(0) @binding({{B_WALLS}}) var<storage, read> walls: array<Wall>;
@group(0) @binding({{B_WALL_MASK}}) var<storage, read> wall_mask: array<u32>;
@group(0) @binding({{B_WALL_TOUCH}}) var<storage, read> wall_touch: array<u32>;
#endif
#if CORRECT
@group(0) @binding({{B_NODE_ACC}}) var<storage, read_write> node_acc: array<f32>;
@group(0) @binding({{B_REACTIONS}}) var<storage, read_write> reactions: array<{{ATOMIC_T}}>;
#include "shared/atomics.wgsl" ARR=reactions FN=reaction_add
#else
@group(0) @binding({{B_NODE_ACC}}) var<storage, read_write> node_acc: array<f32>;
#endif

// Fixed directions of node (i, j): bit 1 = x, bit 2 = y.
fn fix_bits(i: u32, j: u32) -> u32 {
    var f = 0u;
    for (var g = 0u; g < params.n_groups; g++) {
        let c = constraints[g];
        if i >= c.i0 && i <= c.i1 && j >= c.j0 && j <= c.j1 {
            f |= c.fix;
        }
    }
    return f;
}

#if WALLS
// A wall's contact rule on the velocity v of a node in contact (CPU twin:
// `wall_velocity`): separating or resting (v·n ≥ 0) is free; approaching,
// stick stops it, slip removes the normal component, friction also takes
// μ Δv_n (Δv_n = −v·n) off the tangential speed, or stops it when that
// speed is at most μ Δv_n.
fn wall_velocity(v: vec2<f32>, w: Wall) -> vec2<f32> {
    let vn = dot(v, w.normal);
    if vn >= 0.0 {
        return v;
    }
    if w.contact == CONTACT_STICK {
        return vec2<f32>(0.0);
    }
    let vt = v - vn * w.normal;
    if w.contact != CONTACT_FRICTION {
        return vt;
    }
    let dvn = -vn;
    let speed = length(vt);
    if speed <= w.mu * dvn {
        return vec2<f32>(0.0);
    }
    return (1.0 - w.mu * dvn / speed) * vt;
}
#endif

#if !CORRECT
// Prescribed velocities at time t (s) on the fixed components of node
// (i, j); later groups win, as on the CPU.
fn prescribe(i: u32, j: u32, v_in: vec2<f32>, t: f32) -> vec2<f32> {
    var v = v_in;
    for (var g = 0u; g < params.n_groups; g++) {
        let c = constraints[g];
        if i >= c.i0 && i <= c.i1 && j >= c.j0 && j <= c.j1 {
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
    if sim.running == 0u || n >= params.n_nodes {
        return;
    }
    let i = n % params.nx;
    let j = n / params.nx;
    let b = n * NODE_STRIDE;
    let m = node_acc[b];
#if CORRECT
    var f = vec2<f32>(node_acc[b + 3u], node_acc[b + 4u]);
    for (var g = 0u; g < params.n_groups; g++) {
        let c = constraints[g];
        if i >= c.i0 && i <= c.i1 && j >= c.j0 && j <= c.j1 {
            if (c.fix & 1u) != 0u && f.x != 0.0 {
                reaction_add(2u * g, -f.x);
            }
            if (c.fix & 2u) != 0u && f.y != 0.0 {
                reaction_add(2u * g + 1u, -f.y);
            }
        }
    }
    let fix = fix_bits(i, j);
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
#if WALLS
        let mask = wall_mask[n] & wall_touch[n];
        for (var k = 0u; mask != 0u && k < arrayLength(&walls); k++) {
            if (mask & (1u << k)) == 0u {
                continue;
            }
            var nv = wall_velocity(v, walls[k]);
            // A constraint wins: its components keep their value.
            if (fix & 1u) != 0u {
                nv.x = v.x;
            }
            if (fix & 2u) != 0u {
                nv.y = v.y;
            }
            let fw = m * (nv - v) / gdt;
            if fw.x != 0.0 {
                reaction_add(2u * (params.n_groups + k), fw.x);
            }
            if fw.y != 0.0 {
                reaction_add(2u * (params.n_groups + k) + 1u, fw.y);
            }
            f += fw;
            v = nv;
        }
#endif
        node_acc[b + 1u] = v.x;
        node_acc[b + 2u] = v.y;
    }
    node_acc[b + 3u] = f.x;
    node_acc[b + 4u] = f.y;
#else
    var vel = vec2<f32>(0.0);
    if m > params.mass_eps {
        vel = vec2<f32>(node_acc[b + 1u], node_acc[b + 2u]) / m;
#if WALLS
        let mask = wall_mask[n] & wall_touch[n];
        for (var k = 0u; mask != 0u && k < arrayLength(&walls); k++) {
            if (mask & (1u << k)) != 0u {
                vel = wall_velocity(vel, walls[k]);
            }
        }
#endif
        let fix = fix_bits(i, j);
        if (fix & 1u) != 0u {
            vel.x = 0.0;
        }
        if (fix & 2u) != 0u {
            vel.y = 0.0;
        }
        vel = prescribe(i, j, vel, sim.t + sim.t_lo + sim.dt);
    }
    node_acc[b + 1u] = vel.x;
    node_acc[b + 2u] = vel.y;
#endif
}
