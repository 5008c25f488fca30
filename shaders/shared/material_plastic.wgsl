// What the plastic models share: the plastic state
// q = (σzz, ε̄p, εp_v, last return's active surfaces), the elastic trial on
// the Jaumann rate, the plastic strain of a return, the elastic energy with
// σzz. Stresses with σzz are (xx, yy, zz, xy).
// CPU twin: src/model/material/plastic.rs.

// Bits of q.w (mirrored in Rust, compared by tests/gpu_shaders.rs).
const ACTIVE_MAIN: u32 = 1u;
const ACTIVE_EDGE_12: u32 = 2u;
const ACTIVE_EDGE_23: u32 = 4u;
const ACTIVE_T1: u32 = 8u;
const ACTIVE_T2: u32 = 16u;
const ACTIVE_T3: u32 = 32u;

// σ + Δt (Wσ − σW) + D : Δε, W = skew(L), Δε = Δt sym(L), Δεzz = 0.
fn jaumann_trial(m: Material, l: vec4<f32>, dt: f32, s: vec3<f32>, szz: f32) -> vec4<f32> {
    let w = 0.5 * dt * (l.y - l.z);
    let de = vec3<f32>(dt * l.x, dt * l.w, 0.5 * dt * (l.y + l.z));
    let vol = m.lame * (de.x + de.y);
    return vec4<f32>(
        s.x + 2.0 * w * s.z + vol + 2.0 * m.shear * de.x,
        s.y - 2.0 * w * s.z + vol + 2.0 * m.shear * de.y,
        szz + vol,
        s.z + w * (s.y - s.x) + 2.0 * m.shear * de.z,
    );
}

// (Δε̄p, Δεp_v) of the return from `trial` to `s`: Δεp = C : (σ_trial − σ).
fn plastic_increment(m: Material, trial: vec4<f32>, s: vec4<f32>) -> vec2<f32> {
    let d = trial - s;
    let dp = (d.x + d.y + d.z) / 3.0;
    let g2 = 2.0 * m.shear;
    let dev = vec4<f32>(d.x - dp, d.y - dp, d.z - dp, d.w) / g2;
    let dv = dp / m.bulk;
    let e = dev.xyz + vec3<f32>(dv / 3.0);
    let norm2 = dot(e, e) + 2.0 * dev.w * dev.w;
    return vec2<f32>(sqrt(2.0 / 3.0 * norm2), dv);
}

// The state after a return (twin of plastic::record).
fn plastic_record(m: Material, q: vec4<f32>, trial: vec4<f32>, s: vec4<f32>, surfaces: u32) -> vec4<f32> {
    var inc = vec2<f32>(0.0);
    if surfaces != 0u {
        inc = plastic_increment(m, trial, s);
    }
    return vec4<f32>(s.z, q.y + inc.x, q.z + inc.y, f32(surfaces));
}

// 1 + tr Δε, or a fault.
fn plastic_volume_ratio(r: ptr<function, MatUpdate>, l: vec4<f32>, dt: f32) -> bool {
    (*r).j = 1.0 + dt * (l.x + l.w);
    if !is_finite((*r).j) {
        (*r).fault = FAULT_NON_FINITE_STRAIN;
        return false;
    }
    if (*r).j <= 0.0 {
        (*r).fault = FAULT_DENSITY;
        return false;
    }
    return true;
}

// ½ σ : C : σ = s : s / (4G) + p² / (2K).
fn elastic_energy_3d(m: Material, s: vec4<f32>) -> f32 {
    let p = (s.x + s.y + s.z) / 3.0;
    let d = s.xyz - vec3<f32>(p);
    return (dot(d, d) + 2.0 * s.w * s.w) / (4.0 * m.shear) + p * p / (2.0 * m.bulk);
}
