// Elastic-perfectly plastic Mohr–Coulomb, plane strain, with a Rankine
// tension cutoff: Jaumann trial, return in sorted principal stresses
// (main plane, edges, tension planes; de Souza Neto et al. box 8.1 as an
// active-set search), rotation back. CPU twin:
// src/model/material/mohr_coulomb.rs.
#include "shared/material_plastic.wgsl"

// A return is accepted when every yield function, ordering and −Δγ·2G is
// within this fraction of the stress scale c + max |σ_trial|. f32 round-off
// in the trial, the 3×3 solve and the update is a few 1e-7 of the scale
// (the CPU uses 1e-11 in f64); 1e-5 leaves room for the solve's condition
// number ((1 + sin φ)/(1 − sin φ) ≤ ~10 for soils).
const MC_RETURN_TOL_F32: f32 = 1e-5;

struct McPlane {
    a: vec3<f32>,
    k: f32,
    n: vec3<f32>,
}

struct McReturn {
    s: vec3<f32>,
    surfaces: u32,
}

// 0: main plane, 1: edge σ1 = σ2, 2: edge σ2 = σ3, 3–5: σ1, σ2, σ3 ≤ t.
fn mc_plane(m: Material, i: u32) -> McPlane {
    let sf = m.p[MOHR_COULOMB_SIN_PHI];
    let sp = m.p[MOHR_COULOMB_SIN_PSI];
    let k = 2.0 * m.p[MOHR_COULOMB_COHESION] * m.p[MOHR_COULOMB_COS_PHI];
    if i == 0u {
        return McPlane(vec3<f32>(1.0 + sf, 0.0, -(1.0 - sf)), k, vec3<f32>(1.0 + sp, 0.0, -(1.0 - sp)));
    }
    if i == 1u {
        return McPlane(vec3<f32>(0.0, 1.0 + sf, -(1.0 - sf)), k, vec3<f32>(0.0, 1.0 + sp, -(1.0 - sp)));
    }
    if i == 2u {
        return McPlane(vec3<f32>(1.0 + sf, -(1.0 - sf), 0.0), k, vec3<f32>(1.0 + sp, -(1.0 - sp), 0.0));
    }
    var a = vec3<f32>(0.0);
    a[i - 3u] = 1.0;
    return McPlane(a, m.p[MOHR_COULOMB_TENSION], a);
}

fn mc_f(p: McPlane, s: vec3<f32>) -> f32 {
    return dot(p.a, s) - p.k;
}

// D n in principal space.
fn mc_d_times(m: Material, n: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(m.lame * (n.x + n.y + n.z)) + 2.0 * m.shear * n;
}

// Return of sorted principal trial stresses v (twin of
// MohrCoulomb::return_principal, same candidates in the same order).
fn mc_return(m: Material, v: vec3<f32>) -> McReturn {
    let has_t = m.p[MOHR_COULOMB_TENSION] >= 0.0;
    let n_planes = select(3u, 6u, has_t);
    if mc_f(mc_plane(m, 0u), v) <= 0.0 && (!has_t || mc_f(mc_plane(m, 3u), v) <= 0.0) {
        return McReturn(v, 0u);
    }
    let scale = m.p[MOHR_COULOMB_COHESION] + max(abs(v.x), max(abs(v.y), abs(v.z)));
    let tol = MC_RETURN_TOL_F32 * scale;
    // (mask, planes) and the number of planes of each candidate.
    var cands = array<vec4<u32>, 10>(
        vec4<u32>(ACTIVE_MAIN, 0u, 0u, 0u),
        vec4<u32>(ACTIVE_T1, 3u, 0u, 0u),
        vec4<u32>(ACTIVE_MAIN | ACTIVE_EDGE_12, 0u, 1u, 0u),
        vec4<u32>(ACTIVE_MAIN | ACTIVE_EDGE_23, 0u, 2u, 0u),
        vec4<u32>(ACTIVE_MAIN | ACTIVE_T1, 0u, 3u, 0u),
        vec4<u32>(ACTIVE_T1 | ACTIVE_T2, 3u, 4u, 0u),
        vec4<u32>(ACTIVE_MAIN | ACTIVE_EDGE_12 | ACTIVE_T1, 0u, 1u, 3u),
        vec4<u32>(ACTIVE_MAIN | ACTIVE_T1 | ACTIVE_T2, 0u, 3u, 4u),
        vec4<u32>(ACTIVE_MAIN | ACTIVE_EDGE_23 | ACTIVE_T1, 0u, 2u, 3u),
        vec4<u32>(ACTIVE_T1 | ACTIVE_T2 | ACTIVE_T3, 3u, 4u, 5u),
    );
    var counts = array<u32, 10>(1u, 1u, 2u, 2u, 2u, 2u, 3u, 3u, 3u, 3u);
    var best = McReturn(v, 0u);
    var best_viol = 3.0e38;
    for (var ci = 0u; ci < 10u; ci++) {
        let cand = cands[ci];
        let count = counts[ci];
        var idx = vec3<u32>(cand.y, cand.z, cand.w);
        var skip = false;
        var dn = array<vec3<f32>, 3>(vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0));
        for (var r = 0u; r < count; r++) {
            if idx[r] >= n_planes {
                skip = true;
            } else {
                dn[r] = mc_d_times(m, mc_plane(m, idx[r]).n);
            }
        }
        if skip {
            continue;
        }
        // Columns of M (M_rc = a_r · D n_c), identity where unused.
        var cols = array<vec3<f32>, 3>(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(0.0, 0.0, 1.0));
        var rhs = vec3<f32>(0.0);
        for (var r = 0u; r < count; r++) {
            let p = mc_plane(m, idx[r]);
            rhs[r] = mc_f(p, v);
            for (var c = 0u; c < count; c++) {
                cols[c][r] = dot(p.a, dn[c]);
            }
        }
        for (var c = count; c < 3u; c++) {
            for (var r = 0u; r < count; r++) {
                cols[c][r] = 0.0;
            }
        }
        for (var c = 0u; c < count; c++) {
            for (var r = count; r < 3u; r++) {
                cols[c][r] = 0.0;
            }
        }
        let mm = mat3x3<f32>(cols[0], cols[1], cols[2]);
        let det = determinant(mm);
        if det == 0.0 || !is_finite(det) {
            continue;
        }
        var dg = vec3<f32>(0.0);
        for (var c = 0u; c < 3u; c++) {
            var mc = cols;
            mc[c] = rhs;
            dg[c] = determinant(mat3x3<f32>(mc[0], mc[1], mc[2])) / det;
        }
        var s = v;
        for (var c = 0u; c < count; c++) {
            s -= dg[c] * dn[c];
        }
        // One step of iterative refinement: the residual of the active
        // surfaces at s, solved with the same M (f32 corners of three
        // planes otherwise keep ~3e-5 of the scale).
        var res = vec3<f32>(0.0);
        for (var r = 0u; r < count; r++) {
            res[r] = mc_f(mc_plane(m, idx[r]), s);
        }
        for (var c = 0u; c < count; c++) {
            var mc = cols;
            mc[c] = res;
            let ddg = determinant(mat3x3<f32>(mc[0], mc[1], mc[2])) / det;
            dg[c] += ddg;
            s -= ddg * dn[c];
        }
        var viol = max(s.y - s.x, s.z - s.y);
        for (var c = 0u; c < count; c++) {
            viol = max(viol, -dg[c] * 2.0 * m.shear);
        }
        for (var i = 0u; i < n_planes; i++) {
            viol = max(viol, mc_f(mc_plane(m, i), s));
        }
        if viol <= tol {
            return McReturn(s, cand.x);
        }
        if viol < best_viol {
            best = McReturn(s, cand.x);
            best_viol = viol;
        }
    }
    return best;
}

fn mohr_coulomb_update(m: Material, l: vec4<f32>, dt: f32, s: vec3<f32>, f: vec4<f32>, q: vec4<f32>) -> MatUpdate {
    var r = MatUpdate(s, f, q, 1.0, 0u);
    if !plastic_volume_ratio(&r, l, dt) {
        return r;
    }
    let t = jaumann_trial(m, l, dt, s, q.x);
    // In-plane principal stresses and directions (twin of principal_return).
    let c = 0.5 * (t.x + t.y);
    let hd = 0.5 * (t.x - t.y);
    let rr = length(vec2<f32>(hd, t.w));
    var cos2 = 1.0;
    var sin2 = 0.0;
    if rr > 0.0 {
        cos2 = hd / rr;
        sin2 = t.w / rr;
    }
    var v = vec3<f32>(c + rr, c - rr, t.z);
    var idx = vec3<u32>(0u, 1u, 2u);
    if v.y > v.x {
        v = v.yxz;
        idx = idx.yxz;
    }
    if v.z > v.y {
        v = v.xzy;
        idx = idx.xzy;
    }
    if v.y > v.x {
        v = v.yxz;
        idx = idx.yxz;
    }
    let ret = mc_return(m, v);
    var out = t;
    if ret.surfaces != 0u {
        var o = vec3<f32>(0.0);
        o[idx.x] = ret.s.x;
        o[idx.y] = ret.s.y;
        o[idx.z] = ret.s.z;
        let c2 = 0.5 * (o.x + o.y);
        let r2 = 0.5 * (o.x - o.y);
        out = vec4<f32>(c2 + r2 * cos2, c2 - r2 * cos2, o.z, r2 * sin2);
    }
    r.s = vec3<f32>(out.x, out.y, out.w);
    r.q = plastic_record(m, q, t, out, ret.surfaces);
    return r;
}

// The elastic part of the stored energy, with σzz = q.x.
fn mohr_coulomb_energy(m: Material, s: vec3<f32>, f: vec4<f32>, q: vec4<f32>) -> f32 {
    return elastic_energy_3d(m, vec4<f32>(s.x, s.y, q.x, s.z));
}

// The elastic P-wave speed bounds the elastoplastic one.
fn mohr_coulomb_wave_speed(m: Material, rho: f32, s: vec3<f32>, q: vec4<f32>) -> f32 {
    return sqrt(m.p_modulus / rho);
}
