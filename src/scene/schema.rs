//! The scene file as written (TOML, read with serde): every key, its unit and
//! its default. `docs/scenes.md` documents the same keys for users; keep the
//! two in step. Validation of values happens in `scene::validate`.

use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// A whole scene file.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// Name used for the default output folder `out/<name>`. Default: file stem.
    pub name: Option<String>,
    /// Free text shown by `lme-mpm check`.
    #[serde(default)]
    pub description: String,
    /// Exact solution the run is scored against, if any.
    pub exact: Option<ExactKind>,
    /// A manufactured solution driving the scene (body force, initial velocity)
    /// and scoring it; sets `exact` to the solution's kind.
    pub manufactured: Option<ManufacturedSpec>,
    pub grid: GridSpec,
    /// Materials by name.
    pub materials: BTreeMap<String, MaterialSpec>,
    /// Bodies by name (their order in the file does not matter: sorted by name).
    pub bodies: BTreeMap<String, BodySpec>,
    /// Node constraints by name; reactions are reported per constraint.
    #[serde(default)]
    pub constraints: BTreeMap<String, ConstraintSpec>,
    /// Rigid walls (half-planes) by name; reactions are reported per wall.
    #[serde(default)]
    pub walls: BTreeMap<String, WallSpec>,
    /// Contact pairs between bodies by name: each body of a pair moves on
    /// its own grid velocity field; bodies in no pair share one field.
    #[serde(default)]
    pub contact: BTreeMap<String, ContactSpec>,
    /// Distributed loads on a body's boundary by name.
    #[serde(default)]
    pub tractions: BTreeMap<String, TractionSpec>,
    /// Concentrated loads by name.
    #[serde(default)]
    pub point_loads: BTreeMap<String, PointLoadSpec>,
    /// Drained boundaries of saturated soil by name: the pore pressure
    /// held on the nodes of a region (every other boundary is impermeable).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub drainage: BTreeMap<String, DrainageSpec>,
    /// Loaded rigid platens by name: the nodes of a region move as one
    /// along an axis under the forces on them.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub platens: BTreeMap<String, PlatenSpec>,
    pub gravity: Option<GravitySpec>,
    pub solver: SolverSpec,
    #[serde(default)]
    pub output: OutputSpec,
}

/// Background grid. The extent is derived from the bodies unless `min`/`max` are given.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct GridSpec {
    /// Node spacing h (m). Required.
    pub h: f64,
    /// A point that is a node (m). Default: lower-left corner of the bodies' bounding box.
    pub origin: Option<[f64; 2]>,
    /// Room left beyond the bodies for their motion (m). Default: max |v0| · t_end.
    pub margin: Option<f64>,
    /// Explicit lower-left corner of the grid (m); snapped outward to the node lattice.
    pub min: Option<[f64; 2]>,
    /// Explicit upper-right corner of the grid (m); snapped outward to the node lattice.
    pub max: Option<[f64; 2]>,
    /// Largest random displacement of each interior node coordinate, as a fraction of h.
    /// 0 = regular grid. Allowed: [0, 0.25). Default 0.
    #[serde(default)]
    pub perturb: f64,
    /// Seed of the node perturbation. Default 1.
    #[serde(default = "default_seed")]
    pub seed: u64,
}

fn default_seed() -> u64 {
    1
}

/// A material as the scene writes it: the model's name, the density and
/// the model's own keys (numbers; units and ranges per model). Each model
/// registers its keys in `model::material` (the registry), which checks
/// them, naming the key, before a model is built; here they are only read.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(try_from = "toml::Table", into = "toml::Table")]
pub struct MaterialSpec {
    /// The constitutive model (`model = "..."`): a name in the registry.
    pub model: String,
    /// Initial mass density ρ0 (kg/m³).
    pub density: f64,
    /// The model's other keys, by name (TOML integers read as numbers).
    pub values: BTreeMap<String, f64>,
}

impl MaterialSpec {
    /// A material of `model` with density `rho` (kg/m³) and no other keys.
    pub fn new(model: &str, rho: f64) -> MaterialSpec {
        MaterialSpec {
            model: model.to_string(),
            density: rho,
            values: BTreeMap::new(),
        }
    }

    /// This material with `key = value` added.
    pub fn with(mut self, key: &str, value: f64) -> MaterialSpec {
        self.values.insert(key.to_string(), value);
        self
    }

    /// The value of one of the model's keys, if given.
    pub fn get(&self, key: &str) -> Option<f64> {
        self.values.get(key).copied()
    }
}

impl TryFrom<toml::Table> for MaterialSpec {
    type Error = String;

    fn try_from(mut t: toml::Table) -> Result<MaterialSpec, String> {
        let model = match t.remove("model") {
            Some(toml::Value::String(s)) => s,
            Some(v) => return Err(format!("model must be a string, got {v}")),
            None => return Err("missing field `model`".to_string()),
        };
        let number = |k: &str, v: toml::Value| match v {
            toml::Value::Float(x) => Ok(x),
            toml::Value::Integer(i) => Ok(i as f64),
            v => Err(format!("`{k}` must be a number, got {v}")),
        };
        let density = number(
            "density",
            t.remove("density")
                .ok_or_else(|| "missing field `density`".to_string())?,
        )?;
        let values = t
            .into_iter()
            .map(|(k, v)| number(&k, v).map(|x| (k, x)))
            .collect::<Result<_, _>>()?;
        Ok(MaterialSpec {
            model,
            density,
            values,
        })
    }
}

impl From<MaterialSpec> for toml::Table {
    fn from(m: MaterialSpec) -> toml::Table {
        let mut t = toml::Table::new();
        t.insert("model".into(), toml::Value::String(m.model));
        t.insert("density".into(), toml::Value::Float(m.density));
        for (k, v) in m.values {
            t.insert(k, toml::Value::Float(v));
        }
        t
    }
}

/// Where a body's disks put their particles.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum DiskLayout {
    /// The cell's points (`layout`) that fall inside the disk: the disk's
    /// edge is a staircase of the particle lattice.
    #[default]
    Lattice,
    /// Concentric rings, spacing h/ppc across and along them, each
    /// particle its ring's area over the ring's count: round at the
    /// particle scale, mass exact.
    Rings,
}

/// How particles are placed inside each grid cell.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Layout {
    /// Gauss-Legendre points of the cell (volume = quadrature weight).
    Gauss,
    /// Centres of equal sub-cells (the uGIMP layout: voxels neither overlap nor leave gaps).
    Uniform,
}

#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    /// Name of a material in `[materials]`.
    pub material: String,
    /// Particles per cell per direction. Default 2.
    #[serde(default = "default_ppc")]
    pub ppc: u32,
    /// Initial velocity (m/s). Default [0, 0].
    #[serde(default)]
    pub velocity: [f64; 2],
    /// Particle layout. Default: `uniform` for uGIMP, `gauss` otherwise.
    pub layout: Option<Layout>,
    /// Where the body's disks put their particles. Default `lattice`.
    #[serde(default)]
    pub disk_layout: DiskLayout,
    /// Rectangles `[xmin, ymin, xmax, ymax]` (m).
    #[serde(default)]
    pub rects: Vec<[f64; 4]>,
    /// Disks `[cx, cy, r]` (m).
    #[serde(default)]
    pub disks: Vec<[f64; 3]>,
    /// Simple polygons, each a list of `[x, y]` vertices (m).
    #[serde(default)]
    pub polygons: Vec<Vec<[f64; 2]>>,
    /// The stress the body starts with. Default `none` (stress-free).
    #[serde(default)]
    pub initial_stress: InitialStress,
    /// With `initial_stress = "geostatic"`: σ_h / σ_v (> 0). Default
    /// 1 − sin φ for a material with a friction angle, ν/(1 − ν) otherwise.
    pub k0: Option<f64>,
    /// Saturated soil with `initial_stress = "geostatic"`: the y (m) of
    /// the phreatic level. Below it the pore pressure starts hydrostatic,
    /// p = ρ_w g (water_table − y), and the effective stress geostatic
    /// (σ'_v = σ_v + p, σ'_h = k0 σ'_v); the body's particles that start
    /// above it are dry (`model::pore`).
    pub water_table: Option<f64>,
}

/// A body's initial stress.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum InitialStress {
    /// Stress-free (the model's own initial state).
    #[default]
    None,
    /// At rest under gravity: σ_v from the weight of the material above
    /// each particle, σ_h = σ_zz = k0 σ_v (`model::geostatic`).
    Geostatic,
}

fn default_ppc() -> u32 {
    2
}

/// Directions a constraint fixes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Fix {
    X,
    Y,
    Xy,
}

/// Nodes whose (unperturbed) position lies in the box `[min, max]` have their
/// velocity and acceleration set to zero in the fixed directions.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ConstraintSpec {
    /// Lower-left corner of the region (m); `-inf` allowed.
    pub min: [f64; 2],
    /// Upper-right corner of the region (m); `inf` allowed.
    pub max: [f64; 2],
    pub fix: Fix,
    /// Prescribed velocity of the fixed components (m/s). Default [0, 0].
    #[serde(default)]
    pub velocity: [f64; 2],
    /// Linear ramp of `velocity` from 0 over this time (s); 0 = from the start. Default 0.
    #[serde(default)]
    pub ramp_time: f64,
}

/// A drained boundary (`[drainage.<name>]`): the nodes in the region
/// hold the pore pressure `pressure`.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct DrainageSpec {
    /// Lower-left corner of the region (m); `-inf` allowed.
    pub min: [f64; 2],
    /// Upper-right corner of the region (m); `inf` allowed.
    pub max: [f64; 2],
    /// Pore pressure held there (Pa, compression positive). Default 0.
    #[serde(default)]
    pub pressure: f64,
}

/// A loaded rigid platen (`[platens.<name>]`): the nodes in the region
/// move as one rigid, frictionless plate along `axis`, their velocity
/// component there the mass-weighted mean of theirs, driven by the forces
/// on them (its `force`, the material's reaction); across the axis they
/// stay free. A constraint with a
/// `velocity` is the displacement-driven platen; this is the
/// force-driven one (Mandel's plates).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PlatenSpec {
    /// Lower-left corner of the region (m); `-inf` allowed.
    pub min: [f64; 2],
    /// Upper-right corner of the region (m); `inf` allowed.
    pub max: [f64; 2],
    /// The direction the platen moves in, `x` or `y`. Default `y`.
    #[serde(default = "default_platen_axis")]
    pub axis: Axis,
    /// The load on the plate along `axis` (N per unit thickness, i.e.
    /// N/m; positive along +axis): a dead load spread over its nodes by
    /// their mass. Default 0 (a free plate).
    #[serde(default)]
    pub force: f64,
    /// Linear ramp of `force` from 0 over this time (s); 0 = sudden. Default 0.
    #[serde(default)]
    pub ramp_time: f64,
}

/// A coordinate direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Axis {
    X,
    Y,
}

impl Axis {
    /// 0 for x, 1 for y.
    pub fn index(self) -> usize {
        match self {
            Axis::X => 0,
            Axis::Y => 1,
        }
    }
}

fn default_platen_axis() -> Axis {
    Axis::Y
}

/// How a wall treats the material on it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Contact {
    /// Node velocity set to zero.
    Stick,
    /// Normal velocity into the wall removed; tangential free; separation free.
    Slip,
    /// Slip plus Coulomb friction on the tangential velocity (needs `friction`).
    Friction,
}

/// A rigid wall: the half-plane behind the line through `point` with
/// inward normal `normal`. Grid nodes with (x − point)·n ≤ 0 on the
/// unperturbed lattice are its nodes.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct WallSpec {
    /// A point of the wall line (m).
    pub point: [f64; 2],
    /// Normal pointing into the region where material may be; normalised on reading.
    pub normal: [f64; 2],
    pub contact: Contact,
    /// Coulomb friction coefficient μ ≥ 0, only with `contact = "friction"`.
    pub friction: Option<f64>,
    /// Time the wall starts to act (s), ≥ 0. Default 0 (from the start).
    #[serde(default)]
    pub appear_at: f64,
    /// Time the wall stops acting (s), > `appear_at` (a gate). Default:
    /// never.
    pub remove_at: Option<f64>,
}

/// Contact between two bodies: where both have mass at a node and their
/// particles' domains meet, the law acts on their relative velocity.
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// The two bodies (names under `[bodies]`), different.
    pub bodies: [String; 2],
    /// `stick` (no relative motion while approaching), `slip`
    /// (frictionless) or `friction` (Coulomb, needs `friction`).
    pub law: Contact,
    /// Coulomb friction coefficient μ ≥ 0, only with `law = "friction"`.
    pub friction: Option<f64>,
}

/// A traction on a segment of a body's boundary (dead load).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct TractionSpec {
    /// Start of the segment (m).
    pub from: [f64; 2],
    /// End of the segment (m).
    pub to: [f64; 2],
    /// Force per unit boundary length per unit thickness (Pa).
    pub traction: [f64; 2],
    /// Linear ramp from 0 over this time (s); 0 = sudden. Default 0.
    #[serde(default)]
    pub ramp_time: f64,
}

/// A concentrated force on the particle nearest to `at` (dead load).
#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PointLoadSpec {
    /// Where it acts (m).
    pub at: [f64; 2],
    /// Force per unit thickness (N/m).
    pub force: [f64; 2],
    /// Linear ramp from 0 over this time (s); 0 = sudden. Default 0.
    #[serde(default)]
    pub ramp_time: f64,
}

/// Time history of gravity.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Ramp {
    /// Full gravity from t = 0.
    None,
    /// The paper's eq. 45: 0.5 g (sin(2πt/T − π/2) + 1) for t ≤ T/2, then g.
    Sine,
}

#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct GravitySpec {
    /// Gravitational acceleration (m/s²), e.g. [0, -9.81].
    pub g: [f64; 2],
    /// Default `none`.
    #[serde(default = "default_ramp")]
    pub ramp: Ramp,
    /// T of eq. 45 (s): full gravity is reached at T/2. Required with `ramp = "sine"`.
    pub ramp_period: Option<f64>,
}

fn default_ramp() -> Ramp {
    Ramp::None
}

/// Shape functions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ShapeKind {
    /// Bilinear Q4 (isoparametric on perturbed grids).
    Linear,
    /// Uniform GIMP, particle half-width h/(2 ppc).
    Ugimp,
    /// Local max-ent (Arroyo & Ortiz), β = γ/h².
    Lme,
    /// Quadratic B-splines (open knot vectors at the grid's edge).
    Bspline2,
    /// Cubic B-splines (open knot vectors at the grid's edge).
    Bspline3,
}

/// Time integrators.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum IntegratorKind {
    /// Forward Euler in the Zhang et al. (2016) form (paper eqs. 22–23).
    Fe,
    /// Newmark predictor-corrector (paper Algorithm 1).
    Npc,
    /// Modified update stress last, the B-spline paper's update (eqs.
    /// 28–37): nodal momentum update, FLIP particle velocity, position from
    /// the updated nodal momentum, remap of the new particle velocities to
    /// the nodes (by MLS with `solver.mls`), velocity gradient from the
    /// remapped nodal velocity, then F, density and stress.
    Musl,
    /// Implicit Newmark with Newton–Raphson on the grid's displacement
    /// increment, updated Lagrangian (implicit-MPM paper §3–4). CPU only.
    Implicit,
}

/// The implicit step's inertia (mass matrix).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ImplicitMass {
    /// M_IK = Σ_p m_p N_I N_K (implicit-MPM paper eq. 35).
    Consistent,
    /// M_II = Σ_p m_p N_I, as the explicit step's.
    Lumped,
}

/// The implicit step's initial acceleration (`solver.implicit_start`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ImplicitStart {
    /// a = 0 at t = 0, the particles' initial data (the paper's).
    #[default]
    Rest,
    /// a₀ = (f_ext − f_int) / m at t = 0, Coulomb at closed wall contacts.
    Consistent,
}

/// How Newton builds its Jacobian (`solver.newton_jacobian`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum NewtonJacobian {
    /// Assembled and factored at every iteration: full Newton (the
    /// paper's), converging quadratically.
    #[default]
    EveryIteration,
    /// The last factorization kept while the wall contact states it was
    /// built with hold and the residual fell at least fourfold in the last
    /// iteration; rebuilt otherwise (modified Newton: more, cheaper
    /// iterations, the same converged step to the tolerance).
    Reuse,
}

/// What the implicit step solves on (`solver.method`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SolverMethod {
    /// The material point method: shape functions on the background grid,
    /// which is reset every step.
    #[default]
    Mpm,
    /// The Galerkin meshfree method of the implicit-MPM paper (§4.2,
    /// Algorithm 2): a node cloud that belongs to the body and moves with
    /// it, meshfree shape functions over each material point's cloud, and
    /// the Newmark predictor from the nodes' own previous state. Needs
    /// `integrator = "implicit"`.
    Gmm,
}

/// GMM's meshfree basis over a node cloud (`solver.gmm_basis`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum GmmBasis {
    /// Local max-ent with β = `lme_gamma` / h², h the initial node spacing.
    #[default]
    Lme,
    /// Moving least squares, linear basis, cubic-spline weight of support
    /// radius 2 · `gmm_dilation` · h.
    Mls,
}

/// Which nodal velocity moves the particles in the NPC particle update.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum NpcPosition {
    /// x += Δt Σ N v_I(corrected) + ½Δt² a_p (the authors' code).
    Corrected,
    /// x += Δt Σ N v_I(predicted) + ½Δt² a_p (the paper's printed eq. 30).
    Predicted,
    /// x += Δt Σ N v_I(predicted): Newmark's explicit displacement predictor
    /// (β = 0), the same displacement the strain increment was computed from.
    Newmark,
}

#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SolverSpec {
    /// Default `lme`.
    #[serde(default = "default_shape")]
    pub shape: ShapeKind,
    /// Dimensionless LME locality γ (β = γ/h²). Default 4.
    #[serde(default = "default_lme_gamma")]
    pub lme_gamma: f64,
    /// LME support truncation: nodes with exp(−β r²) < tol are dropped. Default 1e-6.
    #[serde(default = "default_lme_tol")]
    pub lme_tol: f64,
    /// Default `npc`.
    #[serde(default = "default_integrator")]
    pub integrator: IntegratorKind,
    /// Newmark γ of the predictor-corrector, in (0, 1]. Default 0.5.
    #[serde(default = "default_npc_gamma")]
    pub npc_gamma: f64,
    /// Default `newmark` (docs/methods.md gives the test that chose it).
    #[serde(default = "default_npc_position")]
    pub npc_position: NpcPosition,
    /// Courant number: Δt = cfl · h / max(|v_p|, c_p). In (0, 1] for the
    /// explicit integrators; the implicit one accepts up to 100. Default 0.1.
    #[serde(default = "default_cfl")]
    pub cfl: f64,
    /// Implicit: Newmark β, in (0, 0.5]. Default 0.25 (trapezoidal rule).
    #[serde(default = "default_newmark_beta")]
    pub newmark_beta: f64,
    /// Implicit: Newmark γ, in [0.5, 1]. Default 0.5.
    #[serde(default = "default_newmark_gamma")]
    pub newmark_gamma: f64,
    /// Implicit: the mass matrix. Default `consistent` (the paper's); `lumped`
    /// keeps nodes that carry a sliver of a particle well posed
    /// (docs/methods.md, "Implicit integrator").
    #[serde(default = "default_implicit_mass")]
    pub implicit_mass: ImplicitMass,
    /// Implicit, dynamic: the nodes' acceleration at the first step.
    /// Default `rest` (the paper's: the particles' initial a = 0);
    /// `consistent` solves it from the equations of motion at t = 0
    /// (docs/methods.md, "Implicit integrator").
    #[serde(default)]
    pub implicit_start: ImplicitStart,
    /// Implicit: a static analysis (no inertia): loads grow linearly to
    /// their full value over `load_steps` equal steps of pseudo-time up to
    /// `t_end`. Default false.
    #[serde(default, rename = "static")]
    pub static_analysis: bool,
    /// Implicit static: number of load increments. Default 1 (a step
    /// whose Newton fails is halved automatically, `newton_max_cuts`).
    #[serde(default = "default_load_steps")]
    pub load_steps: u32,
    /// Implicit: Newton converges when the residual norm relative to the
    /// step's first (or to the load's, if larger) is below this and the
    /// correction relative to the displacement increment (mass-weighted
    /// norms) below its square root. Default 1e-8.
    #[serde(default = "default_newton_tol")]
    pub newton_tol: f64,
    /// Implicit: Newton iterations per attempt of a step. Default 25.
    #[serde(default = "default_newton_max_iter")]
    pub newton_max_iter: u32,
    /// Implicit: times a step that does not converge is retried with half
    /// the Δt before the run stops as unstable (`newton_diverged`). Default 6.
    #[serde(default = "default_newton_max_cuts")]
    pub newton_max_cuts: u32,
    /// Implicit: full Newton (`every_iteration`, default) or the
    /// factorization reused while it still converges fast (`reuse`).
    #[serde(default)]
    pub newton_jacobian: NewtonJacobian,
    /// `mpm` (the grid) or `gmm` (a node cloud moving with the body; needs
    /// `integrator = "implicit"`). Default `mpm`.
    #[serde(default)]
    pub method: SolverMethod,
    /// GMM: the meshfree basis, `lme` (γ from `lme_gamma`) or `mls`.
    /// Default `lme`.
    #[serde(default)]
    pub gmm_basis: GmmBasis,
    /// GMM: the radius within which a material point gathers its cloud of
    /// nodes, in units of the initial node spacing `grid.h`. Default √2,
    /// the paper's r = sqrt(2 h²) (§5.1, §5.3); in [1, 4].
    #[serde(default = "default_gmm_search_radius")]
    pub gmm_search_radius: f64,
    /// GMM with `mls`: the dilation f of the weight, in units of `grid.h`;
    /// the cubic-spline weight reaches zero at 2 f. Default √2/2, the
    /// paper's f = r/2 (§5.1); in [0.6, 4].
    #[serde(default = "default_gmm_dilation")]
    pub gmm_dilation: f64,
    /// End time (s). Required.
    pub t_end: f64,
    /// Fixed time step (s), in place of the CFL condition (the manufactured
    /// solution study uses the paper's 1e-5 s). Default: none, Δt from `cfl`.
    pub dt: Option<f64>,
    /// Moving-least-squares reconstruction (B-spline paper): mass, momentum,
    /// body force and stress reconstructed at 2 × 2 Gauss points per cell and
    /// integrated there. With `bspline2`, `bspline3` or `linear` on a regular
    /// grid (uGIMP, LME and perturbed grids are refused). Default false.
    #[serde(default)]
    pub mls: bool,
    /// Half-width of the MLS weight's support, in cells: the weight of eq.
    /// 17 is taken at r = 1.5 Δx / (mls_support · h). Default 3, the paper's
    /// r = Δx/(2h); in [1.5, 3].
    #[serde(default = "default_mls_support")]
    pub mls_support: f64,
    /// What the MLS fit does (with `mls = true`): `all` (the paper's step:
    /// mass, momentum, body force and stress fitted and integrated at the
    /// Gauss points, and the remap through them) or `force` (the fit only
    /// corrects the quadrature of the internal force, and the strain rate
    /// by its transpose; every other transfer is plain MPM through the
    /// particles' own N_I(x_p); docs/methods.md,
    /// "MLS as a force correction"). Default `all`.
    #[serde(default)]
    pub mls_scope: MlsScope,
    /// Where the B-splines' knots sit (`bspline2`, `bspline3` only):
    /// `midpoints` (the default; one basis per grid node) or `cells` (the
    /// B-spline paper's Fig. 1: knots on the grid lines, n + p bases over
    /// n cells). None when the scene does not say.
    #[serde(default)]
    pub bspline_knots: Option<BsplineKnots>,
    /// Share α of PIC in the particle velocity update, in [0, 1]:
    /// v_p ← (1 − α) v_FLIP + α v_PIC (explicit integrators). Default 0
    /// (pure FLIP), but 0.01 for a cohesionless granular scene
    /// (`defaults::pic_fraction`), which the checked scene then sets.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pic_fraction: Option<f64>,
    /// Cundall's non-viscous local damping α, in [0, 1): each component of
    /// the unbalanced nodal force loses α |f| sign(v) (explicit
    /// integrators). Default 0 (none).
    #[serde(default)]
    pub local_damping: f64,
    /// The volumetric part of each particle's strain rate: its own
    /// (`particle`, the default) or the volume-weighted mean of tr L over
    /// the particles of its body in its grid cell (`cell_average`: a B-bar
    /// against volumetric locking under nearly incompressible plastic
    /// flow, Coombs et al. 2018). Explicit integrators, CPU path.
    #[serde(default)]
    pub volumetric_strain: VolumetricStrain,
    /// Saturated soil: where the mass balance takes the volumetric strain
    /// rate (`nodal`, the stabilised default, or `particle`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pore_volumetric: Option<PoreVolumetric>,
}

/// Where the pore fluid's mass balance takes −∇·v (`solver.pore_volumetric`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PoreVolumetric {
    /// On the nodes, with the flow, Σ_p V_p N_I tr L_p: the pressure is
    /// one field on the grid (stable with equal-order interpolation).
    #[default]
    Nodal,
    /// At each particle from its own tr L_p: equal-order u–p, which
    /// oscillates from particle to particle; kept to show it.
    Particle,
}

/// The volumetric strain rate a particle's stress update takes
/// (`solver.volumetric_strain`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum VolumetricStrain {
    /// tr L_p, the particle's own.
    #[default]
    Particle,
    /// The cell's volume-weighted mean over the particles of the same body.
    CellAverage,
}

/// Where the B-splines' knots sit (`solver.bspline_knots`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BsplineKnots {
    /// Quadratic: interior knots at the cell midpoints, end spans 1.5
    /// cells; cubic: at the nodes, end spans 2 cells. One basis per grid
    /// node, its Greville point the node (away from the edge).
    #[default]
    Midpoints,
    /// The paper's: a knot on every grid line, so the knot spans are the
    /// cells; n + p bases over n cells per direction, their Greville
    /// points the cell midpoints (quadratic) or the nodes (cubic), and
    /// the ends.
    Cells,
}

/// What the MLS fit reconstructs (`solver.mls_scope`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum MlsScope {
    /// The B-spline paper's step: every transfer through the Gauss points.
    #[default]
    All,
    /// The fit corrects the internal force's quadrature only:
    /// f_I = −Σ_p V_p σ_p ∇N_I(x_p) − [Σ_g ω_g σ_h(x_g) ∇N_I(x_g) − Σ_p V_p σ_h(x_p) ∇N_I(x_p)],
    /// and the strain rate by the bracket's transpose (`Mls::strain_correction`).
    Force,
}

impl SolverSpec {
    /// Every key at its default (`t_end` 1 s, which has none): what a
    /// scene that does not set a key runs with.
    pub fn defaults() -> SolverSpec {
        toml::from_str("t_end = 1.0").expect("the solver's defaults deserialise")
    }
}

fn default_gmm_search_radius() -> f64 {
    crate::limits::GMM_SEARCH_RADIUS_DEFAULT
}

fn default_gmm_dilation() -> f64 {
    0.5 * crate::limits::GMM_SEARCH_RADIUS_DEFAULT
}

fn default_mls_support() -> f64 {
    crate::limits::MLS_SUPPORT_MAX
}

fn default_shape() -> ShapeKind {
    ShapeKind::Lme
}
fn default_lme_gamma() -> f64 {
    4.0
}
fn default_lme_tol() -> f64 {
    1e-6
}
fn default_integrator() -> IntegratorKind {
    IntegratorKind::Npc
}
fn default_npc_gamma() -> f64 {
    0.5
}
fn default_npc_position() -> NpcPosition {
    NpcPosition::Newmark
}
fn default_cfl() -> f64 {
    0.1
}
fn default_newmark_beta() -> f64 {
    0.25
}
fn default_newmark_gamma() -> f64 {
    0.5
}
fn default_implicit_mass() -> ImplicitMass {
    ImplicitMass::Consistent
}
fn default_load_steps() -> u32 {
    1
}
fn default_newton_tol() -> f64 {
    1e-8
}
fn default_newton_max_iter() -> u32 {
    25
}
fn default_newton_max_cuts() -> u32 {
    6
}

#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Interval between samples of probes, energy and reactions (s). Default: t_end / 500.
    pub sample_interval: Option<f64>,
    /// Interval between VTK snapshots (s). Default: none (only the final state, if `vtk_final`).
    pub vtk_interval: Option<f64>,
    /// Interval between checkpoints (`checkpoint.lmeck`, for `lme-mpm resume`) (s).
    /// Default: none (a checkpoint is still written when a run is interrupted).
    pub checkpoint_interval: Option<f64>,
    /// Write a VTK snapshot of the final state. Default true.
    #[serde(default = "default_true")]
    pub vtk_final: bool,
    /// Write `particles.csv` at the end. Default true.
    #[serde(default = "default_true")]
    pub particles_csv: bool,
    /// Leave `checkpoint.lmeck` at t_end when the run completes, so
    /// `lme-mpm resume DIR --set solver.t_end=LATER` can extend it (124 to
    /// 188 bytes per particle on disk, docs/outputs.md). Default true.
    #[serde(default = "default_true")]
    pub final_checkpoint: bool,
    /// Named points (m); the particle nearest to each at t = 0 is tracked.
    #[serde(default)]
    pub probes: BTreeMap<String, [f64; 2]>,
}

impl Default for OutputSpec {
    fn default() -> Self {
        OutputSpec {
            sample_interval: None,
            vtk_interval: None,
            checkpoint_interval: None,
            vtk_final: true,
            particles_csv: true,
            final_checkpoint: true,
            probes: BTreeMap::new(),
        }
    }
}

fn default_true() -> bool {
    true
}

/// Exact solutions known to the code.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ExactKind {
    /// 1D bar, free at its left end, fixed at its right end, piecewise-constant
    /// initial velocity (Dyka's bar, paper appendix A).
    DykaBar,
    /// Elastic column on a fixed base under (ramped) gravity (Andersen's block).
    ElasticColumn,
    /// The manufactured 2D aligned vibration (set by `[manufactured]`).
    AlignedVibration,
    /// A block sliding from rest on one frictional (or slip) wall under
    /// gravity: v = max(g_t − μ g_n, 0) t along the wall.
    SlidingBlock,
    /// A disk rolling without slip down a wall under constant gravity
    /// (implicit-MPM paper §5.2): a = (2/3) g_t.
    RollingDisk,
    /// Cantilever under self-weight, static (implicit-MPM paper §5.1): the
    /// free end's mid-height deflection against 0.67433 m.
    Cantilever,
    /// The one contact pair's first body sliding on a face of its second
    /// under gravity: slide = max(g_t − μ g_n, 0) ∫R (a t²/2 unramped).
    ContactSliding,
    /// The one contact pair's first body, a disk, rolling without slip on
    /// its second: the centre moves (2/3) g_t t²/2.
    ContactRolling,
    /// Two disks meeting through a frictionless pair: momentum kept, no spin.
    DiskImpact,
    /// A strip footing (the pair's first body) on a Tresca soil (its
    /// second): the peak q/c against Prandtl's 2 + π.
    PrandtlFooting,
    /// Drained compression of modified Cam-clay: q/p′ at t_end against M.
    CriticalState,
    /// The implicit-MPM paper's cohesive column collapse (§5.3): run-out
    /// and height against `study column`'s figures (the paper has pictures).
    ColumnCollapse,
    /// A cohesionless column collapse: (L_f − W)/W against the
    /// experiments' 1.2 a.
    GranularCollapse,
    /// Nothing does work: kinetic + strain energy at t_end against the start's.
    Energy,
    /// Terzaghi's consolidation of a saturated layer drained at its top:
    /// pore pressure, degree of consolidation and settlement at t_end
    /// against the series (`exact::terzaghi`).
    Terzaghi,
    /// Mandel's problem: a saturated quarter specimen under a loaded
    /// platen, drained at its side: the centre's pore pressure at t_end
    /// against the closed form, with its Mandel–Cryer rise
    /// (`exact::mandel`).
    Mandel,
}

/// Manufactured solutions known to the code.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ManufacturedKind {
    /// B-spline paper eq. 38: u = A [sin(2πX/L) sin(cπt/L), sin(2πY/L) sin(cπt/L + π)],
    /// c = sqrt(E/ρ0), on a square of side L, Neo-Hookean.
    AlignedVibration,
}

#[derive(Debug, Clone, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ManufacturedSpec {
    pub solution: ManufacturedKind,
    /// Displacement amplitude A (m), below L/(2π) so that det F stays positive.
    pub amplitude: f64,
}

/// A checked scene. Fields are the schema's, with defaults resolved.
#[derive(Debug, Clone)]
pub struct Scene {
    /// Output folder name (file stem unless `name` is set).
    pub name: String,
    /// The file after overrides and defaults (echoed into `summary.json`).
    pub file: SceneFile,
    /// `grid.margin`, resolved (m).
    pub margin: f64,
    /// `output.sample_interval`, resolved (s).
    pub sample_interval: f64,
    /// Defaults chosen from what the scene models (`scene::defaults`), in
    /// words, for `check` and the run's log.
    pub chosen: Vec<String>,
}

impl Scene {
    pub fn solver(&self) -> &SolverSpec {
        &self.file.solver
    }

    /// Bodies in a fixed order (by name); a particle's `body` indexes this.
    pub fn bodies(&self) -> impl Iterator<Item = (&String, &BodySpec)> {
        self.file.bodies.iter()
    }

    /// Materials in a fixed order (by name).
    pub fn materials(&self) -> impl Iterator<Item = (&String, &MaterialSpec)> {
        self.file.materials.iter()
    }

    /// Index of a material by name in `materials()` order.
    pub fn material_index(&self, name: &str) -> usize {
        self.file
            .materials
            .keys()
            .position(|k| k == name)
            .expect("validated: every body names an existing material")
    }

    /// Particle layout of a body, resolving the shape-dependent default.
    pub fn layout(&self, body: &BodySpec) -> Layout {
        body.layout.unwrap_or(match self.file.solver.shape {
            ShapeKind::Ugimp => Layout::Uniform,
            _ => Layout::Gauss,
        })
    }
}
