// Linear elastic, plane strain, small-strain increments.
// CPU twin: src/model/material/linear_elastic.rs.

// Stress [xx, yy, xy] after the increment de = [Δεxx, Δεyy, Δεxy].
fn linear_elastic_stress(m: Material, s: vec3<f32>, de: vec3<f32>) -> vec3<f32> {
    let vol = m.lame * (de.x + de.y);
    return s + vec3<f32>(vol + 2.0 * m.shear * de.x, vol + 2.0 * m.shear * de.y, 2.0 * m.shear * de.z);
}

fn linear_elastic_update(m: Material, l: vec4<f32>, dt: f32, s: vec3<f32>, f: vec4<f32>, q: vec4<f32>) -> MatUpdate {
    var r = MatUpdate(s, f, q, 1.0, 0u);
    let de = vec3<f32>(dt * l.x, dt * l.w, 0.5 * dt * (l.y + l.z));
    r.j = 1.0 + de.x + de.y;
    if !is_finite(r.j) {
        r.fault = FAULT_NON_FINITE_STRAIN;
    } else if r.j <= 0.0 {
        r.fault = FAULT_DENSITY;
    } else {
        r.s = linear_elastic_stress(m, s, de);
    }
    return r;
}

fn linear_elastic_energy(m: Material, s: vec3<f32>, f: vec4<f32>, q: vec4<f32>) -> f32 {
    let e = m.youngs;
    let nu = m.nu;
    let exx = ((1.0 - nu * nu) * s.x - nu * (1.0 + nu) * s.y) / e;
    let eyy = ((1.0 - nu * nu) * s.y - nu * (1.0 + nu) * s.x) / e;
    let exy = s.z / (2.0 * m.shear);
    return 0.5 * (s.x * exx + s.y * eyy + 2.0 * s.z * exy);
}

// P-wave speed sqrt((λ + 2μ)/ρ).
fn linear_elastic_wave_speed(m: Material, rho: f32, s: vec3<f32>, q: vec4<f32>) -> f32 {
    return sqrt(m.p_modulus / rho);
}
