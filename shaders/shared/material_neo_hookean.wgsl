// Compressible Neo-Hookean, plane strain, on F = (xx, xy, yx, yy):
// F ← (I + Δt L) F, σ = λ ln J / J I + μ / J (F Fᵀ − I).
// CPU twin: src/model/material/neo_hookean.rs.

fn neo_hookean_update(m: Material, l: vec4<f32>, dt: f32, s: vec3<f32>, f: vec4<f32>, q: vec4<f32>) -> MatUpdate {
    let g = vec4<f32>(1.0 + dt * l.x, dt * l.y, dt * l.z, 1.0 + dt * l.w);
    let nf = vec4<f32>(
        g.x * f.x + g.y * f.z,
        g.x * f.y + g.y * f.w,
        g.z * f.x + g.w * f.z,
        g.z * f.y + g.w * f.w,
    );
    let j_old = f.x * f.w - f.y * f.z;
    let j = nf.x * nf.w - nf.y * nf.z;
    var r = MatUpdate(vec3<f32>(0.0), f, q, 1.0, 0u);
    if !is_finite(j) {
        r.fault = FAULT_NON_FINITE_STRAIN;
        return r;
    }
    if j <= 0.0 {
        r.fault = FAULT_DENSITY;
        return r;
    }
    let bxx = nf.x * nf.x + nf.y * nf.y;
    let byy = nf.z * nf.z + nf.w * nf.w;
    let bxy = nf.x * nf.z + nf.y * nf.w;
    let vol = m.lame * log(j) / j;
    let sh = m.shear / j;
    r.s = vec3<f32>(vol + sh * (bxx - 1.0), vol + sh * (byy - 1.0), sh * bxy);
    r.f = nf;
    r.j = j / j_old;
    return r;
}

fn neo_hookean_energy(m: Material, s: vec3<f32>, f: vec4<f32>, q: vec4<f32>) -> f32 {
    let j = f.x * f.w - f.y * f.z;
    let tr_c = dot(f, f) + 1.0;
    let lj = log(j);
    return (0.5 * m.shear * (tr_c - 3.0) - m.shear * lj + 0.5 * m.lame * lj * lj) / j;
}

// Small-strain P-wave speed sqrt((λ + 2μ)/ρ).
fn neo_hookean_wave_speed(m: Material, rho: f32, s: vec3<f32>, q: vec4<f32>) -> f32 {
    return sqrt(m.p_modulus / rho);
}
