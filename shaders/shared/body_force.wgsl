// Body force per unit mass (m/s²) on particle p at time t (s): gravity
// (paper eq. 45 when ramped) plus, with MMS, the aligned-vibration source
// term derived in src/exact/mms.rs (`AlignedVibration::body_force`), plus,
// with EXT_FORCE, the particle's share of the tractions and point loads
// (ramped) over its mass. Needs the x0 binding, and the mass binding with
// EXT_FORCE. Also the force one particle adds to one node.

#if EXT_FORCE
// (fx, fy, ramp_time) per particle: full force (N/m) and its ramp (s).
@group(0) @binding({{B_EXT_FORCE}}) var<storage, read> ext_force: array<f32>;

fn external_force(p: u32, t: f32) -> vec2<f32> {
    let ramp = ext_force[3u * p + 2u];
    var r = 1.0;
    if ramp > 0.0 {
        r = clamp(t / ramp, 0.0, 1.0);
    }
    return r * vec2<f32>(ext_force[3u * p], ext_force[3u * p + 1u]);
}
#endif

// Gravity at time t (paper eq. 45 when ramped).
fn gravity_at(t: f32) -> vec2<f32> {
    let period = params.ramp_period;
    if period > 0.0 && t <= 0.5 * period {
        let pi = 3.14159265358979;
        return params.gravity * 0.5 * (sin(2.0 * pi * t / period - 0.5 * pi) + 1.0);
    }
    return params.gravity;
}

#if MMS
// b = (k²/4) u (4μ/ρ0 − c² + 4 (λ (1 − ln J) + μ) / (ρ0 F²)) per direction, at
// the particle's reference position; u_y runs half a period behind u_x.
fn mms_body_force(x0p: vec2<f32>, t: f32) -> vec2<f32> {
    let xr = params.mms_k * (x0p - params.mms_origin);
    let s = sin(params.mms_omega * t);
    let ak = params.mms_amp * params.mms_k;
    let fxx = 1.0 + ak * cos(xr.x) * s;
    let fyy = 1.0 - ak * cos(xr.y) * s;
    let u = params.mms_amp * vec2<f32>(sin(xr.x) * s, -sin(xr.y) * s);
    let lnj = log(fxx * fyy);
    let lead = 4.0 * params.mms_shear - params.mms_c2;
    let tail = 4.0 * (params.mms_lame * (1.0 - lnj) + params.mms_shear);
    let q = 0.25 * params.mms_k * params.mms_k;
    return q * u * vec2<f32>(lead + tail / (fxx * fxx), lead + tail / (fyy * fyy));
}
#endif

fn body_force(p: u32, t: f32) -> vec2<f32> {
#if MMS
    var b = gravity_at(t) + mms_body_force(x0[p], t);
#else
    var b = gravity_at(t);
#endif
#if EXT_FORCE
    b += external_force(p, t) / mass[p];
#endif
    return b;
}

// Stage `forces`: the force −V_p σ_p ∇N + N m_p b one particle (volume
// vol, stress s = (xx, yy, xy), body force m_p b) puts on one node (weight w).
// CPU twin: `add_particle_forces` in src/cpu/forces.rs.
fn node_force(w: NodeW, vol: f32, s: vec3<f32>, mb: vec2<f32>) -> vec2<f32> {
    return -vol * vec2<f32>(s.x * w.dn.x + s.z * w.dn.y, s.z * w.dn.x + s.y * w.dn.y) + w.n * mb;
}

#if WALK
// What forces.wgsl and the fused stress.wgsl (FORCES) put through the
// walks of shared/bins.wgsl: a particle's volume, stress and body force,
// and its `node_force` on each node. Each pass defines `bin_particle`.
alias BinSum = vec2<f32>;

struct BinParticle {
    ok: bool,
    vol: f32,
    s: vec3<f32>,
    mb: vec2<f32>,
}

fn bin_term(q: BinParticle, w: NodeW) -> BinSum {
    return node_force(w, q.vol, q.s, q.mb);
}

#if !GATHER
fn bin_add(node: u32, f: BinSum) {
    node_add(node * NODE_STRIDE + 3u, f.x);
    node_add(node * NODE_STRIDE + 4u, f.y);
}
#endif
#endif
