// Contact between bodies (multi-field MPM): what the contact passes share.
// CPU twins: src/cpu/contact_detect.rs (the normal rule) and
// src/cpu/contact_exchange.rs (`pair_impulse`).

// A declared pair (src/gpu/layout.rs `GpuContactPair`): the fields of its
// first and second body, its law (CONTACT_*), Coulomb μ (friction only)
// and the index of its reaction in `reactions` (after the constraint
// groups' and the walls').
struct ContactPair {
    fields: vec2<u32>,
    law: u32,
    mu: f32,
    reaction: u32,
    _pad: u32,
}

// Slack of the gap test relative to the smallest particle half-width:
// domains seeded flush against each other touch whatever the round-off.
// Keep in sync with `CONTACT_GAP_SLACK` in src/cpu/contact_detect.rs.
const CONTACT_GAP_SLACK: f32 = 1e-3;

// Least share of PIC in g2p for particles at a node in contact. Keep in
// sync with `CONTACT_PIC_FRACTION` in src/model/contact.rs.
const CONTACT_PIC_FRACTION: f32 = 0.05;

// The logistic-regression normal: ridge, Newton steps, step cap, least scale.
// Keep in sync with `LR_RIDGE`, `LR_ITERATIONS`, `LR_MAX_STEP`, `LR_MIN_SCALE` in
// src/cpu/contact_detect.rs (tests/gpu_shaders.rs checks).
const LR_RIDGE: f32 = 1e-9;
const LR_ITERATIONS: u32 = 10u;
const LR_MAX_STEP: f32 = 4.0;
const LR_MIN_SCALE: f32 = 2.0;
// cos 3°: where the fit's normal is this close to the gradient normal, the
// gradient is kept. Keep in sync with `LR_FLAT_COS`.
const LR_FLAT_COS: f32 = 0.99862953475;

// "No gap measured" (the CPU's infinity; WGSL may assume no infinities).
const CONTACT_NO_GAP: f32 = 3.4028235e38;

// The gradient normal: at a node where both bodies of a pair have mass,
// the unit normal from the pair's first body towards its second, from
// their mass gradients and volumes [Σ m_p ∇N, Σ N V_p] there (`ga`, `gb`):
// the gradient of the body with the larger volume at the node (Nairn's "max
// volume" choice; ∇m_a points out of a, −∇m_b into b). Zero: no normal.
// Where the pair touches, `lr_normal` (contact_detect.wgsl) replaces it
// with the line that separates the two bodies' particles, and keeps it
// where none does.
fn contact_normal(ga: vec3<f32>, gb: vec3<f32>) -> vec2<f32> {
    var d = -gb.xy;
    if ga.z >= gb.z {
        d = ga.xy;
    }
    let len = length(d);
    if len > 0.0 {
        return d / len;
    }
    return vec2<f32>(0.0);
}

// The momentum Δp that field a gains (b gains −Δp) under `law` with μ, at
// masses ma, mb and velocities va, vb, normal n from a to b: none unless
// the bodies approach; stick: both take the centre-of-mass velocity;
// slip: the normal part of the stick impulse; friction: Coulomb, the
// tangential part capped at μ times the normal one.
// CPU twin: `pair_impulse`.
fn pair_impulse(law: u32, mu: f32, ma: f32, va: vec2<f32>, mb: f32, vb: vec2<f32>, n: vec2<f32>) -> vec2<f32> {
    let rel = va - vb;
    if dot(rel, n) <= 0.0 {
        return vec2<f32>(0.0);
    }
    let red = ma * mb / (ma + mb);
    let stick = -red * rel;
    if law == CONTACT_STICK {
        return stick;
    }
    let pn = dot(stick, n);
    let normal = pn * n;
    if law != CONTACT_FRICTION {
        return normal;
    }
    let t = stick - normal;
    let pt = length(t);
    let cap = mu * abs(pn);
    if pt <= cap {
        return stick;
    }
    return normal + cap / pt * t;
}
