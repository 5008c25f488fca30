// Elastic-perfectly plastic Drucker–Prager matched to Mohr–Coulomb in plane
// strain (α, ᾱ, k in Material), with a cap p ≤ t on the mean stress:
// Jaumann trial, cone return, cap or corner. CPU twin:
// src/model/material/drucker_prager.rs.
#include "shared/material_plastic.wgsl"

struct DpReturn {
    s: vec4<f32>,
    surfaces: u32,
}

// (p, sqrt J2) of (xx, yy, zz, xy).
fn dp_p_sqrt_j2(s: vec4<f32>) -> vec2<f32> {
    let p = (s.x + s.y + s.z) / 3.0;
    let d = s.xyz - vec3<f32>(p);
    return vec2<f32>(p, sqrt(0.5 * dot(d, d) + s.w * s.w));
}

// t with mean stress p_new and sqrt J2 scaled from sj2 to sj2_new.
fn dp_with(t: vec4<f32>, p: f32, sj2: f32, p_new: f32, sj2_new: f32) -> vec4<f32> {
    var r = 0.0;
    if sj2 > 0.0 {
        r = sj2_new / sj2;
    }
    return vec4<f32>(vec3<f32>(p_new) + r * (t.xyz - vec3<f32>(p)), r * t.w);
}

fn dp_return(m: Material, t: vec4<f32>) -> DpReturn {
    let inv = dp_p_sqrt_j2(t);
    let p = inv.x;
    let sj2 = inv.y;
    let f = sj2 + 3.0 * m.p[DRUCKER_PRAGER_ALPHA] * p - m.p[DRUCKER_PRAGER_K];
    let has_cap = m.p[DRUCKER_PRAGER_TENSION] >= 0.0;
    let cap = m.p[DRUCKER_PRAGER_TENSION];
    if f <= 0.0 && (!has_cap || p <= cap) {
        return DpReturn(t, 0u);
    }
    if f > 0.0 {
        let dg = f / (m.shear + 9.0 * m.bulk * m.p[DRUCKER_PRAGER_ALPHA] * m.p[DRUCKER_PRAGER_ALPHA_PSI]);
        let sj2_new = sj2 - m.shear * dg;
        let p_new = p - 3.0 * m.bulk * m.p[DRUCKER_PRAGER_ALPHA_PSI] * dg;
        if sj2_new >= 0.0 && (!has_cap || p_new <= cap) {
            return DpReturn(dp_with(t, p, sj2, p_new, sj2_new), ACTIVE_MAIN);
        }
    }
    if has_cap && p > cap && sj2 + 3.0 * m.p[DRUCKER_PRAGER_ALPHA] * cap - m.p[DRUCKER_PRAGER_K] <= 0.0 {
        return DpReturn(dp_with(t, p, sj2, cap, sj2), ACTIVE_T1);
    }
    let sj2_new = max(m.p[DRUCKER_PRAGER_K] - 3.0 * m.p[DRUCKER_PRAGER_ALPHA] * cap, 0.0);
    return DpReturn(dp_with(t, p, sj2, cap, min(sj2_new, sj2)), ACTIVE_MAIN | ACTIVE_T1);
}

fn drucker_prager_update(m: Material, l: vec4<f32>, dt: f32, s: vec3<f32>, f: vec4<f32>, q: vec4<f32>) -> MatUpdate {
    var r = MatUpdate(s, f, q, 1.0, 0u);
    if !plastic_volume_ratio(&r, l, dt) {
        return r;
    }
    let t = jaumann_trial(m, l, dt, s, q.x);
    let ret = dp_return(m, t);
    r.s = vec3<f32>(ret.s.x, ret.s.y, ret.s.w);
    r.q = plastic_record(m, q, t, ret.s, ret.surfaces);
    return r;
}

// The elastic part of the stored energy, with σzz = q.x.
fn drucker_prager_energy(m: Material, s: vec3<f32>, f: vec4<f32>, q: vec4<f32>) -> f32 {
    return elastic_energy_3d(m, vec4<f32>(s.x, s.y, q.x, s.z));
}

// The elastic P-wave speed bounds the elastoplastic one.
fn drucker_prager_wave_speed(m: Material, rho: f32, s: vec3<f32>, q: vec4<f32>) -> f32 {
    return sqrt(m.p_modulus / rho);
}
