// Stage `grid_update`, walls only, before `predict`: per node, the weight
// S_I = Σ_p N_Ip of the particles in contact with a wall, those whose
// contact spring is positive (`shared/wall_spring.wgsl`: the domain of
// half-width l_p = ½ sqrt(m_p / ρ_p) reaches past the wall's contact
// line, or a preloaded particle has not left it) (a particle in contact
// with two walls counts twice), at `wall_touch[2n]`, and at
// `wall_touch[2n + 1]` the friction's weights T_I of the same contacts:
// at the wall's line, N − d n·∇N, where none of a contact's is negative
// (linear shapes), else N (`wall_contact` sizes the friction with them).
// With WALL_PRELOAD, each contact's preload
// onto the nodes at the wall's line (B-splines: their basis evaluated at
// the line's point; else N − d n·∇N), into `wall_pre_force`, and with
// WALL_PRE_FIT its fit to the body's discrete reaction, P N_I a_I
// (`Walls::pre_fit`, src/model/preload_fit.rs). `wall_contact`
// reads it; `clear_grid` zeroes it. With GATES only the walls that act at
// the step's start time t (appear_at <= t < remove_at) are in contact.
// CPU twin: src/cpu/wall_touch.rs.
#include "shared/common.wgsl"
#include "shared/shape_bindings.wgsl" LME_ACCESS=read
#include "shared/shape.wgsl"

@group(0) @binding({{B_X0}}) var<storage, read> x0: array<vec2<f32>>;
@group(0) @binding({{B_U}}) var<storage, read> u: array<vec2<f32>>;
@group(0) @binding({{B_MASS}}) var<storage, read> mass: array<f32>;
@group(0) @binding({{B_RHO}}) var<storage, read> rho: array<f32>;
@group(0) @binding({{B_WALLS}}) var<storage, read> walls: array<Wall>;
@group(0) @binding({{B_WALL_TOUCH}}) var<storage, read_write> wall_touch: array<{{ATOMIC_T}}>;
#include "shared/wall_spring.wgsl"
#include "shared/atomics.wgsl" ARR=wall_touch FN=touch_add
#if WALL_PRELOAD
@group(0) @binding({{B_WALL_PRE_FORCE}}) var<storage, read_write> wall_pre_force: array<{{ATOMIC_T}}>;
#include "shared/atomics.wgsl" ARR=wall_pre_force FN=pre_force_add
#endif
#if WALL_PRE_FIT
@group(0) @binding({{B_WALL_PRE_FIT}}) var<storage, read> wall_pre_fit: array<vec2<f32>>;
#endif

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let p = linear_index(gid, nwg);
    if sim.running == 0u || p >= params.n_particles {
        return;
    }
    let x = x0[p] + u[p];
    let lp = 0.5 * sqrt(mass[p] / rho[p]);
    var count = 0u;
#if GATES
    let t = sim.t + sim.t_lo;
#endif
#if WALL_PRE_FIT
    let fit_on = pre_fit_on();
#endif
    // Per contact, the friction's weights: at the wall's line where none
    // of them is negative, else the particle's; with WALL_PRELOAD, its
    // preload P n onto the nodes at the wall's line (weights N − d n·∇N, or
    // B-splines' basis at the line's point),
    // which `wall_contact` counts in the body's velocity before it
    // decides the rest.
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
        count += 1u;
        let c = shape_ctx(p, x);
        let d = wall_depth(x, lp, wl);
        let positive = line_weights_positive(c, wl.normal, d);
#if WALL_PRELOAD
        // B-splines: the preload with the basis evaluated at the line's
        // point itself (the first-order weights are off by ½ d² ∂²N).
        var exact = false;
#if SHAPE_BSPLINE
        if sp.y > 0.0 {
            let cl = shape_ctx(p, x - d * wl.normal);
            exact = cl.ok;
            for (var r = 0u; exact && r < SHAPE_ROWS; r++) {
                let span = shape_span(cl, r);
                for (var s = span.x; s < span.y; s++) {
                    let nw = shape_node(cl, s);
                    if nw.ok && nw.n != 0.0 {
                        let f = sp.y * nw.n * wl.normal;
                        pre_force_add(2u * nw.node, f.x);
                        pre_force_add(2u * nw.node + 1u, f.y);
                    }
                }
            }
        }
#endif
#endif
        for (var r = 0u; r < SHAPE_ROWS; r++) {
            let span = shape_span(c, r);
            for (var s = span.x; s < span.y; s++) {
                let nw = shape_node(c, s);
                if !nw.ok {
                    continue;
                }
                let line = nw.n - d * dot(wl.normal, nw.dn);
                var fw = nw.n;
                if positive {
                    fw = line;
                }
                if fw != 0.0 {
                    touch_add(2u * nw.node + 1u, fw);
                }
#if WALL_PRELOAD
                if sp.y > 0.0 && !exact {
                    let f = sp.y * line * wl.normal;
                    pre_force_add(2u * nw.node, f.x);
                    pre_force_add(2u * nw.node + 1u, f.y);
                }
#if WALL_PRE_FIT
                // The fit to the body's discrete reaction (`Walls::pre_fit`),
                // while every wall that stood at the start stands.
                if sp.y > 0.0 && nw.n != 0.0 && fit_on {
                    let a = wall_pre_fit[nw.node];
                    if a.x != 0.0 || a.y != 0.0 {
                        let f = sp.y * nw.n * a;
                        pre_force_add(2u * nw.node, f.x);
                        pre_force_add(2u * nw.node + 1u, f.y);
                    }
                }
#endif
#endif
            }
        }
    }
    if count == 0u {
        return;
    }
    let c = shape_ctx(p, x);
    for (var r = 0u; r < SHAPE_ROWS; r++) {
        let span = shape_span(c, r);
        for (var k = span.x; k < span.y; k++) {
            let w = shape_node(c, k);
            if w.ok && w.n != 0.0 {
                touch_add(2u * w.node, f32(count) * w.n);
            }
        }
    }
}
