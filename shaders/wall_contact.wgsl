// Stage `grid_update`, walls only, before `correct`: the walls' forces at
// their contact points, the particles whose contact spring is positive
// (`shared/wall_spring.wgsl`, as in `wall_touch.wgsl`). Per particle and
// wall: the body's velocity at the particle, corrected without the walls,
// v̂ = Σ N (v_I + γΔt f_I / m_I), and w = γΔt Σ N S_I / m_I (S_I: the
// contact weights of `wall_touch`, `wall_touch[2n]`); the normal force
// F_n = max(0, spring − WALL_DAMPING v̂·n / w), and the tangential
// force that stops the particle's own slip, v_p' = v_p + sΔt Σ N f_I/m_I
// (sΔt = (2 − γ)Δt, the time it feels a nodal force in), −v'_t / w',
// w' = sΔt Σ N T_I / m_I (T_I: the friction's weights of the contacts,
// `wall_touch[2n + 1]`), at most μ F_n (`shared/wall_coulomb.wgsl`;
// stick: μ = STICK_MU; slip: 0).
// With WALL_PRELOAD both velocities count the preloads (`wall_touch`'s
// `wall_pre_force`). F goes onto the nodes with the particle's weights
// (`wall_force`, which `correct` adds to f_I), the preload's share of F_n
// and the friction (where those weights have no negative part: linear
// shapes) on the wall's line x_p − d n (d: `wall_depth`) with the weights
// there to first order, N − d n·∇N, and into the wall's reaction; with
// WALL_PRE_FIT the preload's fit, N_I min(P, F_n) a_I, too. `clear_grid` zeroes `wall_force`. With GATES only the walls
// that act at the step's start time t (appear_at <= t < remove_at) push.
// CPU twin: src/cpu/wall_contact.rs.
#include "shared/common.wgsl"
#include "shared/shape_bindings.wgsl" LME_ACCESS=read
#include "shared/shape.wgsl"

@group(0) @binding({{B_X0}}) var<storage, read> x0: array<vec2<f32>>;
@group(0) @binding({{B_U}}) var<storage, read> u: array<vec2<f32>>;
@group(0) @binding({{B_MASS}}) var<storage, read> mass: array<f32>;
@group(0) @binding({{B_RHO}}) var<storage, read> rho: array<f32>;
@group(0) @binding({{B_V}}) var<storage, read> v_p: array<vec2<f32>>;
@group(0) @binding({{B_NODE_ACC}}) var<storage, read> node_acc: array<f32>;
@group(0) @binding({{B_WALLS}}) var<storage, read> walls: array<Wall>;
@group(0) @binding({{B_WALL_TOUCH}}) var<storage, read> wall_touch: array<f32>;
@group(0) @binding({{B_WALL_FORCE}}) var<storage, read_write> wall_force: array<{{ATOMIC_T}}>;
@group(0) @binding({{B_REACTIONS}}) var<storage, read_write> reactions: array<{{ATOMIC_T}}>;
#include "shared/atomics.wgsl" ARR=wall_force FN=wall_force_add
#include "shared/atomics.wgsl" ARR=reactions FN=reaction_add
#include "shared/wall_spring.wgsl"
#include "shared/wall_coulomb.wgsl"
#if WALL_PRELOAD
@group(0) @binding({{B_WALL_PRE_FORCE}}) var<storage, read> wall_pre_force: array<f32>;
#endif
#if WALL_PRE_FIT
@group(0) @binding({{B_WALL_PRE_FIT}}) var<storage, read> wall_pre_fit: array<vec2<f32>>;
#endif

// Keep in sync with src/model/walls.rs.
const WALL_DAMPING: f32 = 0.05;

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let p = linear_index(gid, nwg);
    if sim.running == 0u || p >= params.n_particles {
        return;
    }
    let x = x0[p] + u[p];
    let lp = 0.5 * sqrt(mass[p] / rho[p]);
    let gdt = params.npc_gamma * sim.dt;
    // The time over which a particle feels a nodal force: (2 − γ)Δt for
    // NPC (Δt in v_p, (1 − γ)Δt in the next predictor), Δt for FE (γ = 1).
    let sdt = (2.0 - params.npc_gamma) * sim.dt;
#if GATES
    let t = sim.t + sim.t_lo;
#endif
#if WALL_PRE_FIT
    let fit_on = pre_fit_on();
#endif
    for (var k = 0u; k < arrayLength(&walls); k++) {
        let wl = walls[k];
#if GATES
        if t < wl.appear_at || t >= wl.remove_at {
            continue;
        }
#endif
        let sp = contact_spring(p, k, wl, x, lp);
        if sp.x <= 0.0 {
            continue;
        }
        let c = shape_ctx(p, x);
        // v: the body's corrected velocity at the particle (the damping);
        // vp: the particle's own next velocity (the friction); both
        // without the contact forces, with the preloads.
        var v = vec2<f32>(0.0);
        var vp = v_p[p];
        var w = 0.0;
        var wf = 0.0;
        var w_own = 0.0;
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
                    var f = vec2<f32>(node_acc[b + 3u], node_acc[b + 4u]);
#if WALL_PRELOAD
                    f += vec2<f32>(wall_pre_force[2u * nw.node], wall_pre_force[2u * nw.node + 1u]);
#endif
                    v += nw.n * (vec2<f32>(node_acc[b + 1u], node_acc[b + 2u]) + gdt / m * f);
                    vp += nw.n * sdt / m * f;
                    w += nw.n * wall_touch[2u * nw.node] / m;
                    wf += nw.n * wall_touch[2u * nw.node + 1u] / m;
                    w_own += nw.n * nw.n / m;
                }
            }
        }
        if w <= 0.0 {
            continue;
        }
        // At least this contact's own weights (S_I ≥ N_Ip): a preloaded
        // particle whose spring crossed zero since `wall_touch` is in
        // contact here without them in S (CPU twin's comment).
        w = max(w, w_own);
        w *= gdt;
        let vn = dot(v, wl.normal);
        let fnorm = max(sp.x - WALL_DAMPING * vn / w, 0.0);
        let vt = vp - dot(vp, wl.normal) * wl.normal;
        // Coulomb (`coulomb_slip`): the force that stops the slip, at
        // most μ F_n.
        // Sized over sdt, the step the particle feels it in (over γΔt the
        // stick loop's gain was (2 − γ)/γ and a slip grew), and with the
        // friction's own weights T_I (with S_I while it acts on the line,
        // a stick loop's gain was about 1.28: the held particles kept a
        // slip against their load); S_I where the nodes carry no T.
        var ws = w / gdt * sdt;
        if wf > 0.0 {
            ws = wf * sdt;
        }
        var ft = -vt / ws;
        let mag = length(ft);
        let slip = coulomb_slip(mag, fnorm, coulomb_mu(wl));
        if slip.slips {
            ft *= slip.cap / mag;
        }
        let fw = fnorm * wl.normal + ft;
        reaction_add(2u * (params.n_groups + k), fw.x);
        reaction_add(2u * (params.n_groups + k) + 1u, fw.y);
        // The preload's share and the friction at the wall's line (the
        // friction only where the line's weights N − d n·∇N have no
        // negative part), the rest at the particle.
        let f_pre = min(sp.y, fnorm);
        let d = wall_depth(x, lp, wl);
        let positive = line_weights_positive(c, wl.normal, d);
        var ft_line = vec2<f32>(0.0);
        if positive {
            ft_line = ft;
        }
        // B-splines: the preload's share with the basis evaluated at the
        // line's point itself (as `wall_touch`), the friction as below.
        var f_pre_line = f_pre;
#if SHAPE_BSPLINE
        if f_pre > 0.0 {
            let cl = shape_ctx(p, x - d * wl.normal);
            if cl.ok {
                f_pre_line = 0.0;
                for (var r = 0u; r < SHAPE_ROWS; r++) {
                    let span = shape_span(cl, r);
                    for (var s = span.x; s < span.y; s++) {
                        let nw = shape_node(cl, s);
                        if nw.ok && nw.n != 0.0 {
                            let o = nw.n * f_pre * wl.normal;
                            wall_force_add(2u * nw.node, o.x);
                            wall_force_add(2u * nw.node + 1u, o.y);
                        }
                    }
                }
            }
        }
#endif
#if WALL_PRE_FIT
        // The preload's fit to the body's discrete reaction goes with the
        // preload it carries now (`Walls::pre_fit`).
        if f_pre > 0.0 && fit_on {
            var fit_sum = vec2<f32>(0.0);
            for (var r = 0u; r < SHAPE_ROWS; r++) {
                let span = shape_span(c, r);
                for (var s = span.x; s < span.y; s++) {
                    let nw = shape_node(c, s);
                    if nw.ok && nw.n != 0.0 {
                        let a = wall_pre_fit[nw.node];
                        if a.x != 0.0 || a.y != 0.0 {
                            let o = nw.n * f_pre * a;
                            wall_force_add(2u * nw.node, o.x);
                            wall_force_add(2u * nw.node + 1u, o.y);
                            fit_sum += o;
                        }
                    }
                }
            }
            reaction_add(2u * (params.n_groups + k), fit_sum.x);
            reaction_add(2u * (params.n_groups + k) + 1u, fit_sum.y);
        }
#endif
        let f_at = fw - f_pre * wl.normal - ft_line;
        let f_line = f_pre_line * wl.normal + ft_line;
        let lined = f_pre_line != 0.0 || positive;
        for (var r = 0u; r < SHAPE_ROWS; r++) {
            let span = shape_span(c, r);
            for (var s = span.x; s < span.y; s++) {
                let nw = shape_node(c, s);
                if nw.ok && (nw.n != 0.0 || lined) {
                    let o = nw.n * f_at + (nw.n - d * dot(wl.normal, nw.dn)) * f_line;
                    wall_force_add(2u * nw.node, o.x);
                    wall_force_add(2u * nw.node + 1u, o.y);
                }
            }
        }
    }
}
