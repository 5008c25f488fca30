// Stage `grid_update`, walls only, before `correct`: the walls' forces at
// their contact points, the particles whose domain reaches past a wall's
// contact line by pen > 0 (as in `wall_touch.wgsl`). Per particle and
// wall: the body's velocity at the particle, corrected without the walls,
// v̂ = Σ N (v_I + γΔt f_I / m_I), and w = γΔt Σ N S_I / m_I (S_I: the
// contact weights of `wall_touch`); the normal force
// F_n = max(0, k pen 2 l_p − WALL_DAMPING v̂·n / w), and the tangential
// force −v̂_t / w that stops the slip there, at most μ F_n (stick: μ =
// STICK_MU; slip: 0). F goes onto the nodes with the particle's weights
// (`wall_force`, which `correct` adds to f_I) and into the wall's
// reaction. `clear_grid` zeroes `wall_force`. With GATES only the walls
// that act at the step's start time t (appear_at <= t < remove_at) push.
// CPU twin: `wall_contact` in src/cpu/grid_update.rs.
#include "shared/common.wgsl"
#include "shared/shape_bindings.wgsl" LME_ACCESS=read
#include "shared/shape.wgsl"

@group(0) @binding({{B_X0}}) var<storage, read> x0: array<vec2<f32>>;
@group(0) @binding({{B_U}}) var<storage, read> u: array<vec2<f32>>;
@group(0) @binding({{B_MASS}}) var<storage, read> mass: array<f32>;
@group(0) @binding({{B_RHO}}) var<storage, read> rho: array<f32>;
@group(0) @binding({{B_NODE_ACC}}) var<storage, read> node_acc: array<f32>;
@group(0) @binding({{B_WALLS}}) var<storage, read> walls: array<Wall>;
@group(0) @binding({{B_WALL_TOUCH}}) var<storage, read> wall_touch: array<f32>;
@group(0) @binding({{B_WALL_FORCE}}) var<storage, read_write> wall_force: array<{{ATOMIC_T}}>;
@group(0) @binding({{B_REACTIONS}}) var<storage, read_write> reactions: array<{{ATOMIC_T}}>;
#include "shared/atomics.wgsl" ARR=wall_force FN=wall_force_add
#include "shared/atomics.wgsl" ARR=reactions FN=reaction_add

// Keep in sync with src/model/walls.rs.
const WALL_DAMPING: f32 = 0.05;
const STICK_MU: f32 = 20.0;

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let p = linear_index(gid, nwg);
    if sim.running == 0u || p >= params.n_particles {
        return;
    }
    let x = x0[p] + u[p];
    let lp = 0.5 * sqrt(mass[p] / rho[p]);
    let gdt = params.npc_gamma * sim.dt;
#if GATES
    let t = sim.t + sim.t_lo;
#endif
    for (var k = 0u; k < arrayLength(&walls); k++) {
        let wl = walls[k];
#if GATES
        if t < wl.appear_at || t >= wl.remove_at {
            continue;
        }
#endif
        let pen = lp * (abs(wl.normal.x) + abs(wl.normal.y)) - dot(x - wl.point, wl.normal) - wl.offset;
        if pen <= 0.0 {
            continue;
        }
        let c = shape_ctx(p, x);
        var v = vec2<f32>(0.0);
        var w = 0.0;
        for (var r = 0u; r < SHAPE_ROWS; r++) {
            let span = shape_span(c, r);
            for (var s = span.x; s < span.y; s++) {
                let nw = shape_node(c, s);
                if !nw.ok {
                    continue;
                }
                let b = nw.node * NODE_STRIDE;
                let m = node_acc[b];
                if m > params.mass_eps {
                    let f = vec2<f32>(node_acc[b + 3u], node_acc[b + 4u]);
                    v += nw.n * (vec2<f32>(node_acc[b + 1u], node_acc[b + 2u]) + gdt / m * f);
                    w += nw.n * wall_touch[nw.node] / m;
                }
            }
        }
        if w <= 0.0 {
            continue;
        }
        w *= gdt;
        let vn = dot(v, wl.normal);
        let fnorm = max(wl.stiffness * pen * 2.0 * lp - WALL_DAMPING * vn / w, 0.0);
        let vt = v - vn * wl.normal;
        var mu = 0.0;
        if wl.contact == CONTACT_STICK {
            mu = STICK_MU;
        } else if wl.contact == CONTACT_FRICTION {
            mu = wl.mu;
        }
        // Coulomb: the force that stops the slip, at most μ F_n.
        var ft = -vt / w;
        let mag = length(ft);
        let cap = mu * fnorm;
        if mag > cap {
            ft *= cap / mag;
        }
        let fw = fnorm * wl.normal + ft;
        reaction_add(2u * (params.n_groups + k), fw.x);
        reaction_add(2u * (params.n_groups + k) + 1u, fw.y);
        for (var r = 0u; r < SHAPE_ROWS; r++) {
            let span = shape_span(c, r);
            for (var s = span.x; s < span.y; s++) {
                let nw = shape_node(c, s);
                if nw.ok && nw.n != 0.0 {
                    wall_force_add(2u * nw.node, nw.n * fw.x);
                    wall_force_add(2u * nw.node + 1u, nw.n * fw.y);
                }
            }
        }
    }
}
