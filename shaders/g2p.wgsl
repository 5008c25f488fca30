// Stage `g2p`: particle update and checks.
// FE and MUSL:  v += Δt Σ N f/m;  u += Δt Σ N v_I.
// NPC: a = Σ N f/m;  v += Δt a;  u += Δt Σ N v_I (+ ½ Δt² a), v_I corrected or
//      predicted as NPC_POSITION_* says. Positions live as x0 + u, and u is a
//      compensated (Kahan) sum u − u_lo: a slow, steady motion would otherwise
//      lose the same fraction of every small increment to f32 rounding.
// PIC: v = (1 − α) v_FLIP + α Σ N v_I, α = params.pic_fraction.
// CONTACT: a particle that reaches a node where a pair of its field is in
// contact (a normal in contact_detect's output) takes α at least
// CONTACT_PIC_FRACTION (shared/contact.wgsl), and adds the momentum this
// changes to its field's sum, which contact_conserve.wgsl gives back.
// CPU twin: src/cpu/g2p.rs.
#include "shared/common.wgsl"
#include "shared/kahan.wgsl"
#include "shared/shape_bindings.wgsl" LME_ACCESS=read
#include "shared/shape.wgsl"
#if CONTACT
#include "shared/contact.wgsl"
@group(0) @binding({{B_CONTACT_PAIRS}}) var<storage, read> contact_pairs: array<ContactPair>;
@group(0) @binding({{B_CONTACT_NORMAL}}) var<storage, read> contact_normal_in: array<f32>;
@group(0) @binding({{B_MASS}}) var<storage, read> mass: array<f32>;
// Per field [mass, Σ m_p Δv_p]: the blend's momentum, for contact_conserve.
@group(0) @binding({{B_CONTACT_PIC}}) var<storage, read_write> contact_pic: array<{{ATOMIC_T}}>;
#include "shared/atomics.wgsl" ARR=contact_pic FN=pic_add

// Whether a pair of field f with a tangential force (stick, friction) is
// in contact at grid node i.
fn touched(f: u32, i: u32) -> bool {
    for (var k = 0u; k < N_PAIRS; k++) {
        let pf = contact_pairs[k].fields;
        if contact_pairs[k].law != CONTACT_SLIP && (pf.x == f || pf.y == f) {
            let o = 3u * (k * params.n_nodes + i);
            if contact_normal_in[o] != 0.0 || contact_normal_in[o + 1u] != 0.0 {
                return true;
            }
        }
    }
    return false;
}
#endif

@group(0) @binding({{B_X0}}) var<storage, read> x0: array<vec2<f32>>;
@group(0) @binding({{B_U}}) var<storage, read_write> u: array<vec2<f32>>;
@group(0) @binding({{B_U_LO}}) var<storage, read_write> u_lo: array<vec2<f32>>;
@group(0) @binding({{B_V}}) var<storage, read_write> v: array<vec2<f32>>;
#if NPC
@group(0) @binding({{B_A}}) var<storage, read_write> a: array<vec2<f32>>;
#endif
@group(0) @binding({{B_NODE_ACC}}) var<storage, read> node_acc: array<f32>;

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let p = linear_index(gid, nwg);
    if sim.running == 0u || p >= params.n_particles {
        return;
    }
    let dt = sim.dt;
    let c = shape_ctx(p, x0[p] + u[p]);
    var acc = vec2<f32>(0.0);
    var vel = vec2<f32>(0.0);
#if CONTACT
    var near_contact = false;
    let base = field_base(p);
#endif
    for (var r = 0u; r < SHAPE_ROWS; r++) {
        let span = shape_span(c, r);
        for (var k = span.x; k < span.y; k++) {
            let w = shape_node(c, k);
            if !w.ok {
                continue;
            }
#if CONTACT
            if w.n > 0.0 && !near_contact {
                near_contact = touched(field[p], w.node - base);
            }
#endif
            let b = w.node * NODE_STRIDE;
            let m = node_acc[b];
            if m > params.mass_eps {
                acc += w.n * vec2<f32>(node_acc[b + 3u], node_acc[b + 4u]) / m;
                vel += w.n * vec2<f32>(node_acc[b + 1u], node_acc[b + 2u]);
            }
        }
    }
#if CONTACT
    var alpha = params.pic_fraction;
    if near_contact {
        alpha = max(alpha, CONTACT_PIC_FRACTION);
    }
    let flip = v[p] + dt * acc;
    var vp = flip;
    if alpha > 0.0 {
        vp = (1.0 - alpha) * flip + alpha * vel;
    }
    if alpha > params.pic_fraction {
        // The interface's share over the scene's: its momentum change,
        // which contact_conserve gives back to the field.
        let scene_v = (1.0 - params.pic_fraction) * flip + params.pic_fraction * vel;
        let dp = mass[p] * (vp - scene_v);
        let f = field[p];
        pic_add(3u * f + 1u, dp.x);
        pic_add(3u * f + 2u, dp.y);
    }
#else
#if PIC
    let vp = (1.0 - params.pic_fraction) * (v[p] + dt * acc) + params.pic_fraction * vel;
#else
    let vp = v[p] + dt * acc;
#endif
#endif
    var du = dt * vel;
#if NPC
#if !NPC_POSITION_CORRECTED
    du -= params.npc_gamma * dt * dt * acc;
#endif
#if !NPC_POSITION_NEWMARK
    du += 0.5 * dt * dt * acc;
#endif
    a[p] = acc;
#endif
    let k = kahan_add2(u[p], u_lo[p], du, params.opaque_zero);
    let up = k.sum;
    u_lo[p] = k.lo;
    v[p] = vp;
    u[p] = up;
    if !(is_finite(up.x) && is_finite(up.y) && is_finite(vp.x) && is_finite(vp.y)) {
        report_fault(FAULT_NON_FINITE_MOTION, p);
        return;
    }
    if !inside_grid(x0[p] + up, params.edge_margin) {
        report_fault(FAULT_LEFT_GRID, p);
    }
}
