// The material interface: the models a scene uses are compiled in
// (MAT_LINEAR_ELASTIC, MAT_NEO_HOOKEAN, MAT_MOHR_COULOMB,
// MAT_DRUCKER_PRAGER) and chosen per particle by Material.model.
// CPU twin: src/model/material/mod.rs.
#include "shared/material_bindings.wgsl"

const MODEL_LINEAR_ELASTIC: u32 = 0u;
const MODEL_NEO_HOOKEAN: u32 = 1u;
const MODEL_MOHR_COULOMB: u32 = 2u;
const MODEL_DRUCKER_PRAGER: u32 = 3u;

// Result of one constitutive step: stress, deformation gradient (xx, xy,
// yx, yy), plastic state (σzz, ε̄p, εp_v, active surfaces), volume ratio
// V_new/V_old, and a fault code (0 = none).
struct MatUpdate {
    s: vec3<f32>,
    f: vec4<f32>,
    q: vec4<f32>,
    j: f32,
    fault: u32,
}

#if MAT_LINEAR_ELASTIC
#include "shared/material_linear_elastic.wgsl"
#endif
#if MAT_NEO_HOOKEAN
#include "shared/material_neo_hookean.wgsl"
#endif
#if MAT_MOHR_COULOMB
#include "shared/material_mohr_coulomb.wgsl"
#endif
#if MAT_DRUCKER_PRAGER
#include "shared/material_drucker_prager.wgsl"
#endif

fn material_of(p: u32) -> Material {
#if MULTI_MATERIAL
    return materials[mat[p]];
#else
    return materials[0];
#endif
}

// l = velocity gradient (xx, xy, yx, yy); q = plastic state (ignored by
// the elastic models).
fn material_update(m: Material, l: vec4<f32>, dt: f32, s: vec3<f32>, f: vec4<f32>, q: vec4<f32>) -> MatUpdate {
    var r = MatUpdate(s, f, q, 1.0, 0u);
#if MAT_LINEAR_ELASTIC
    if m.model == MODEL_LINEAR_ELASTIC {
        let de = vec3<f32>(dt * l.x, dt * l.w, 0.5 * dt * (l.y + l.z));
        r.j = 1.0 + de.x + de.y;
        if !is_finite(r.j) {
            r.fault = FAULT_NON_FINITE_STRAIN;
        } else if r.j <= 0.0 {
            r.fault = FAULT_DENSITY;
        } else {
            r.s = linear_elastic_update(m, s, de);
        }
        return r;
    }
#endif
#if MAT_NEO_HOOKEAN
    if m.model == MODEL_NEO_HOOKEAN {
        return neo_hookean_update(m, l, dt, f, q);
    }
#endif
#if MAT_MOHR_COULOMB
    if m.model == MODEL_MOHR_COULOMB {
        return mohr_coulomb_update(m, l, dt, s, f, q);
    }
#endif
#if MAT_DRUCKER_PRAGER
    if m.model == MODEL_DRUCKER_PRAGER {
        return drucker_prager_update(m, l, dt, s, f, q);
    }
#endif
    return r;
}

fn wave_speed(m: Material, rho: f32) -> f32 {
    return sqrt(m.p_modulus / rho);
}

// Stored energy per unit current volume (plastic models: the elastic part,
// with σzz = q.x).
fn strain_energy_density(m: Material, s: vec3<f32>, f: vec4<f32>, q: vec4<f32>) -> f32 {
#if MAT_MOHR_COULOMB
    if m.model == MODEL_MOHR_COULOMB {
        return elastic_energy_3d(m, vec4<f32>(s.x, s.y, q.x, s.z));
    }
#endif
#if MAT_DRUCKER_PRAGER
    if m.model == MODEL_DRUCKER_PRAGER {
        return elastic_energy_3d(m, vec4<f32>(s.x, s.y, q.x, s.z));
    }
#endif
#if MAT_LINEAR_ELASTIC
    if m.model == MODEL_LINEAR_ELASTIC {
        return linear_elastic_energy(m, s);
    }
#endif
#if MAT_NEO_HOOKEAN
    if m.model == MODEL_NEO_HOOKEAN {
        return neo_hookean_energy(m, f);
    }
#endif
    return 0.0;
}
