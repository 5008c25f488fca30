// Stage `stress` with solver.mls_scope = "force": each particle q's
// strain-rate correction, the transpose of the force's bracket,
//   V_q ΔL_q = Σ_{g ok} ω_g φ_q(x_g) L(x_g) − Σ_{p ok} V_p φ_q(x_p) L_p,
// φ_q(x) = w(x_q − x) c(x) · [1, (x_q − x)/h] with c the fit's A⁻¹e₀ at x
// (mls_fit.wgsl: mls_coef for Gauss points, mls_fit for particles) and
// ω_g L(x_g), V_p L_p from mls_grad.wgsl; "ok": integration cells whose fits
// are all regular (mls_occ == 1). stress.wgsl (MLS_FORCE) adds ΔL_q to
// L_q, so the stress does the corrected forces' work. Positions are the
// fit's (MUSL: x_start), the particles found through the fit's bins.
// CPU twin: `Mls::strain_correction` (src/cpu/mls.rs).
#include "shared/common.wgsl"
#include "shared/mls.wgsl"

@group(0) @binding({{B_X0}}) var<storage, read> x0: array<vec2<f32>>;
@group(0) @binding({{B_U}}) var<storage, read> u: array<vec2<f32>>;
#if MUSL
@group(0) @binding({{B_X_START}}) var<storage, read> x_start: array<vec2<f32>>;
#endif
@group(0) @binding({{B_MASS}}) var<storage, read> mass: array<f32>;
@group(0) @binding({{B_RHO}}) var<storage, read> rho: array<f32>;
@group(0) @binding({{B_CELL_START}}) var<storage, read> cell_start: array<u32>;
@group(0) @binding({{B_CELL_ORDER}}) var<storage, read> cell_order: array<u32>;
@group(0) @binding({{B_MLS_OCC}}) var<storage, read> mls_occ: array<u32>;
@group(0) @binding({{B_MLS_COEF}}) var<storage, read> mls_coef: array<f32>;
@group(0) @binding({{B_MLS_FIT}}) var<storage, read> mls_fit: array<f32>;
@group(0) @binding({{B_MLS_GRAD}}) var<storage, read> mls_grad: array<vec4<f32>>;
@group(0) @binding({{B_MLS_DL}}) var<storage, read_write> mls_dl: array<vec4<f32>>;

fn fit_pos(p: u32) -> vec2<f32> {
#if MUSL
    return x_start[p];
#else
    return x0[p] + u[p];
#endif
}

// φ_q(x) for a fit with c at a point whose offset from x_q is d (units of h).
fn phi(d: vec2<f32>, c: vec3<f32>) -> f32 {
    let s = params.mls_weight_scale;
    let w = mls_weight(s * abs(d.x)) * mls_weight(s * abs(d.y));
    return w * (c.x + c.y * d.x + c.z * d.y);
}

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let q = linear_index(gid, nwg);
    if sim.running == 0u || q >= params.n_particles {
        return;
    }
    let xq = fit_pos(q);
    let uq = xq * params.inv_h;
    var acc = vec4<f32>(0.0);
    // Gauss points within the weight's reach.
    let reach = 1.5 / params.mls_weight_scale;
    let sx0 = mls_span_of(uq.x - reach, params.mls_spans_x);
    let sx1 = mls_span_of(uq.x + reach, params.mls_spans_x);
    let sy0 = mls_span_of(uq.y - reach, params.mls_spans_y);
    let sy1 = mls_span_of(uq.y + reach, params.mls_spans_y);
    for (var sy = sy0; sy <= sy1; sy++) {
        for (var sx = sx0; sx <= sx1; sx++) {
            let span = sy * params.mls_spans_x + sx;
            if mls_occ[span] != 1u {
                continue;
            }
            for (var g = 4u * span; g < 4u * span + 4u; g++) {
                let gp = mls_gauss_point(g);
                let c = vec3<f32>(mls_coef[6u * g + 3u], mls_coef[6u * g + 4u], mls_coef[6u * g + 5u]);
                acc += phi((xq - gp.x) * params.inv_h, c) * mls_grad[g];
            }
        }
    }
    // Particles within the weight's reach (the fit's bins).
    let r = mls_cells_around(uq);
    let ng = mls_n_gauss();
    for (var j = r.lo.y; j <= r.hi.y; j++) {
        let row = j * (params.nx - 1u);
        let s = cell_start[row + r.lo.x];
        let e = cell_start[row + r.hi.x + 1u];
        for (var idx = s; idx < e; idx++) {
            let p = cell_order[idx];
            let vl = mls_grad[ng + p];
            if all(vl == vec4<f32>(0.0)) {
                continue;
            }
            let c = vec3<f32>(mls_fit[6u * p + 3u], mls_fit[6u * p + 4u], mls_fit[6u * p + 5u]);
            acc -= phi((xq - fit_pos(p)) * params.inv_h, c) * vl;
        }
    }
    mls_dl[q] = acc * (rho[q] / mass[q]);
}
