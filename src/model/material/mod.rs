//! Materials: the registry. Each model is its own file (a type that
//! implements `registry::Constitutive`: scene keys, state, update, GPU
//! parameters), its WGSL twin `shaders/shared/material_<name>.wgsl`, and
//! one line of `register!` below, from which the `Material` enum, its
//! dispatch, the scene's model names and the GPU dispatch
//! (`registry::wgsl`) follow. A model stores only the per-particle state it
//! needs (linear elastic: the stress alone; Neo-Hookean: the deformation
//! gradient too; the plastic models: a `plastic::PlasticState`).

pub mod increment;
pub mod plastic;
pub mod registry;
pub mod state;

pub use registry::{Constitutive, Entry, Key, Keys, MaterialFault, StateColumn, StateKind};
pub use state::{DefGrad, PlasticState};

use crate::error::SceneError;
use crate::model::fault::FaultKind;
use crate::scene::{MaterialSpec, SceneFile};

/// Declares the registered models: for each, its module (its Rust file),
/// the `Material` variant and the type implementing `Constitutive`. Its
/// code (GPU `MODEL_*`) is its place in the list.
macro_rules! register {
    ($($variant:ident($module:ident::$ty:ident)),* $(,)?) => {
        $(pub mod $module; pub use $module::$ty;)*

        /// A material of the scene: one registered model.
        #[derive(Debug, Clone, PartialEq)]
        pub enum Material {
            $($variant($ty),)*
        }

        /// Every registered model; `code` is its place in the list.
        pub fn registry() -> Vec<Entry> {
            [$(Entry {
                name: <$ty as Constitutive>::NAME,
                code: 0,
                state: <$ty as Constitutive>::STATE,
                gpu_params: <$ty as Constitutive>::GPU_PARAMS,
                keys: <$ty as Constitutive>::KEYS,
                faults: <$ty as Constitutive>::FAULTS,
                state_columns: <$ty as Constitutive>::STATE_COLUMNS,
                own_start: <$ty as Constitutive>::OWN_START,
            }),*]
            .into_iter()
            .enumerate()
            .map(|(i, e)| Entry { code: i as u32, ..e })
            .collect()
        }

        impl Material {
            /// Builds material `name` of the scene from its keys, each
            /// checked; unknown models and keys are refused, naming them.
            pub fn from_spec(name: &str, spec: &MaterialSpec) -> Result<Material, SceneError> {
                $(if spec.model == <$ty as Constitutive>::NAME {
                    let k = Keys::new(name, spec, <$ty as Constitutive>::KEYS);
                    let m = <$ty as Constitutive>::from_keys(&k)?;
                    k.finish()?;
                    return Ok(Material::$variant(m));
                })*
                let known: Vec<String> =
                    registry().iter().map(|e| format!("\"{}\"", e.name)).collect();
                Err(SceneError::invalid(
                    format!("materials.{name}.model"),
                    format!("unknown model \"{}\"; the models are {}", spec.model, known.join(", ")),
                ))
            }

            /// The registry entry of this material's model.
            pub fn entry(&self) -> Entry {
                let name = match self {
                    $(Material::$variant(_) => <$ty as Constitutive>::NAME,)*
                };
                registry()
                    .into_iter()
                    .find(|e| e.name == name)
                    .expect("a registered model")
            }

            /// Initial density ρ0 (kg/m³).
            pub fn density(&self) -> f64 {
                match self { $(Material::$variant(m) => <$ty as Constitutive>::density(m),)* }
            }

            /// Lamé λ and shear modulus μ (Pa), at the initial state.
            pub fn lame_shear(&self) -> (f64, f64) {
                match self { $(Material::$variant(m) => <$ty as Constitutive>::lame_shear(m),)* }
            }

            /// Young's modulus E (Pa) and Poisson's ratio ν, at the initial state.
            pub fn youngs_nu(&self) -> (f64, f64) {
                match self { $(Material::$variant(m) => <$ty as Constitutive>::youngs_nu(m),)* }
            }

            /// One step of the constitutive update from the velocity
            /// gradient `l` = [∂vx/∂x, ∂vx/∂y, ∂vy/∂x, ∂vy/∂y] (1/s) over
            /// `dt` (s): updates the stress (and F, or the plastic state
            /// `q`), and returns the volume ratio V_new / V_old. Models
            /// ignore the state they do not keep.
            #[inline(always)]
            pub fn update(
                &self,
                l: [f64; 4],
                dt: f64,
                stress: &mut [f64; 3],
                f: &mut DefGrad,
                q: &mut PlasticState,
            ) -> Result<f64, FaultKind> {
                match self { $(Material::$variant(m) => <$ty as Constitutive>::update(m, l, dt, stress, f, q),)* }
            }

            /// Speed of the fastest wave at density `rho` (m/s) and the
            /// particle's state, for the CFL condition.
            #[inline(always)]
            pub fn wave_speed(&self, rho: f64, stress: &[f64; 3], q: &PlasticState) -> f64 {
                match self { $(Material::$variant(m) => <$ty as Constitutive>::wave_speed(m, rho, stress, q),)* }
            }

            /// `wave_speed` squared (m²/s²), for the largest over the particles.
            #[inline(always)]
            pub fn wave_speed_squared(&self, rho: f64, stress: &[f64; 3], q: &PlasticState) -> f64 {
                match self { $(Material::$variant(m) => <$ty as Constitutive>::wave_speed_squared(m, rho, stress, q),)* }
            }

            /// Stored elastic energy per unit current volume (J/m³).
            #[inline]
            pub fn strain_energy_density(&self, stress: &[f64; 3], f: &DefGrad, q: &PlasticState) -> f64 {
                match self { $(Material::$variant(m) => <$ty as Constitutive>::strain_energy_density(m, stress, f, q),)* }
            }

            /// The stress (Pa) and plastic state a particle starts with.
            pub fn initial_state(&self) -> ([f64; 3], PlasticState) {
                match self { $(Material::$variant(m) => <$ty as Constitutive>::initial_state(m),)* }
            }

            /// σzz (Pa) of a particle's state (`Constitutive::stress_zz`).
            #[inline]
            pub fn stress_zz(
                &self,
                stress: &[f64; 3],
                f: Option<&DefGrad>,
                rho: f64,
                q: Option<&PlasticState>,
            ) -> f64 {
                match self { $(Material::$variant(m) => <$ty as Constitutive>::stress_zz(m, stress, f, rho, q),)* }
            }

            /// The GPU parameters (`GpuMaterial::p`), in the entry's order.
            pub fn gpu_params(&self) -> Vec<f32> {
                match self { $(Material::$variant(m) => <$ty as Constitutive>::gpu_params(m),)* }
            }
        }
    };
}

register! {
    LinearElastic(linear_elastic::LinearElastic),
    NeoHookean(neo_hookean::NeoHookean),
    MohrCoulomb(mohr_coulomb::MohrCoulomb),
    DruckerPrager(drucker_prager::DruckerPrager),
    ModifiedCamClay(modified_cam_clay::ModifiedCamClay),
}

/// The registered models' scene names, in registry order, for messages
/// that list them (`"a", "b" or "c"` with `quoted_list`).
pub fn names_where(keep: impl Fn(&Entry) -> bool) -> Vec<&'static str> {
    registry()
        .into_iter()
        .filter(|e| keep(e))
        .map(|e| e.name)
        .collect()
}

/// `names` as a message lists them: `a, b or c` (`word` = "or"/"and").
pub fn name_list(names: &[&str], word: &str) -> String {
    match names {
        [] => String::new(),
        [one] => one.to_string(),
        [rest @ .., last] => format!("{} {word} {last}", rest.join(", ")),
    }
}

/// Every distinct state column of the registered models, in registry order.
pub fn state_columns() -> Vec<StateColumn> {
    let mut out: Vec<StateColumn> = Vec::new();
    for c in registry().iter().flat_map(|e| e.state_columns) {
        if !out.contains(c) {
            out.push(*c);
        }
    }
    out
}

impl Material {
    /// The model keeps a deformation gradient per particle.
    pub fn needs_deformation_gradient(&self) -> bool {
        self.entry().state == StateKind::DefGrad
    }

    /// The model keeps a `PlasticState` per particle.
    pub fn needs_plastic_state(&self) -> bool {
        self.entry().state == StateKind::Plastic
    }
}

/// The generated WGSL of the material interface for `materials`' models
/// (`registry::wgsl`), as `generated/materials.wgsl`.
pub fn wgsl_of(materials: &[Material]) -> String {
    let used = materials.iter().fold(0, |b, m| b | 1 << m.entry().code);
    registry::wgsl(&registry(), used)
}

/// Every material of `file`, built and checked (the scene's model keys;
/// `scene::validate` checks the rest of the scene without the model).
pub fn check(file: &SceneFile) -> Result<Vec<Material>, SceneError> {
    file.materials
        .iter()
        .map(|(name, spec)| Material::from_spec(name, spec))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Drained biaxial compression in plane strain: the lateral stress held
    /// at −σc (solved each step by the secant method on ∂vx/∂x), the axial
    /// strain rate fixed, many small steps of `Material::update`. Returns
    /// the largest deviator (σc − σ_axial, compression positive) reached.
    fn biaxial_peak(m: &Material, sigma_c: f64, steps: usize, dt: f64) -> f64 {
        let mut s = [-sigma_c, -sigma_c, 0.0];
        let mut f = [1.0, 0.0, 0.0, 1.0];
        let mut q = [-sigma_c, 0.0, 0.0, 0.0];
        let lyy = -1.0; // 1/s: Δεyy = −dt per step.
        let (lame, shear) = m.lame_shear();
        let mut peak: f64 = 0.0;
        for _ in 0..steps {
            let trial = |lxx: f64| {
                let (mut s1, mut f1, mut q1) = (s, f, q);
                m.update([lxx, 0.0, 0.0, lyy], dt, &mut s1, &mut f1, &mut q1)
                    .unwrap();
                (s1, f1, q1)
            };
            let r = |lxx: f64| trial(lxx).0[0] + sigma_c;
            let mut a = -lame * lyy / (lame + 2.0 * shear);
            let mut b = a * 1.01 + 1e-3;
            let (mut ra, mut rb) = (r(a), r(b));
            for _ in 0..60 {
                if rb.abs() < 1e-9 * sigma_c || rb == ra {
                    break;
                }
                let c = b - rb * (b - a) / (rb - ra);
                (a, ra) = (b, rb);
                (b, rb) = (c, r(c));
            }
            assert!(rb.abs() < 1e-6 * sigma_c, "lateral stress not held: {rb}");
            (s, f, q) = trial(b);
            peak = peak.max(-s[1] - sigma_c);
        }
        peak
    }

    fn material(model: &str, psi: f64) -> Material {
        let spec = MaterialSpec::new(model, 1800.0)
            .with("E", 2.0e7)
            .with("nu", 0.3)
            .with("cohesion", 1.0e4)
            .with("friction_angle", 30.0)
            .with("dilation_angle", psi);
        Material::from_spec("m", &spec).unwrap()
    }

    /// Mohr–Coulomb's plane-strain peak: (σ1 − σ3) = 2c cos φ + (σ1 + σ3) sin φ
    /// with compression positive, σ3 = σc: q = (2c cos φ + 2σc sin φ)/(1 − sin φ).
    fn mc_peak(c: f64, phi_deg: f64, sigma_c: f64) -> f64 {
        let (sp, cp) = phi_deg.to_radians().sin_cos();
        (2.0 * c * cp + 2.0 * sigma_c * sp) / (1.0 - sp)
    }

    /// The biaxial peak within this fraction of Mohr–Coulomb's (issue 11).
    const PEAK_REL: f64 = 5e-3;

    #[test]
    fn biaxial_test_reaches_the_mohr_coulomb_peak() {
        for sigma_c in [5.0e4, 2.0e5] {
            let want = mc_peak(1.0e4, 30.0, sigma_c);
            for psi in [0.0, 15.0] {
                let m = material("mohr_coulomb", psi);
                // Δεyy = 1e-5 per step to 4 % axial strain.
                let got = biaxial_peak(&m, sigma_c, 4000, 1e-5);
                let err = (got - want) / want;
                println!("MC σc = {sigma_c}, ψ = {psi}: peak {got:.2} vs {want:.2} ({err:+.2e})");
                assert!(
                    err.abs() < PEAK_REL,
                    "MC σc = {sigma_c} ψ = {psi}: {got} vs {want}"
                );
            }
        }
    }

    #[test]
    fn biaxial_test_of_matched_drucker_prager() {
        // The plane-strain match is exact at collapse with associated flow
        // (plastic εzz rate zero): ψ = φ reaches MC's peak; ψ = 0 (szz = 0
        // at collapse) stays below it.
        let sigma_c = 1.0e5;
        let want = mc_peak(1.0e4, 30.0, sigma_c);
        let m = material("drucker_prager", 30.0);
        let got = biaxial_peak(&m, sigma_c, 4000, 1e-5);
        let err = (got - want) / want;
        println!("DP ψ = φ: peak {got:.2} vs MC {want:.2} ({err:+.2e})");
        assert!(err.abs() < PEAK_REL, "{got} vs {want}");
        let m = material("drucker_prager", 0.0);
        let got = biaxial_peak(&m, sigma_c, 4000, 1e-5);
        println!("DP ψ = 0: peak {got:.2} vs MC {want:.2}");
        assert!(got < want, "{got} vs {want}");
    }

    /// Every model names what its state holds (`STATE_COLUMNS`): a plastic
    /// model the two middle slots of its `PlasticState`, the others none;
    /// distinct columns have distinct names, none the outputs' fixed ones.
    #[test]
    fn every_model_names_its_state_columns() {
        for e in registry() {
            let want = if e.state == StateKind::Plastic { 2 } else { 0 };
            assert_eq!(e.state_columns.len(), want, "{}", e.name);
        }
        let all = state_columns();
        for (i, a) in all.iter().enumerate() {
            for b in &all[i + 1..] {
                assert!(a.column != b.column && a.array != b.array, "{a:?} {b:?}");
            }
            assert!(!["szz", "plastic", "stress_zz", "body"].contains(&a.column));
        }
        let names: Vec<&str> = all.iter().map(|c| c.column).collect();
        assert_eq!(names, ["eps_p", "eps_pv", "p_c", "v"]);
    }

    /// σzz as each model makes it: ν (σxx + σyy) for linear elasticity,
    /// λ ln J / J for Neo-Hookean (J from F, else ρ0 / ρ), carried in the
    /// plastic state otherwise (0 without one).
    #[test]
    fn every_model_gives_its_own_szz() {
        let s = [-3.0e4, -1.0e4, 2.0e3];
        let f = [1.01, 0.02, -0.01, 0.98];
        let q = [-7.5e3, 0.0, 0.0, 0.0];
        for e in registry() {
            let spec = MaterialSpec::new(e.name, 1800.0)
                .with("E", 2.0e7)
                .with("nu", 0.3);
            let spec = if e.state != StateKind::Plastic {
                spec
            } else if e.name != "modified_cam_clay" {
                spec.with("cohesion", 1.0e4).with("friction_angle", 30.0)
            } else {
                MaterialSpec::new(e.name, 1800.0)
                    .with("kappa", 0.04)
                    .with("lambda", 0.2)
                    .with("M", 1.2)
                    .with("N", 2.5)
                    .with("p0", 1.0e5)
                    .with("nu", 0.3)
            };
            let m = Material::from_spec("m", &spec).unwrap();
            let got = m.stress_zz(&s, Some(&f), 1700.0, Some(&q));
            let want = match &m {
                Material::LinearElastic(l) => l.nu * (s[0] + s[1]),
                Material::NeoHookean(n) => {
                    let j = f[0] * f[3] - f[1] * f[2];
                    let without = m.stress_zz(&s, None, 1700.0, None);
                    let j0: f64 = 1800.0 / 1700.0;
                    assert_eq!(without, n.lame * j0.ln() / j0);
                    n.lame * j.ln() / j
                }
                _ => {
                    assert_eq!(m.stress_zz(&s, Some(&f), 1700.0, None), 0.0);
                    q[0]
                }
            };
            assert_eq!(got, want, "{}", e.name);
        }
    }

    /// A model's faults are its own: declared once (`FAULTS`), numbered
    /// for the GPU by the registry, written into the generated WGSL and
    /// decoded back to the same fault; the solver's codes stay below them.
    #[test]
    fn material_faults_round_trip_through_the_gpu_codes() {
        use crate::model::fault::{Fault, FaultKind};
        for e in registry() {
            assert!(e.faults.len() <= registry::FAULT_SLOTS, "{}", e.name);
            let wgsl = registry::wgsl(&[e], 1 << e.code);
            for (i, f) in e.faults.iter().enumerate() {
                assert!(f.code.chars().all(|c| c.is_ascii_lowercase() || c == '_'));
                let code = e.gpu_fault_code(f.code).unwrap();
                assert_eq!(code, registry::GPU_FAULT_BASE + i as u32);
                assert!(code < 16, "fits the fault word's four bits");
                assert_eq!(e.fault_of_gpu_code(code), Some(*f));
                let line = format!(
                    "const {}_FAULT_{}: u32 = {code}u;",
                    e.name.to_uppercase(),
                    f.code.to_uppercase()
                );
                assert!(wgsl.contains(&line), "{line}");
            }
            assert_eq!(e.fault_of_gpu_code(registry::GPU_FAULT_BASE - 1), None);
        }
        let mcc = registry()
            .into_iter()
            .find(|e| e.name == "modified_cam_clay")
            .unwrap();
        assert_eq!(mcc.faults, &[modified_cam_clay::NOT_CONVERGED]);
        let fault = Fault::at(
            7,
            FaultKind::Material {
                fault: modified_cam_clay::NOT_CONVERGED,
                value: 2.5e-3,
            },
        );
        assert_eq!(fault.code(), "return_not_converged");
        assert_eq!(
            fault.to_string(),
            "the material's stress return did not converge (scaled residual 2.500e-3): \
             lower solver.cfl / solver.dt (particle 7)"
        );
        let gpu = Fault::at(
            7,
            FaultKind::Material {
                fault: modified_cam_clay::NOT_CONVERGED,
                value: f64::NAN,
            },
        );
        assert!(!gpu.to_string().contains("residual"), "{gpu}");
    }
}
