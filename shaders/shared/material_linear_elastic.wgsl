// Linear elastic, plane strain, small-strain increments.
// CPU twin: src/material/linear_elastic.rs.

fn material_of(p: u32) -> Material {
#if MULTI_MATERIAL
    return materials[mat[p]];
#else
    return materials[0];
#endif
}

// Stress [xx, yy, xy] after the increment de = [Δεxx, Δεyy, Δεxy].
fn update_stress(m: Material, s: vec3<f32>, de: vec3<f32>) -> vec3<f32> {
    let vol = m.lame * (de.x + de.y);
    return s + vec3<f32>(vol + 2.0 * m.shear * de.x, vol + 2.0 * m.shear * de.y, 2.0 * m.shear * de.z);
}

fn wave_speed(m: Material, rho: f32) -> f32 {
    return sqrt(m.p_modulus / rho);
}

fn strain_energy_density(m: Material, s: vec3<f32>) -> f32 {
    let e = m.youngs;
    let nu = m.nu;
    let exx = ((1.0 - nu * nu) * s.x - nu * (1.0 + nu) * s.y) / e;
    let eyy = ((1.0 - nu * nu) * s.y - nu * (1.0 + nu) * s.x) / e;
    let exy = s.z / (2.0 * m.shear);
    return 0.5 * (s.x * exx + s.y * eyy + 2.0 * s.z * exy);
}
