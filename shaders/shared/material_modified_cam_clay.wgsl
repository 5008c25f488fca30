// Modified Cam-clay, plane strain, tension positive: exact integration of
// the unloading line (K = v p′/κ) and of the hardening (λ), associated
// ellipse f = q²/M² + p′(p′ − p_c), closest-point return by Newton on
// (ln p′, ln p_c, Δγ) (a step split into 8, then 64 parts when it does not
// converge), tension to the apex σ = 0. Plastic state
// q = (σzz, p_c, v, return). Stresses with σzz are (xx, yy, zz, xy).
// Needs only shared/common.wgsl (FAULT_* codes, Material, is_finite).
// CPU twin: src/model/material/modified_cam_clay.rs.

// Newton converges when every scaled residual is below this (the CPU's
// RETURN_TOL_F32; f64 uses 1e-11): f32 residuals round off at
// ~1e-7 · |ln p′/p_c| (≤ ~20).
const MCC_RETURN_TOL: f32 = 1e-5;
// Newton iterations before a fault (MAX_ITER).
const MCC_MAX_ITER: u32 = 40u;
// The splits of a step tried in turn (SUBSTEPS).
const MCC_SUBSTEPS: array<u32, 3> = array<u32, 3>(1u, 8u, 64u);
// Returns recorded in q.w: the ellipse and the tension apex (the values of
// ACTIVE_MAIN and ACTIVE_T1 | ACTIVE_T2 | ACTIVE_T3 in material_plastic.wgsl,
// which this file does not include).
const MCC_RETURN_ELLIPSE: u32 = 1u;
const MCC_RETURN_APEX: u32 = 56u;
// Fault code of a return that did not converge (FaultKind::ReturnNotConverged);
// not among the FAULT_* codes of types.wgsl yet.
const MCC_FAULT_NOT_CONVERGED: u32 = FAULT_RETURN_NOT_CONVERGED;

// The model's parameters, in ModifiedCamClay::packed order.
struct MccParams {
    kappa: f32,
    lambda: f32,
    // Critical-state ratio M.
    m_cs: f32,
    nu: f32,
    // Constant shear modulus G (Pa); 0: from K and ν.
    shear: f32,
    // Pressure floor of the stiffness (Pa).
    p_floor: f32,
    // ρ0 v0 (kg/m³): v = rho_v0 / ρ.
    rho_v0: f32,
    // v on the NCL at p′ = 1 Pa: N + λ ln(1000).
    n_pa: f32,
}

// The parameters from the material record (its registry entry's
// GPU_PARAMS, packed by ModifiedCamClay::packed).
fn mcc_params(m: Material) -> MccParams {
    return MccParams(
        m.p[MODIFIED_CAM_CLAY_KAPPA],
        m.p[MODIFIED_CAM_CLAY_LAMBDA],
        m.p[MODIFIED_CAM_CLAY_M_CS],
        m.p[MODIFIED_CAM_CLAY_NU],
        m.p[MODIFIED_CAM_CLAY_SHEAR],
        m.p[MODIFIED_CAM_CLAY_P_FLOOR],
        m.p[MODIFIED_CAM_CLAY_RHO_V0],
        m.p[MODIFIED_CAM_CLAY_N_PA],
    );
}

struct MccStep {
    s: vec4<f32>,
    q: vec4<f32>,
    fault: u32,
}

// Result of mcc_update: in-plane stress, plastic state, V_new/V_old, fault
// (0 = none).
struct MccUpdate {
    s: vec3<f32>,
    q: vec4<f32>,
    j: f32,
    fault: u32,
}

fn mcc_bulk(m: MccParams, p: f32, v: f32) -> f32 {
    return v * max(p, m.p_floor) / m.kappa;
}

fn mcc_shear_at(m: MccParams, k: f32) -> f32 {
    if m.shear > 0.0 {
        return m.shear;
    }
    return 1.5 * k * (1.0 - 2.0 * m.nu) / (1.0 + m.nu);
}

fn mcc_yield(m: MccParams, p: f32, q: f32, pc: f32) -> f32 {
    return q * q / (m.m_cs * m.m_cs) + p * (p - pc);
}

fn mcc_det3(a: vec3<f32>, b: vec3<f32>, c: vec3<f32>) -> f32 {
    return dot(a, cross(b, c));
}

// Solves the 3×3 system with rows r0, r1, r2 by Cramer's rule; w of the
// result is 0 when singular (twin of mohr_coulomb::solve3).
fn mcc_solve3(r0: vec3<f32>, r1: vec3<f32>, r2: vec3<f32>, b: vec3<f32>) -> vec4<f32> {
    // Columns.
    let c0 = vec3<f32>(r0.x, r1.x, r2.x);
    let c1 = vec3<f32>(r0.y, r1.y, r2.y);
    let c2 = vec3<f32>(r0.z, r1.z, r2.z);
    let d = mcc_det3(c0, c1, c2);
    if d == 0.0 || !is_finite(d) {
        return vec4<f32>(0.0);
    }
    return vec4<f32>(mcc_det3(b, c1, c2) / d, mcc_det3(c0, b, c2) / d, mcc_det3(c0, c1, b) / d, 1.0);
}

// One step from the rotated stress s with the strain increment de (both
// xx, yy, zz, xy), split into 8 then 64 parts (volume ratios multiplying
// to 1 + tr Δε) should the return not converge: the twin of
// ModifiedCamClay::step.
fn mcc_step(m: MccParams, s: vec4<f32>, de: vec4<f32>, q: vec4<f32>) -> MccStep {
    var r = MccStep(s, q, MCC_FAULT_NOT_CONVERGED);
    for (var k = 0u; k < 3u; k++) {
        let n = MCC_SUBSTEPS[k];
        let ev = de.x + de.y + de.z;
        // Diagonal scale c: (1 + c ev / n)^n = 1 + ev.
        var c = 1.0 / f32(n);
        if ev != 0.0 && n > 1u {
            c = (pow(1.0 + ev, 1.0 / f32(n)) - 1.0) / ev;
        }
        let d = vec4<f32>(c * de.xyz, de.w / f32(n));
        r = MccStep(s, q, 0u);
        for (var i = 0u; i < n; i++) {
            let st = mcc_step_once(m, r.s, d, r.q);
            if st.fault != 0u {
                r = MccStep(s, q, st.fault);
                break;
            }
            r = st;
        }
        if r.fault != MCC_FAULT_NOT_CONVERGED {
            return r;
        }
    }
    return r;
}

// One step without substeps (twin of ModifiedCamClay::step_once).
fn mcc_step_once(m: MccParams, s: vec4<f32>, de: vec4<f32>, q: vec4<f32>) -> MccStep {
    let v = q.z;
    let pc = q.y;
    let p_n = -(s.x + s.y + s.z) / 3.0;
    let pb = max(p_n, m.p_floor);
    let g = mcc_shear_at(m, mcc_bulk(m, p_n, v));
    let ev = de.x + de.y + de.z;
    let v_new = v * (1.0 + ev);
    // Elastic trial: p′ exact along the unloading line (from p_floor below
    // it), s by 2G Δe; p_n e^x does not cancel to 0 in a large extension.
    let ex = exp(-v * ev / m.kappa);
    var p_tr = p_n + pb * (ex - 1.0);
    if p_n >= m.p_floor {
        p_tr = p_n * ex;
    }
    let sd = vec4<f32>(s.xyz + vec3<f32>(p_n) + 2.0 * g * (de.xyz - vec3<f32>(ev / 3.0)), s.w + 2.0 * g * de.w);
    let q_tr = sqrt(1.5 * (dot(sd.xyz, sd.xyz) + 2.0 * sd.w * sd.w));
    if !(is_finite(p_tr) && is_finite(q_tr)) {
        return MccStep(s, q, FAULT_NON_FINITE_STRESS);
    }
    if p_tr <= 0.0 {
        // Tension: the apex of the ellipse, where it admits no stress.
        return MccStep(vec4<f32>(0.0), vec4<f32>(0.0, pc, v_new, f32(MCC_RETURN_APEX)), 0u);
    }
    if mcc_yield(m, p_tr, q_tr, pc) <= 0.0 {
        let out = vec4<f32>(sd.xyz - vec3<f32>(p_tr), sd.w);
        return MccStep(out, vec4<f32>(out.z, pc, v_new, 0.0), 0u);
    }
    // Closest point, scaled by p_c: P = e^y, Pc = e^z, w = Δγ p_c,n.
    let m2 = m.m_cs * m.m_cs;
    let a = v / m.kappa;
    let b = v / (m.lambda - m.kappa);
    let gn = g / pc;
    let qn = q_tr / pc;
    let yt = log(p_tr / pc);
    var y = yt;
    var z = 0.0;
    var w = 0.0;
    var ratio = 1.0;
    var converged = false;
    for (var it = 0u; it < MCC_MAX_ITER; it++) {
        let pp = exp(y);
        let pcc = exp(z);
        let d = 2.0 * pp - pcc;
        let den = 1.0 + 6.0 * gn * w / m2;
        let qq = qn / den;
        let f = qq * qq / m2 + pp * (pp - pcc);
        // f over max(p_c, p_c,n)²: the current p_c where the step hardens.
        var e2 = 1.0;
        var dz = 0.0;
        if pcc > 1.0 {
            e2 = 1.0 / (pcc * pcc);
            dz = 2.0 * f;
        }
        let r = vec3<f32>(y - yt + a * w * d, z - b * w * d, f * e2);
        let res = max(abs(r.x), max(abs(r.y), abs(r.z)));
        ratio = 1.0 / den;
        if res <= MCC_RETURN_TOL {
            converged = true;
            break;
        }
        let dx = mcc_solve3(
            vec3<f32>(1.0 + 2.0 * a * w * pp, -a * w * pcc, a * d),
            vec3<f32>(-2.0 * b * w * pp, 1.0 + b * w * pcc, -b * d),
            vec3<f32>(pp * d * e2, -(pp * pcc + dz) * e2, -12.0 * gn * qq * qq / (m2 * m2 * den) * e2),
            r,
        );
        if dx.w == 0.0 {
            break;
        }
        // Steps of at most one e-fold in p′ and p_c; Δγ stays ≥ 0.
        let big = max(abs(dx.x), abs(dx.y));
        var t = 1.0;
        if big > 1.0 {
            t = 1.0 / big;
        }
        y -= t * dx.x;
        z -= t * dx.y;
        let w_new = w - t * dx.z;
        if w_new < 0.0 {
            w = 0.5 * w;
        } else {
            w = w_new;
        }
    }
    if !converged {
        return MccStep(s, q, MCC_FAULT_NOT_CONVERGED);
    }
    let p = exp(y) * pc;
    let pc_new = exp(z) * pc;
    let out = vec4<f32>(ratio * sd.xyz - vec3<f32>(p), ratio * sd.w);
    return MccStep(out, vec4<f32>(out.z, pc_new, v_new, f32(MCC_RETURN_ELLIPSE)), 0u);
}

// One step: Jaumann rotation, plane-strain increment, mcc_step (twin of
// ModifiedCamClay::update). l = velocity gradient (xx, xy, yx, yy).
fn mcc_update(m: MccParams, l: vec4<f32>, dt: f32, s: vec3<f32>, q: vec4<f32>) -> MccUpdate {
    var r = MccUpdate(s, q, 1.0 + dt * (l.x + l.w), 0u);
    if !is_finite(r.j) {
        r.fault = FAULT_NON_FINITE_STRAIN;
        return r;
    }
    if r.j <= 0.0 {
        r.fault = FAULT_DENSITY;
        return r;
    }
    // σ + Δt (Wσ − σW), W = skew(L); σzz is not turned.
    let w = 0.5 * dt * (l.y - l.z);
    let rot = vec4<f32>(s.x + 2.0 * w * s.z, s.y - 2.0 * w * s.z, q.x, s.z + w * (s.y - s.x));
    let de = vec4<f32>(dt * l.x, dt * l.w, 0.0, 0.5 * dt * (l.y + l.z));
    let st = mcc_step(m, rot, de, q);
    r.fault = st.fault;
    if st.fault == 0u {
        r.s = vec3<f32>(st.s.x, st.s.y, st.s.w);
        r.q = st.q;
    }
    return r;
}

// Fastest elastic wave at density rho (m/s): p′ ≤ exp((N₁ − v)/λ) Pa at
// v = ρ0 v0 / ρ (twin of ModifiedCamClay::wave_speed).
fn mcc_wave_speed(m: MccParams, rho: f32) -> f32 {
    let v = m.rho_v0 / rho;
    let p_max = exp((m.n_pa - v) / m.lambda);
    let k = mcc_bulk(m, p_max, v);
    return sqrt((k + 4.0 / 3.0 * mcc_shear_at(m, k)) / rho);
}

// ½ σ : C⁻¹ : σ at the current moduli, with σzz = q.x (twin of
// ModifiedCamClay::energy).
fn mcc_energy(m: MccParams, s: vec3<f32>, q: vec4<f32>) -> f32 {
    let p = -(s.x + s.y + q.x) / 3.0;
    let k = mcc_bulk(m, p, q.z);
    let g = mcc_shear_at(m, k);
    let d = vec3<f32>(s.x, s.y, q.x) + vec3<f32>(p);
    return (dot(d, d) + 2.0 * s.z * s.z) / (4.0 * g) + p * p / (2.0 * k);
}

// The registry's contract (src/model/material/registry.rs).
fn modified_cam_clay_update(m: Material, l: vec4<f32>, dt: f32, s: vec3<f32>, f: vec4<f32>, q: vec4<f32>) -> MatUpdate {
    let u = mcc_update(mcc_params(m), l, dt, s, q);
    return MatUpdate(u.s, f, u.q, u.j, u.fault);
}

fn modified_cam_clay_energy(m: Material, s: vec3<f32>, f: vec4<f32>, q: vec4<f32>) -> f32 {
    return mcc_energy(mcc_params(m), s, q);
}

fn modified_cam_clay_wave_speed(m: Material, rho: f32, s: vec3<f32>, q: vec4<f32>) -> f32 {
    return mcc_wave_speed(mcc_params(m), rho);
}
