//! Every struct shared with WGSL, defined once here with explicit padding
//! and a compile-time size check. Keep in sync with shaders/shared/types.wgsl;
//! tests/gpu_shaders.rs compares offsets and sizes with naga's reflection.

use bytemuck::{Pod, Zeroable};

/// Scene constants (uniform). See types.wgsl for each field's meaning and unit.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct Params {
    pub n_particles: u32,
    pub n_nodes: u32,
    pub nx: u32,
    pub ny: u32,
    pub h: f32,
    pub inv_h: f32,
    pub cfl_h: f32,
    pub mass_eps: f32,
    /// t_end in clock ticks (`Clock`), low word first.
    pub t_end_ticks: [u32; 2],
    pub gravity: [f32; 2],
    pub ramp_period: f32,
    pub npc_gamma: f32,
    pub p2g_accel: f32,
    pub edge_margin: f32,
    pub grid_w: f32,
    pub grid_hgt: f32,
    pub lme_beta: f32,
    pub lme_r2: f32,
    pub lme_tol: f32,
    pub lme_reach: f32,
    pub lme_side: u32,
    pub lme_max_iter: u32,
    pub ugimp_lp: f32,
    pub n_groups: u32,
    pub n_probes: u32,
    pub n_materials: u32,
    pub fixed_dt: f32,
    pub mms_amp: f32,
    pub mms_origin: [f32; 2],
    pub mms_k: f32,
    pub mms_omega: f32,
    pub mms_lame: f32,
    pub mms_shear: f32,
    pub mms_c2: f32,
    pub mls_spans_x: u32,
    pub mls_spans_y: u32,
    pub mls_break_off: f32,
    pub mls_weight_scale: f32,
    pub pic_fraction: f32,
    pub local_damping: f32,
    /// A clock tick is 2^-tick_exp s (`Clock`).
    pub tick_exp: i32,
    /// The fixed Δt (f64, as the CPU path steps it) in ticks; 0 with CFL steps.
    pub fixed_dt_ticks: [u32; 2],
    /// Always 0: an operand the shader compiler cannot fold
    /// (`shaders/shared/kahan.wgsl`).
    pub opaque_zero: u32,
    pub _pad_p3: u32,
}
const _: () = assert!(std::mem::size_of::<Params>() == 192);

/// Run state on the device. Atomic fields of the WGSL struct are plain u32 here.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct Sim {
    /// The time as a two-float sum t + t_lo (s), derived from `ticks`.
    pub t: f32,
    pub t_lo: f32,
    /// The time in clock ticks (`Clock`), low word first: the device's clock.
    pub ticks: [u32; 2],
    /// Steps stop once `ticks` reaches this.
    pub t_stop_ticks: [u32; 2],
    pub dt: f32,
    pub steps: u32,
    pub running: u32,
    pub final_step: u32,
    pub cmax_bits: u32,
    pub fault: u32,
}
const _: () = assert!(std::mem::size_of::<Sim>() == 48);

#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct GpuMaterial {
    pub lame: f32,
    pub shear: f32,
    pub p_modulus: f32,
    pub youngs: f32,
    pub nu: f32,
    /// The model's code: its place in the registry (`MODEL_*`, generated
    /// by `model::material::registry::wgsl`).
    pub model: u32,
    /// Bulk modulus K = λ + 2μ/3 (Pa).
    pub bulk: f32,
    /// The model's own parameters (`Constitutive::gpu_params`), read in
    /// WGSL as `m.p[<MODEL>_<PARAM>]`; unused slots are zero.
    pub p: [f32; GPU_PARAM_SLOTS],
}

pub use crate::model::material::registry::GPU_PARAM_SLOTS;
const _: () = assert!(std::mem::size_of::<GpuMaterial>() == 64);

#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct GpuConstraint {
    pub i0: u32,
    pub i1: u32,
    pub j0: u32,
    pub j1: u32,
    pub fix: u32,
    /// Prescribed velocity of the fixed components at full ramp (m/s).
    pub vx: f32,
    pub vy: f32,
    /// Linear ramp time of the velocity (s); 0 = from the start.
    pub ramp_time: f32,
}
const _: () = assert!(std::mem::size_of::<GpuConstraint>() == 32);

/// A wall (shaders/shared/types.wgsl `Wall`): its line through `point`
/// (m, grid-relative), unit normal into the material, contact code
/// (`model::walls::CONTACT_*`) and μ; it acts for `appear_at` ≤ t <
/// `remove_at` (s; `f32::MAX` for never removed).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct GpuWall {
    pub point: [f32; 2],
    pub normal: [f32; 2],
    pub mu: f32,
    pub contact: u32,
    /// Penalty stiffness k (Pa/m, `Wall::stiffness`).
    pub stiffness: f32,
    /// Contact line's offset (m, `Wall::offset`).
    pub offset: f32,
    pub appear_at: f32,
    pub remove_at: f32,
}
const _: () = assert!(std::mem::size_of::<GpuWall>() == 40);

/// A contact pair (shaders/shared/contact.wgsl `ContactPair`): the fields
/// of its first and second body, its law (`model::walls::CONTACT_*`),
/// Coulomb μ (friction only) and the index of its reaction in
/// `Buf::Reactions` (after the constraint groups' and the walls').
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, PartialEq)]
pub struct GpuContactPair {
    pub fields: [u32; 2],
    pub law: u32,
    pub mu: f32,
    pub reaction: u32,
    pub _pad: u32,
}
const _: () = assert!(std::mem::size_of::<GpuContactPair>() == 24);

/// Floats per node in the nodal accumulator: mass, momentum/velocity (2), force (2).
pub const NODE_STRIDE: usize = 5;
/// Floats per probe in the probe buffer.
pub const PROBE_STRIDE: usize = 8;
/// Workgroup size of the per-particle and per-node passes.
pub const WG: u32 = 256;
/// Workgroup size of the probe gather (shaders/probes.wgsl).
pub const PROBES_WG: u32 = 64;

/// Fault codes (types.wgsl): `Sim::fault` = (particle << 4) | code.
pub const FAULT_NONE: u32 = 0xffff_ffff;
pub const FAULT_LEFT_GRID: u32 = 1;
pub const FAULT_NON_FINITE_STRAIN: u32 = 2;
pub const FAULT_NON_FINITE_STRESS: u32 = 3;
pub const FAULT_NON_FINITE_MOTION: u32 = 4;
pub const FAULT_DENSITY: u32 = 5;
pub const FAULT_LME_FEW_NODES: u32 = 6;
pub const FAULT_LME_NOT_CONVERGED: u32 = 7;
pub const FAULT_LME_SINGULAR: u32 = 8;
/// The index field holds the Gauss point, not a particle.
pub const FAULT_MLS_SINGULAR: u32 = 9;
/// The first code of the material models' own faults (codes
/// `FAULT_MATERIAL..16`, `Constitutive::FAULTS` in order).
pub const FAULT_MATERIAL: u32 = crate::model::material::registry::GPU_FAULT_BASE;

/// Splits an f64 into a two-float sum hi + lo (for times in f32).
pub fn split_f64(v: f64) -> (f32, f32) {
    let hi = v as f32;
    (hi, (v - hi as f64) as f32)
}

/// The device's clock: time as an unsigned 64-bit count of ticks of
/// 2^-exp s, advanced in integers by `step_end.wgsl`. A compensated float
/// sum (Kahan) is not safe on GPUs: a driver may reassociate
/// `(t + y − t) − y` to 0 (llvmpipe's time followed a plain f32 sum), and
/// a plain f32 sum of 1e5 steps of 1e-5 s drifts by whole steps. Integer
/// sums cannot be rewritten. `exp` is chosen so that t_end is at most
/// 2^61 ticks, an eighth of the range: at t_end = 1 s a tick is 2^-61 s;
/// any f32 Δt above 2^23 ticks (4e-12 s at t_end = 1 s) converts to ticks
/// exactly.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Clock {
    pub exp: i32,
}

impl Clock {
    /// The finest clock that holds `t_end` in 2^61 ticks.
    pub fn for_end(t_end: f64) -> Clock {
        let e = t_end.max(f64::MIN_POSITIVE).log2().ceil() as i32;
        Clock {
            exp: (61 - e).clamp(-60, 120),
        }
    }

    /// `t` (s, ≥ 0) in ticks, rounded to the nearest.
    pub fn ticks(self, t: f64) -> [u32; 2] {
        let v = (t.max(0.0) * 2f64.powi(self.exp)).round();
        let v = if v >= 1.8e19 { u64::MAX } else { v as u64 };
        [v as u32, (v >> 32) as u32]
    }

    /// Ticks in seconds.
    pub fn seconds(self, ticks: [u32; 2]) -> f64 {
        let v = ((ticks[1] as u64) << 32) | ticks[0] as u64;
        v as f64 * 2f64.powi(-self.exp)
    }
}

#[cfg(test)]
mod clock_tests {
    use super::Clock;

    #[test]
    fn the_clock_holds_t_end_and_resolves_small_steps() {
        for t_end in [1e-3, 0.0025, 1.0, 20.0, 3600.0, 1e6] {
            let c = Clock::for_end(t_end);
            let ticks = c.ticks(t_end);
            let v = ((ticks[1] as u64) << 32) | ticks[0] as u64;
            assert!(v <= 1 << 61 && v > 1 << 59, "t_end {t_end}: {v} ticks");
            // One tick is below 1e-17 of t_end: the clock adds no error a
            // run could see.
            assert!((c.seconds(ticks) - t_end).abs() <= 2f64.powi(-c.exp));
            assert!(2f64.powi(-c.exp) < 1e-17 * t_end);
            // 1e5 steps of t_end / 1e5, each an f32, sum exactly in ticks.
            let dt = (t_end / 1e5) as f32 as f64;
            let step = c.ticks(dt);
            assert_eq!(
                c.seconds(step),
                dt,
                "t_end {t_end}: Δt {dt} not exact in ticks"
            );
        }
    }
}
