// Stage `forces` with solver.mls_scope = "force", the fit of σ: one
// invocation per Gauss point g, or, built with PARTICLES, per particle p:
// σ_h at its position by moving least squares over the particles within
// the weight's reach (basis [1, Δx, Δy] in units of h, shared/mls.wgsl's
// weight), each point with its own moment matrix. A singular matrix marks
// the point's integration cell (mls_occ |= 2), which mls_force_gauss and
// forces (MLS_FORCE) then leave out of both sums. Gauss points: σ_h(x_g)
// and c = A⁻¹e₀ into mls_coef[6g..6g+6]; particles: σ_h(x_p) and c into
// mls_fit[6p..6p+6]. In stage `stress` (update stress first) the same
// passes give mls_strain.wgsl its c's.
// CPU twin: `Mls::fit_stress` (src/cpu/mls.rs).
#include "shared/common.wgsl"
#include "shared/mls.wgsl"

@group(0) @binding({{B_X0}}) var<storage, read> x0: array<vec2<f32>>;
@group(0) @binding({{B_U}}) var<storage, read> u: array<vec2<f32>>;
@group(0) @binding({{B_STRESS}}) var<storage, read> stress: array<f32>;
@group(0) @binding({{B_CELL_START}}) var<storage, read> cell_start: array<u32>;
@group(0) @binding({{B_CELL_ORDER}}) var<storage, read> cell_order: array<u32>;
@group(0) @binding({{B_MLS_OCC}}) var<storage, read_write> mls_occ: array<atomic<u32>>;
#if PARTICLES
@group(0) @binding({{B_MLS_FIT}}) var<storage, read_write> mls_fit: array<f32>;
#else
@group(0) @binding({{B_MLS_COEF}}) var<storage, read_write> mls_coef: array<f32>;
#endif

struct Fit {
    ok: bool,
    s: vec3<f32>,
    // c = A⁻¹e₀ (mls_strain.wgsl's weights φ_q(x) = w (c · [1, Δ])).
    c: vec3<f32>,
}

// The fit of σ at x (m, grid-relative).
fn fit_at(x: vec2<f32>) -> Fit {
    let q = x * params.inv_h;
    let r = mls_cells_around(q);
    var a00 = 0.0;
    var a01 = 0.0;
    var a02 = 0.0;
    var a11 = 0.0;
    var a12 = 0.0;
    var a22 = 0.0;
    var m_xx = vec3<f32>(0.0);
    var m_yy = vec3<f32>(0.0);
    var m_xy = vec3<f32>(0.0);
    for (var j = r.lo.y; j <= r.hi.y; j++) {
        let row = j * (params.nx - 1u);
        let s = cell_start[row + r.lo.x];
        let e = cell_start[row + r.hi.x + 1u];
        for (var idx = s; idx < e; idx++) {
            let p = cell_order[idx];
            let dw = mls_sample(p, q);
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
            let pb = w * vec3<f32>(1.0, d.x, d.y);
            m_xx += stress[3u * p] * pb;
            m_yy += stress[3u * p + 1u] * pb;
            m_xy += stress[3u * p + 2u] * pb;
        }
    }
    let c00 = a11 * a22 - a12 * a12;
    let c01 = a02 * a12 - a01 * a22;
    let c02 = a01 * a12 - a02 * a11;
    let det = a00 * c00 + a01 * c01 + a02 * c02;
    if !(a00 > 0.0) || !(det > MLS_SINGULAR_REL * a00 * a00 * a00) {
        return Fit(false, vec3<f32>(0.0), vec3<f32>(0.0));
    }
    let c = vec3<f32>(c00, c01, c02) / det;
    return Fit(true, vec3<f32>(dot(c, m_xx), dot(c, m_yy), dot(c, m_xy)), c);
}

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
#if PARTICLES
    let p = linear_index(gid, nwg);
    if sim.running == 0u || p >= params.n_particles {
        return;
    }
    let x = x0[p] + u[p];
    let f = fit_at(x);
    mls_fit[6u * p] = f.s.x;
    mls_fit[6u * p + 1u] = f.s.y;
    mls_fit[6u * p + 2u] = f.s.z;
    mls_fit[6u * p + 3u] = f.c.x;
    mls_fit[6u * p + 4u] = f.c.y;
    mls_fit[6u * p + 5u] = f.c.z;
    if !f.ok {
        let q = x * params.inv_h;
        let span = mls_span_of(q.y, params.mls_spans_y) * params.mls_spans_x + mls_span_of(q.x, params.mls_spans_x);
        atomicOr(&mls_occ[span], 2u);
    }
#else
    let g = linear_index(gid, nwg);
    if sim.running == 0u || g >= mls_n_gauss() {
        return;
    }
    for (var k = 0u; k < 6u; k++) {
        mls_coef[6u * g + k] = 0.0;
    }
    let gp = mls_gauss_point(g);
    if atomicLoad(&mls_occ[gp.span]) == 0u {
        return;
    }
    let f = fit_at(gp.x);
    if !f.ok {
        atomicOr(&mls_occ[gp.span], 2u);
        return;
    }
    mls_coef[6u * g] = f.s.x;
    mls_coef[6u * g + 1u] = f.s.y;
    mls_coef[6u * g + 2u] = f.s.z;
    mls_coef[6u * g + 3u] = f.c.x;
    mls_coef[6u * g + 4u] = f.c.y;
    mls_coef[6u * g + 5u] = f.c.z;
#endif
}
