// The material interface: the models a scene uses are compiled in
// (MAT_LINEAR_ELASTIC, MAT_NEO_HOOKEAN) and chosen per particle by
// Material.model. CPU twin: src/material/mod.rs.
#include "shared/material_bindings.wgsl"

const MODEL_LINEAR_ELASTIC: u32 = 0u;
const MODEL_NEO_HOOKEAN: u32 = 1u;

#if MAT_LINEAR_ELASTIC
#include "shared/material_linear_elastic.wgsl"
#endif
#if MAT_NEO_HOOKEAN
#include "shared/material_neo_hookean.wgsl"
#endif

fn material_of(p: u32) -> Material {
#if MULTI_MATERIAL
    return materials[mat[p]];
#else
    return materials[0];
#endif
}

// Result of one constitutive step: stress, deformation gradient (xx, xy,
// yx, yy), volume ratio V_new/V_old, and a fault code (0 = none).
struct MatUpdate {
    s: vec3<f32>,
    f: vec4<f32>,
    j: f32,
    fault: u32,
}

// l = velocity gradient (xx, xy, yx, yy).
fn material_update(m: Material, l: vec4<f32>, dt: f32, s: vec3<f32>, f: vec4<f32>) -> MatUpdate {
    var r = MatUpdate(s, f, 1.0, 0u);
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
        return neo_hookean_update(m, l, dt, f);
    }
#endif
    return r;
}

fn wave_speed(m: Material, rho: f32) -> f32 {
    return sqrt(m.p_modulus / rho);
}

// Stored energy per unit current volume.
fn strain_energy_density(m: Material, s: vec3<f32>, f: vec4<f32>) -> f32 {
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
