// Stage `p2g` with MLS, pass 5 of 5, one invocation per Gauss point g:
// fit ρ and ρv* (v* = v + (1 − γ) Δt a for NPC) by moving least squares
// over the particles within 3h (basis [1, Δx, Δy] in units of h, weight
// w(|Δx|/2) w(|Δy|/2)), keep c = A⁻¹ e₀ for the forces pass, and add
// N_I(x_g) [ρ, ρv*] ω_g to the nodes. CPU twin: `Mls::p2g` (src/cpu/mls.rs).
#include "shared/common.wgsl"
#include "shared/shape_bindings.wgsl" LME_ACCESS=read
#include "shared/shape.wgsl"
#include "shared/mls.wgsl"

@group(0) @binding({{B_X0}}) var<storage, read> x0: array<vec2<f32>>;
@group(0) @binding({{B_U}}) var<storage, read> u: array<vec2<f32>>;
@group(0) @binding({{B_V}}) var<storage, read> v: array<vec2<f32>>;
#if NPC
@group(0) @binding({{B_A}}) var<storage, read> a: array<vec2<f32>>;
#endif
@group(0) @binding({{B_RHO}}) var<storage, read> rho: array<f32>;
@group(0) @binding({{B_CELL_START}}) var<storage, read> cell_start: array<u32>;
@group(0) @binding({{B_CELL_ORDER}}) var<storage, read> cell_order: array<u32>;
@group(0) @binding({{B_MLS_OCC}}) var<storage, read> mls_occ: array<u32>;
@group(0) @binding({{B_MLS_COEF}}) var<storage, read_write> mls_coef: array<f32>;
@group(0) @binding({{B_NODE_ACC}}) var<storage, read_write> node_acc: array<{{ATOMIC_T}}>;

#include "shared/atomics.wgsl" ARR=node_acc FN=node_add

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let g = linear_index(gid, nwg);
    if sim.running == 0u || g >= mls_n_gauss() {
        return;
    }
    mls_coef[3u * g] = 0.0;
    mls_coef[3u * g + 1u] = 0.0;
    mls_coef[3u * g + 2u] = 0.0;
    let gp = mls_gauss_point(g);
    if mls_occ[gp.span] == 0u {
        return;
    }
    let qg = gp.x * params.inv_h;
    let r = mls_cells_around(qg);
    // A = [a00 a01 a02; . a11 a12; . . a22]; m_f = Σ w p f for f = ρ, ρv*x, ρv*y.
    var a00 = 0.0;
    var a01 = 0.0;
    var a02 = 0.0;
    var a11 = 0.0;
    var a12 = 0.0;
    var a22 = 0.0;
    var m_rho = vec3<f32>(0.0);
    var m_qx = vec3<f32>(0.0);
    var m_qy = vec3<f32>(0.0);
    for (var j = r.lo.y; j <= r.hi.y; j++) {
        let row = j * (params.nx - 1u);
        let s = cell_start[row + r.lo.x];
        let e = cell_start[row + r.hi.x + 1u];
        for (var idx = s; idx < e; idx++) {
            let p = cell_order[idx];
            let dw = mls_sample(p, qg);
            let d = dw.xy;
            let w = dw.z;
            if w == 0.0 {
                continue;
            }
            a00 += w;
            a01 += w * d.x;
            a02 += w * d.y;
            a11 += w * d.x * d.x;
            a12 += w * d.x * d.y;
            a22 += w * d.y * d.y;
            var vel = v[p];
#if NPC
            vel += params.p2g_accel * sim.dt * a[p];
#endif
            let pb = w * vec3<f32>(1.0, d.x, d.y);
            m_rho += rho[p] * pb;
            m_qx += rho[p] * vel.x * pb;
            m_qy += rho[p] * vel.y * pb;
        }
    }
    // First column of A⁻¹ by cofactors.
    let c00 = a11 * a22 - a12 * a12;
    let c01 = a02 * a12 - a01 * a22;
    let c02 = a01 * a12 - a02 * a11;
    let det = a00 * c00 + a01 * c01 + a02 * c02;
    if !(a00 > 0.0) || !(det > MLS_SINGULAR_REL * a00 * a00 * a00) {
        report_fault(FAULT_MLS_SINGULAR, g);
        return;
    }
    let c = vec3<f32>(c00, c01, c02) / det;
    mls_coef[3u * g] = c.x;
    mls_coef[3u * g + 1u] = c.y;
    mls_coef[3u * g + 2u] = c.z;
    let fit = vec3<f32>(dot(c, m_rho), dot(c, m_qx), dot(c, m_qy)) * gp.w;
    let sc = shape_ctx(0u, gp.x);
    for (var k = 0u; k < STENCIL; k++) {
        let nw = shape_node(sc, k);
        if !nw.ok {
            continue;
        }
        let base = nw.node * NODE_STRIDE;
        node_add(base, nw.n * fit.x);
        node_add(base + 1u, nw.n * fit.y);
        node_add(base + 2u, nw.n * fit.z);
    }
}
