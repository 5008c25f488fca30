//! What a constitutive model is to the solver (`Constitutive`), how its
//! scene keys are read and checked (`Keys`), and the WGSL generated from
//! the registered models (`wgsl`). A model is its Rust file, its WGSL file
//! (`shaders/shared/material_<name>.wgsl`) and one line of `register!` in
//! `mod.rs`; nothing else names it.
//!
//! The WGSL contract of a model `<name>` (its scene name): the file defines
//! `<name>_update(m: Material, l: vec4<f32>, dt: f32, s: vec3<f32>,
//! f: vec4<f32>, q: vec4<f32>) -> MatUpdate`, `<name>_energy(m, s, f, q)
//! -> f32` and `<name>_wave_speed(m, rho: f32, s, q) -> f32`, mirroring
//! the Rust `update`, `strain_energy_density` and `wave_speed`, and reads
//! its parameters as `m.p[<NAME>_<PARAM>]`: the constants are generated
//! from `GPU_PARAMS`, in the order `gpu_params` packs them. A model that
//! can fail in its own way declares its faults in `FAULTS`; its WGSL
//! reports the i-th as `report_fault(<NAME>_FAULT_<CODE>, particle)` (a
//! generated constant, `GPU_FAULT_BASE + i`), and the GPU backend decodes
//! it through the particle's material: no other file names the fault.

use super::{DefGrad, PlasticState};
use crate::error::SceneError;
use crate::model::fault::FaultKind;
pub use crate::model::fault::MaterialFault;
use crate::scene::MaterialSpec;
use std::collections::BTreeSet;

/// Parameter slots of `GpuMaterial::p` (shared/types.wgsl `Material.p`).
pub const GPU_PARAM_SLOTS: usize = 9;
/// The first GPU fault code of the material faults (`Sim::fault`'s low
/// four bits; codes below it are the solver's, shared/types.wgsl).
pub const GPU_FAULT_BASE: u32 = 10;
/// How many faults one model may declare: the codes `GPU_FAULT_BASE..16`.
pub const FAULT_SLOTS: usize = 16 - GPU_FAULT_BASE as usize;

/// The per-particle state a model keeps beside the stress.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StateKind {
    /// The stress alone.
    Stress,
    /// The deformation gradient F (`Particles::f`).
    DefGrad,
    /// A `PlasticState` (`Particles::plastic`): four numbers whose meaning
    /// the model documents (σzz first, the active-surface mask last).
    Plastic,
}

/// One scene key of a model: its name, unit and what it means (for
/// `check`'s description and the unknown-key message).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Key {
    pub name: &'static str,
    pub unit: &'static str,
    pub doc: &'static str,
}

/// One column of a model's state in the outputs: what a `PlasticState`
/// slot (1 or 2) of the model holds, named the model's way in
/// `particles.csv`, the VTU point data, `result.png` and `lme-mpm render`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StateColumn {
    /// Its `particles.csv` column and `render --field` value.
    pub column: &'static str,
    /// Its VTU point-array name.
    pub array: &'static str,
    /// Its unit ("1": none).
    pub unit: &'static str,
    /// What it is, in words (titles and messages).
    pub meaning: &'static str,
    /// Its symbol in a colour bar's label.
    pub symbol: &'static str,
    /// A magnitude that grows from zero: colour scales start at 0 (else
    /// at the least value, as p_c's about p′0).
    pub from_zero: bool,
}

impl StateColumn {
    /// ` (unit)`, or nothing for a pure number.
    fn unit_suffix(&self) -> String {
        if self.unit == "1" {
            String::new()
        } else {
            format!(" ({})", self.unit)
        }
    }

    /// Its meaning and unit, as a picture's title names it.
    pub fn label(&self) -> String {
        format!("{}{}", self.meaning, self.unit_suffix())
    }

    /// Its symbol and unit, as a colour bar names it.
    pub fn short_label(&self) -> String {
        format!("{}{}", self.symbol, self.unit_suffix())
    }
}

/// A constitutive model. The methods mirror its WGSL twin's functions.
pub trait Constitutive: Sized {
    /// Its scene name (`model = "..."`), also the prefix of its WGSL functions.
    const NAME: &'static str;
    /// Its scene keys besides `model` and `density`.
    const KEYS: &'static [Key];
    /// The per-particle state it keeps.
    const STATE: StateKind;
    /// Names of its GPU parameters, in `gpu_params` order (at most
    /// `GPU_PARAM_SLOTS`); WGSL reads them as `m.p[<NAME>_<PARAM>]`.
    const GPU_PARAMS: &'static [&'static str];
    /// The faults its update can report beyond the solver's own (at most
    /// `FAULT_SLOTS`); none unless the model says.
    const FAULTS: &'static [MaterialFault] = &[];
    /// What slots 1 and 2 of its `PlasticState` hold, in that order: two
    /// columns for a `StateKind::Plastic` model, none for the others (a
    /// test holds every model to it). Slot 0 is σzz and slot 3 the active
    /// surfaces for every plastic model (`szz`, `plastic`).
    const STATE_COLUMNS: &'static [StateColumn] = &[];
    /// It starts at a state of its own (`initial_state` is not zero), so
    /// a geostatic start cannot set its stress.
    const OWN_START: bool = false;

    /// Builds the model from its keys, each checked (the error names it).
    fn from_keys(k: &Keys) -> Result<Self, SceneError>;
    /// Initial density ρ0 (kg/m³).
    fn density(&self) -> f64;
    /// Elastic constants at the initial state: Lamé λ and shear modulus μ (Pa).
    fn lame_shear(&self) -> (f64, f64);
    /// Young's modulus E (Pa) and Poisson's ratio ν at the initial state.
    fn youngs_nu(&self) -> (f64, f64);
    /// One constitutive step from the velocity gradient `l` =
    /// [∂vx/∂x, ∂vx/∂y, ∂vy/∂x, ∂vy/∂y] (1/s) over `dt` (s): updates the
    /// stress (and F, or the plastic state `q`), returns V_new / V_old.
    fn update(
        &self,
        l: [f64; 4],
        dt: f64,
        stress: &mut [f64; 3],
        f: &mut DefGrad,
        q: &mut PlasticState,
    ) -> Result<f64, FaultKind>;
    /// Speed of the fastest wave (m/s) at density `rho` and the particle's
    /// state, for the CFL condition.
    fn wave_speed(&self, rho: f64, stress: &[f64; 3], q: &PlasticState) -> f64;
    /// `wave_speed` squared (m²/s²): the CFL condition takes the largest
    /// over the particles and one square root. A model whose speed is a
    /// square root gives its argument, so that the largest speed is the
    /// same number either way (the square root keeps the order).
    #[inline]
    fn wave_speed_squared(&self, rho: f64, stress: &[f64; 3], q: &PlasticState) -> f64 {
        let c = self.wave_speed(rho, stress, q);
        c * c
    }
    /// Stored energy per unit current volume (J/m³).
    fn strain_energy_density(&self, stress: &[f64; 3], f: &DefGrad, q: &PlasticState) -> f64;
    /// The GPU parameters, in `GPU_PARAMS` order.
    fn gpu_params(&self) -> Vec<f32>;
    /// The out-of-plane stress σzz (Pa) of plane strain (εzz = 0) that the
    /// model makes of a particle's state: its stress, its F (`None` where
    /// the particles keep none), its density `rho` (kg/m³) and its plastic
    /// state (`None` where the particles keep none). Every model says; none
    /// is silently 0.
    fn stress_zz(
        &self,
        stress: &[f64; 3],
        f: Option<&DefGrad>,
        rho: f64,
        q: Option<&PlasticState>,
    ) -> f64;
    /// The stress (Pa) and plastic state a particle starts with: zero,
    /// unless the model starts elsewhere.
    fn initial_state(&self) -> ([f64; 3], PlasticState) {
        ([0.0; 3], [0.0; 4])
    }
}

/// A material's keys as the model reads them: each read is checked (finite,
/// in range) and remembered, and `finish` refuses the keys no read asked
/// for, listing the model's own.
pub struct Keys<'a> {
    spec: &'a MaterialSpec,
    /// The material's name in `[materials]`.
    name: &'a str,
    model_keys: &'static [Key],
    read: std::cell::RefCell<BTreeSet<String>>,
}

impl<'a> Keys<'a> {
    pub fn new(name: &'a str, spec: &'a MaterialSpec, model_keys: &'static [Key]) -> Keys<'a> {
        Keys {
            spec,
            name,
            model_keys,
            read: Default::default(),
        }
    }

    /// The full scene key of `k`: `materials.<name>.<k>`.
    pub fn key(&self, k: &str) -> String {
        format!("materials.{}.{k}", self.name)
    }

    /// An error naming key `k`.
    pub fn invalid(&self, k: &str, message: impl Into<String>) -> SceneError {
        SceneError::invalid(self.key(k), message)
    }

    pub fn density(&self) -> f64 {
        self.spec.density
    }

    /// Key `k` if given (finite).
    pub fn optional(&self, k: &str) -> Result<Option<f64>, SceneError> {
        self.read.borrow_mut().insert(k.to_string());
        match self.spec.get(k) {
            Some(v) if !v.is_finite() => Err(self.invalid(k, format!("must be finite, got {v}"))),
            v => Ok(v),
        }
    }

    /// Key `k`, which the model requires.
    pub fn required(&self, k: &str) -> Result<f64, SceneError> {
        self.optional(k)?.ok_or_else(|| {
            self.invalid(
                k,
                format!("is required for model = \"{}\"", self.spec.model),
            )
        })
    }

    /// Key `k` (or its default), within `lo ≤ v < hi` (`hi_closed`: ≤ hi);
    /// `what` names the range in the message (e.g. "≥ 0 Pa").
    pub fn within(
        &self,
        k: &str,
        v: f64,
        lo: f64,
        hi: f64,
        hi_closed: bool,
        what: &str,
    ) -> Result<f64, SceneError> {
        let ok = v >= lo && (v < hi || hi_closed && v <= hi);
        if ok {
            Ok(v)
        } else {
            Err(self.invalid(k, format!("must be {what}, got {v}")))
        }
    }

    /// A required key > 0.
    pub fn positive(&self, k: &str, unit: &str) -> Result<f64, SceneError> {
        let v = self.required(k)?;
        if v > 0.0 {
            Ok(v)
        } else {
            Err(self.invalid(k, format!("must be > 0 {unit}, got {v}")))
        }
    }

    /// The elastic pair every linear-elastic-based model reads: E > 0 (Pa)
    /// and ν in (−1, 0.5).
    pub fn youngs_nu(&self) -> Result<(f64, f64), SceneError> {
        let e = self.positive("E", "Pa")?;
        let nu = self.required("nu")?;
        let nu = self.within("nu", nu, -1.0, 0.5, false, "in (-1, 0.5)")?;
        if nu == -1.0 {
            return Err(self.invalid("nu", "must be in (-1, 0.5), got -1"));
        }
        Ok((e, nu))
    }

    /// Refuses keys the model did not read.
    pub fn finish(&self) -> Result<(), SceneError> {
        let read = self.read.borrow();
        // The pore fluid's keys belong to every model (`model::pore`).
        let pore = |k: &str| crate::model::pore::KEYS.iter().any(|(p, _)| *p == k);
        if let Some(k) = self
            .spec
            .values
            .keys()
            .find(|k| !read.contains(*k) && !pore(k))
        {
            let known: Vec<String> = self
                .model_keys
                .iter()
                .map(|k| format!("{} ({})", k.name, k.unit))
                .collect();
            return Err(self.invalid(
                k,
                format!(
                    "is not a key of model = \"{}\"; its keys: density (kg/m³), {}; and for saturated soil {}",
                    self.spec.model,
                    known.join(", "),
                    crate::model::pore::KEYS
                        .iter()
                        .map(|(k, u)| format!("{k} ({u})"))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            ));
        }
        Ok(())
    }
}

/// One registered model as the WGSL generator sees it.
#[derive(Debug, Clone, Copy)]
pub struct Entry {
    pub name: &'static str,
    pub code: u32,
    pub state: StateKind,
    pub gpu_params: &'static [&'static str],
    pub keys: &'static [Key],
    pub faults: &'static [MaterialFault],
    pub state_columns: &'static [StateColumn],
    pub own_start: bool,
}

impl Entry {
    /// The model's WGSL file, relative to `shaders/`.
    pub fn wgsl_file(&self) -> String {
        format!("shared/material_{}.wgsl", self.name)
    }

    /// Its `MODEL_*` constant.
    pub fn model_const(&self) -> String {
        format!("MODEL_{}", self.name.to_uppercase())
    }

    /// The GPU fault code of its fault `code` (`FAULTS`' `code`).
    pub fn gpu_fault_code(&self, code: &str) -> Option<u32> {
        let i = self.faults.iter().position(|f| f.code == code)?;
        Some(GPU_FAULT_BASE + i as u32)
    }

    /// Its fault whose GPU code is `gpu_code`, if it declares one.
    pub fn fault_of_gpu_code(&self, gpu_code: u32) -> Option<MaterialFault> {
        let i = gpu_code.checked_sub(GPU_FAULT_BASE)? as usize;
        self.faults.get(i).copied()
    }
}

/// The WGSL of the material interface for the models whose codes are in
/// `used` (a bit per code): every model's `MODEL_*` and parameter-index
/// constants, its fault codes (`<NAME>_FAULT_<CODE>`), the used models'
/// files, and `material_update`,
/// `strain_energy_density` and `wave_speed` dispatching on `m.model`.
/// Included by `shaders/shared/material.wgsl` as `generated/materials.wgsl`.
pub fn wgsl(entries: &[Entry], used: u32) -> String {
    let mut s = String::from("// Generated by src/model/material/registry.rs from the registry.\n");
    for e in entries {
        s += &format!("const {}: u32 = {}u;\n", e.model_const(), e.code);
        for (i, p) in e.gpu_params.iter().enumerate() {
            s += &format!(
                "const {}_{}: u32 = {i}u;\n",
                e.name.to_uppercase(),
                p.to_uppercase()
            );
        }
        assert!(
            e.faults.len() <= FAULT_SLOTS,
            "model {} declares {} faults; the GPU has codes for {FAULT_SLOTS}",
            e.name,
            e.faults.len()
        );
        for f in e.faults {
            s += &format!(
                "const {}_FAULT_{}: u32 = {}u;\n",
                e.name.to_uppercase(),
                f.code.to_uppercase(),
                e.gpu_fault_code(f.code).expect("its own fault")
            );
        }
    }
    let on: Vec<&Entry> = entries
        .iter()
        .filter(|e| used & (1 << e.code) != 0)
        .collect();
    for e in &on {
        s += &format!("#include \"{}\"\n", e.wgsl_file());
    }
    let dispatch = |sig: &str, call: &str, fallback: &str| {
        let mut f = format!("{sig} {{\n");
        for e in &on {
            f += &format!(
                "    if m.model == {} {{\n        return {}_{call};\n    }}\n",
                e.model_const(),
                e.name
            );
        }
        f += &format!("    return {fallback};\n}}\n");
        f
    };
    s += &dispatch(
        "fn material_update(m: Material, l: vec4<f32>, dt: f32, s: vec3<f32>, f: vec4<f32>, q: vec4<f32>) -> MatUpdate",
        "update(m, l, dt, s, f, q)",
        "MatUpdate(s, f, q, 1.0, 0u)",
    );
    s += &dispatch(
        "fn strain_energy_density(m: Material, s: vec3<f32>, f: vec4<f32>, q: vec4<f32>) -> f32",
        "energy(m, s, f, q)",
        "0.0",
    );
    s += &dispatch(
        "fn wave_speed(m: Material, rho: f32, s: vec3<f32>, q: vec4<f32>) -> f32",
        "wave_speed(m, rho, s, q)",
        "sqrt(m.p_modulus / rho)",
    );
    s
}
