// Linear elastic, plane strain, small-strain increments.
// CPU twin: src/material/linear_elastic.rs.

// Stress [xx, yy, xy] after the increment de = [Δεxx, Δεyy, Δεxy].
fn linear_elastic_update(m: Material, s: vec3<f32>, de: vec3<f32>) -> vec3<f32> {
    let vol = m.lame * (de.x + de.y);
    return s + vec3<f32>(vol + 2.0 * m.shear * de.x, vol + 2.0 * m.shear * de.y, 2.0 * m.shear * de.z);
}

fn linear_elastic_energy(m: Material, s: vec3<f32>) -> f32 {
    let e = m.youngs;
    let nu = m.nu;
    let exx = ((1.0 - nu * nu) * s.x - nu * (1.0 + nu) * s.y) / e;
    let eyy = ((1.0 - nu * nu) * s.y - nu * (1.0 + nu) * s.x) / e;
    let exy = s.z / (2.0 * m.shear);
    return 0.5 * (s.x * exx + s.y * eyy + 2.0 * s.z * exy);
}
