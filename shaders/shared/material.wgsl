// The material interface: MatUpdate and the dispatch on Material.model
// (`material_update`, `strain_energy_density`, `wave_speed`), generated
// from the registry (src/model/material/registry.rs) with only the models
// a scene uses compiled in; each model's functions live in
// shared/material_<name>.wgsl. CPU twin: src/model/material/mod.rs.
#include "shared/material_bindings.wgsl"

// Result of one constitutive step: stress, deformation gradient (xx, xy,
// yx, yy), plastic state (the model's four numbers: σzz first, the active
// surfaces last), volume ratio V_new/V_old, and a fault code (0 = none).
struct MatUpdate {
    s: vec3<f32>,
    f: vec4<f32>,
    q: vec4<f32>,
    j: f32,
    fault: u32,
}

fn material_of(p: u32) -> Material {
#if MULTI_MATERIAL
    return materials[mat[p]];
#else
    return materials[0];
#endif
}

#include "generated/materials.wgsl"
