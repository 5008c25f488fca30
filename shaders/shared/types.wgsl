// Shared structs and helpers. Keep in sync with src/gpu/layout.rs, which
// defines each struct once in Rust with a compile-time size check; the test
// tests/gpu_layout.rs compares both with naga's reflection of this file.

const WG: u32 = 256u;
// Fault codes, packed as (particle << 4) | code into Sim.fault (atomicMin
// keeps the lowest particle). Keep in sync with src/gpu/layout.rs.
const FAULT_NONE: u32 = 0xffffffffu;
const FAULT_LEFT_GRID: u32 = 1u;
const FAULT_NON_FINITE_STRAIN: u32 = 2u;
const FAULT_NON_FINITE_STRESS: u32 = 3u;
const FAULT_NON_FINITE_MOTION: u32 = 4u;
const FAULT_DENSITY: u32 = 5u;
const FAULT_LME_FEW_NODES: u32 = 6u;
const FAULT_LME_NOT_CONVERGED: u32 = 7u;
const FAULT_LME_SINGULAR: u32 = 8u;
// MLS moment matrix singular; the index is the Gauss point's, not a particle's.
const FAULT_MLS_SINGULAR: u32 = 9u;
// Codes 10..15 are the material models' own faults (Constitutive::FAULTS,
// in order; generated constants <NAME>_FAULT_<CODE>), decoded through the
// faulting particle's material.
const FAULT_MATERIAL: u32 = 10u;

// Scene constants (uniform), fixed for a run.
struct Params {
    n_particles: u32,
    n_nodes: u32,
    nx: u32,
    ny: u32,
    h: f32,
    inv_h: f32,
    // CFL number times the smallest node spacing (m).
    cfl_h: f32,
    // Nodes lighter than this (kg) are empty.
    mass_eps: f32,
    // t_end in clock ticks (shared/clock.wgsl), low word first.
    t_end_ticks: vec2<u32>,
    // Full gravity (m/s^2).
    gravity: vec2<f32>,
    // T of the sine ramp (eq. 45); 0 = constant gravity.
    ramp_period: f32,
    // NPC γ; FE uses 1 (the nodal momentum update).
    npc_gamma: f32,
    // (1 − γ) for the NPC predictor; FE 0.
    p2g_accel: f32,
    // Distance a particle keeps from the grid's edge (m).
    edge_margin: f32,
    // Grid size (m): positions run over [0, grid_w] x [0, grid_hgt].
    grid_w: f32,
    grid_hgt: f32,
    // LME: β (1/m^2), support radius squared (m^2), Newton |r| tolerance (m),
    // search reach (cells), search box side (nodes), iteration cap.
    lme_beta: f32,
    lme_r2: f32,
    lme_tol: f32,
    lme_reach: f32,
    lme_side: u32,
    lme_max_iter: u32,
    // uGIMP particle half-width over h.
    ugimp_lp: f32,
    n_groups: u32,
    n_probes: u32,
    n_materials: u32,
    // Fixed Δt (s); 0 = from the CFL condition.
    fixed_dt: f32,
    // Manufactured aligned vibration (flag MMS): amplitude A (m), the square's
    // lower-left corner (m, grid-relative), k = 2π/L (1/m), ω = cπ/L (rad/s),
    // λ/ρ0 and μ/ρ0 (m²/s²), c² = E/ρ0 (m²/s²).
    mms_amp: f32,
    mms_origin: vec2<f32>,
    mms_k: f32,
    mms_omega: f32,
    mms_lame: f32,
    mms_shear: f32,
    mms_c2: f32,
    // MLS (flag MLS): integration cells along x and y; interior breaks sit
    // at k + mls_break_off (lattice units), the first at 0, the last at n − 1.
    mls_spans_x: u32,
    mls_spans_y: u32,
    mls_break_off: f32,
    // r per |Δx|/h in the MLS weight: 1.5 / solver.mls_support (the paper's 0.5).
    mls_weight_scale: f32,
    // Share α of PIC in g2p's velocity update (flag PIC), in [0, 1].
    pic_fraction: f32,
    // Cundall's local damping α (flag LOCAL_DAMPING), in [0, 1).
    local_damping: f32,
    // A clock tick is 2^-tick_exp s (shared/clock.wgsl).
    tick_exp: i32,
    // The fixed Δt (as the CPU path's f64) in ticks; 0 with CFL steps.
    fixed_dt_ticks: vec2<u32>,
    // Always 0, unknown to the shader compiler (shared/kahan.wgsl).
    opaque_zero: u32,
    _pad_p3: u32,
}

// Run state on the device (storage, read_write), read back at sample times.
struct Sim {
    // Time reached (s) as a two-float sum t + t_lo, derived from `ticks`.
    t: f32,
    t_lo: f32,
    // Time reached in clock ticks (shared/clock.wgsl): the device's clock.
    ticks: vec2<u32>,
    // Steps stop once `ticks` reaches this.
    t_stop_ticks: vec2<u32>,
    // This step's Δt (s).
    dt: f32,
    steps: u32,
    // 1 while the current step runs; every pass returns early on 0.
    running: u32,
    // 1 when this step lands on t_end.
    final_step: u32,
    // Largest signal speed (m/s) as f32 bits: positive floats order like u32.
    cmax_bits: atomic<u32>,
    // (particle << 4) | code of the first fault, FAULT_NONE if none.
    fault: atomic<u32>,
}

struct Material {
    // Lamé λ, shear modulus μ, P-wave modulus λ + 2μ, Young's E (Pa), ν.
    lame: f32,
    shear: f32,
    p_modulus: f32,
    youngs: f32,
    nu: f32,
    // The model's code, MODEL_* (generated from the registry).
    model: u32,
    // Bulk modulus K = λ + 2μ/3 (Pa).
    bulk: f32,
    // The model's own parameters, read as p[<MODEL>_<PARAM>] (the
    // constants are generated from its registry entry).
    p: array<f32, 9>,
}

// Nodes with i0 <= i <= i1 and j0 <= j <= j1 are fixed in the `fix` bits
// (1 = x, 2 = y) at velocity (vx, vy) (m/s), ramped linearly from 0 over
// ramp_time (s; 0 = from the start); their reactions add up in
// `reactions[group]`.
struct Constraint {
    i0: u32,
    i1: u32,
    j0: u32,
    j1: u32,
    fix: u32,
    vx: f32,
    vy: f32,
    ramp_time: f32,
}

// Contact laws of a wall. Keep in sync with src/model/walls.rs.
const CONTACT_STICK: u32 = 0u;
const CONTACT_SLIP: u32 = 1u;
const CONTACT_FRICTION: u32 = 2u;

// A rigid wall: the line through `point` (m, grid-relative) with unit
// normal `normal` into the material; `contact` is CONTACT_*, `mu` Coulomb's
// coefficient (friction only); `stiffness` the penalty k (Pa/m) and
// `offset` (m) how far past the line contact starts (src/model/walls.rs).
struct Wall {
    point: vec2<f32>,
    normal: vec2<f32>,
    mu: f32,
    contact: u32,
    stiffness: f32,
    offset: f32,
    // The wall acts for appear_at <= t < remove_at (s), t the step's start
    // (flag GATES).
    appear_at: f32,
    remove_at: f32,
}

// Linear invocation index over a 2D dispatch (large counts exceed 65535
// workgroups in x).
fn linear_index(gid: vec3<u32>, nwg: vec3<u32>) -> u32 {
    return gid.x + gid.y * nwg.x * WG;
}

fn is_finite(v: f32) -> bool {
    // NaN fails v == v; ±inf exceed the largest finite f32.
    return v == v && abs(v) <= 3.4028235e38;
}

fn report_fault(code: u32, particle: u32) {
    atomicMin(&sim.fault, (particle << 4u) | code);
}
