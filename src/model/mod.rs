//! What a run is: the grid, the particles (structure of arrays), node
//! constraints, loads and solver settings, built from a checked `Scene`.
//! Everything here is backend-neutral; `cpu::` and `gpu::` step it.

pub mod constraint_points;
pub mod contact;
pub mod energy;
pub mod fault;
pub mod gauss;
pub mod geostatic;
mod grid;
pub mod loads;
pub mod material;
mod particles;
pub mod pore;
pub mod preload_fit;
pub mod shape;
pub mod time_step;
pub mod walls;

pub use constraint_points::ConstraintPoint;
pub use contact::Contacts;
pub use grid::{Grid, inside};
pub use loads::{AlignedVibration, ExternalForces, Gravity};
pub use particles::{Particles, node_force};
pub use walls::{Wall, Walls};

use crate::error::SceneError;
use crate::model::material::Material;
use crate::model::shape::Shape;
use crate::scene::{
    Fix, GmmBasis, ImplicitMass, ImplicitStart, IntegratorKind, MlsScope, NpcPosition, Scene,
    SolverMethod, seed,
};

/// Nodes lighter than this (kg) count as empty. Relative to the lightest
/// particle: 1e-9 keeps LME tail nodes (N ≳ 1e-6) and drops only round-off.
/// Both backends scale it by the lightest particle's mass.
pub const MASS_EPS_REL: f64 = 1e-9;

/// Bit of `Constraints::fix` for a node fixed in x.
pub const FIX_X: u8 = 1;
/// Bit of `Constraints::fix` for a node fixed in y.
pub const FIX_Y: u8 = 2;

/// One named constraint: its nodes and directions (reactions are summed per constraint).
#[derive(Debug, Clone)]
pub struct ConstraintGroup {
    pub name: String,
    pub nodes: Vec<u32>,
    /// `FIX_X`, `FIX_Y` or both.
    pub fix: u8,
    /// Prescribed velocity of the fixed components at full ramp (m/s).
    pub velocity: [f64; 2],
    /// Time to reach `velocity` from 0, linearly (s); 0 = from the start.
    pub ramp_time: f64,
    /// The region's nodes at t = 0 as a box of the lattice, `[i0, i1, j0,
    /// j1]` (inclusive); a moving group's nodes are this box shifted by
    /// `shift` (`Constraints::move_to`).
    pub cells: [usize; 4],
    /// The `shift` its `nodes` stand at (whole spacings; [0, 0] at t = 0).
    pub shifted: [i64; 2],
}

impl ConstraintGroup {
    /// Prescribed velocity at time `t` (m/s).
    pub fn velocity_at(&self, t: f64) -> [f64; 2] {
        let r = loads::ramp_factor(t, self.ramp_time);
        [r * self.velocity[0], r * self.velocity[1]]
    }

    /// Whether it prescribes a non-zero velocity on a fixed component.
    pub fn moves(&self) -> bool {
        (self.fix & FIX_X != 0 && self.velocity[0] != 0.0)
            || (self.fix & FIX_Y != 0 && self.velocity[1] != 0.0)
    }

    /// How far the region has moved by time `t` (m): the time integral of
    /// `velocity_at` on the fixed components, zero on the free ones.
    pub fn travel(&self, t: f64) -> [f64; 2] {
        let s = if self.ramp_time > 0.0 && t < self.ramp_time {
            t * t / (2.0 * self.ramp_time)
        } else {
            t - 0.5 * self.ramp_time
        };
        let along = |bit: u8, v: f64| if self.fix & bit != 0 { s * v } else { 0.0 };
        [
            along(FIX_X, self.velocity[0]),
            along(FIX_Y, self.velocity[1]),
        ]
    }

    /// The whole node spacings the region's nodes have moved by time `t`:
    /// `travel` / h rounded to the nearest (halves up), as the WGSL twin
    /// computes it (`shaders/grid_update.wgsl`, `shift`).
    pub fn shift(&self, t: f64, h: f64) -> [i64; 2] {
        let d = self.travel(t);
        [
            (d[0] / h + 0.5).floor() as i64,
            (d[1] / h + 0.5).floor() as i64,
        ]
    }

    /// The region's nodes at time `t` on a lattice of `nx` × `ny` nodes at
    /// spacing `h`: the box at t = 0 shifted by `shift`, less what falls
    /// off the grid; a side on the grid's edge stays there (a region
    /// reaching the edge, often to ±inf, keeps reaching it).
    pub fn nodes_at(&self, t: f64, h: f64, nx: usize, ny: usize) -> Vec<u32> {
        let s = self.shift(t, h);
        let side = |lo: usize, hi: usize, n: usize, s: i64| {
            let a = if lo == 0 { 0 } else { lo as i64 + s };
            let b = if hi + 1 == n {
                n as i64 - 1
            } else {
                hi as i64 + s
            };
            (a.max(0), b.min(n as i64 - 1))
        };
        let [i0, i1, j0, j1] = self.cells;
        let (a0, a1) = side(i0, i1, nx, s[0]);
        let (b0, b1) = side(j0, j1, ny, s[1]);
        let mut out = Vec::new();
        for j in b0..=b1 {
            for i in a0..=a1 {
                out.push((j as usize * nx + i as usize) as u32);
            }
        }
        out
    }
}

/// Dirichlet nodes (zero or prescribed velocity), and the points where a
/// region's edge inside the grid holds the body (`constraint_points`).
#[derive(Debug, Clone, Default)]
pub struct Constraints {
    /// Per node: `FIX_X | FIX_Y` bits (0 = free).
    pub fix: Vec<u8>,
    pub groups: Vec<ConstraintGroup>,
    /// Empty unless some group's edge lies inside the grid where nodes
    /// outside its region reach it.
    pub points: Vec<ConstraintPoint>,
    /// Per group: the region's nodes its points freed (sorted; empty
    /// without points). The GPU keeps each group as its region's box of
    /// nodes less these (`gpu::buffers::constraint_boxes`).
    pub freed: Vec<Vec<u32>>,
    /// Loaded rigid platens (`[platens]`), each tying its nodes' velocity
    /// along an axis (`cpu::grid_update::platens`).
    pub platens: Vec<Platen>,
}

/// One `[platens.<name>]`: the nodes that move as one along `axis`.
#[derive(Debug, Clone)]
pub struct Platen {
    pub name: String,
    pub nodes: Vec<u32>,
    /// 0 = x, 1 = y.
    pub axis: usize,
    /// The load along the axis (N/m) at full value, and its ramp time (s).
    pub force: f64,
    pub ramp_time: f64,
}

impl Platen {
    /// The load (N/m) at time `t` (s).
    pub fn force_at(&self, t: f64) -> f64 {
        loads::ramp_factor(t, self.ramp_time) * self.force
    }
}

impl Constraints {
    /// Takes `placed`'s points: each group drops the region nodes they
    /// free, and the fixed bits are rebuilt from the groups (no points:
    /// nothing changes).
    pub fn hold_at(&mut self, placed: constraint_points::Placement) {
        if placed.points.is_empty() {
            return;
        }
        for (group, freed) in self.groups.iter_mut().zip(&placed.freed) {
            group.nodes.retain(|n| freed.binary_search(n).is_err());
        }
        self.fix.fill(0);
        for group in &self.groups {
            for &n in &group.nodes {
                self.fix[n as usize] |= group.fix;
            }
        }
        self.points = placed.points;
        self.freed = placed.freed;
    }

    /// Moves the regions of the groups that prescribe a velocity to where
    /// they are at time `t` (`ConstraintGroup::nodes_at`), so a platen
    /// keeps pressing as the material it pushes moves, and rebuilds the
    /// fixed bits when a region's nodes changed. Groups holding points
    /// never move (`Model::new` refuses one that would).
    pub fn move_to(&mut self, t: f64, h: f64, nx: usize, ny: usize) {
        let mut changed = false;
        for (k, g) in self.groups.iter_mut().enumerate() {
            let points = self.freed.get(k).is_some_and(|f| !f.is_empty());
            if !g.moves() || points {
                continue;
            }
            // Only when it crosses a node line: no allocation per step.
            let shift = g.shift(t, h);
            if shift == g.shifted {
                continue;
            }
            g.shifted = shift;
            let nodes = g.nodes_at(t, h, nx, ny);
            if nodes != g.nodes {
                g.nodes = nodes;
                changed = true;
            }
        }
        if changed {
            self.fix.fill(0);
            for group in &self.groups {
                for &n in &group.nodes {
                    self.fix[n as usize] |= group.fix;
                }
            }
        }
    }
}

/// Time integrator with its parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Integrator {
    Fe,
    Npc {
        gamma: f64,
        position: NpcPosition,
    },
    /// Modified update stress last (B-spline paper eqs. 28–37).
    Musl,
    /// Implicit Newmark with Newton–Raphson (`cpu::implicit`).
    Implicit(ImplicitSettings),
}

/// The implicit integrator's settings (`solver.*` keys of the same names).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImplicitSettings {
    /// Newmark β and γ.
    pub beta: f64,
    pub gamma: f64,
    /// No inertia; loads scaled by t / t_end over `load_steps` steps.
    pub static_analysis: bool,
    pub load_steps: u32,
    /// Relative residual and correction norms that end Newton.
    pub tol: f64,
    pub max_iter: u32,
    /// Keep Newton's factorization from one iteration to the next while
    /// it converges fast (`solver.newton_jacobian = "reuse"`).
    pub reuse_jacobian: bool,
    /// Halvings of Δt allowed for a step before the run is unstable.
    pub max_cuts: u32,
    /// Lumped instead of consistent mass.
    pub lumped_mass: bool,
    /// The first step starts from a₀ = (f_ext − f_int) / m instead of 0
    /// (`solver.implicit_start = "consistent"`).
    pub consistent_start: bool,
    /// The Galerkin meshfree method's settings (`solver.method = "gmm"`):
    /// the step solves on a node cloud that moves with the body instead of
    /// the grid. None: implicit MPM.
    pub gmm: Option<GmmSettings>,
}

/// GMM's basis and cloud (`solver.gmm_*` keys, `solver.lme_gamma`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GmmSettings {
    pub basis: GmmBasis,
    /// LME locality γ = β h² (h the initial node spacing, `grid.h`).
    pub gamma: f64,
    /// Search radius, in units of h.
    pub search_radius: f64,
    /// MLS dilation f, in units of h (the weight vanishes at 2 f).
    pub dilation: f64,
}

/// Every body's shapes as the scene gives them (m): rectangles
/// `[xmin, ymin, xmax, ymax]`, disks `[cx, cy, r]`, simple polygons.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BodyOutline {
    pub rects: Vec<[f64; 4]>,
    pub disks: Vec<[f64; 3]>,
    pub polygons: Vec<Vec<[f64; 2]>>,
}

impl Integrator {
    pub fn kind(&self) -> IntegratorKind {
        match self {
            Integrator::Fe => IntegratorKind::Fe,
            Integrator::Npc { .. } => IntegratorKind::Npc,
            Integrator::Musl => IntegratorKind::Musl,
            Integrator::Implicit(_) => IntegratorKind::Implicit,
        }
    }
}

/// A tracked particle.
#[derive(Debug, Clone)]
pub struct Probe {
    pub name: String,
    /// Requested point (m).
    pub point: [f64; 2],
    /// Index of the particle nearest to `point` at t = 0.
    pub particle: usize,
}

/// Everything a backend needs to run a scene.
#[derive(Debug, Clone)]
pub struct Model {
    pub grid: Grid,
    pub shape: Shape,
    pub particles: Particles,
    /// Materials in scene order; `body_material[b]` indexes this.
    pub materials: Vec<Material>,
    pub body_material: Vec<u32>,
    pub body_names: Vec<String>,
    pub constraints: Constraints,
    /// Rigid walls with their contact laws (empty: none).
    pub walls: Walls,
    /// Contact pairs between bodies and each body's field; None without
    /// pairs (one shared field, as ever).
    pub contact: Option<Contacts>,
    pub gravity: Option<Gravity>,
    /// Tractions and point loads as particle forces (None: the scene has none).
    pub external: Option<ExternalForces>,
    pub integrator: Integrator,
    /// Courant number.
    pub cfl: f64,
    /// End time (s).
    pub t_end: f64,
    /// Fixed time step (s) in place of the CFL condition.
    pub fixed_dt: Option<f64>,
    /// MLS reconstruction at Gauss points (`solver.mls`).
    pub mls: bool,
    /// MLS weight support half-width (cells, `solver.mls_support`).
    pub mls_support: f64,
    /// What the fit does (`solver.mls_scope`): the paper's step or only the
    /// internal force's quadrature correction.
    pub mls_scope: MlsScope,
    /// Share α of PIC in the particle velocity update (`solver.pic_fraction`,
    /// 0 = FLIP; explicit integrators, `g2p`).
    pub pic_fraction: f64,
    /// Cundall's local damping α (`solver.local_damping`, 0 = none;
    /// explicit integrators, `grid_update::correct`).
    pub local_damping: f64,
    /// `solver.volumetric_strain = "cell_average"`: each particle's
    /// volumetric strain rate is its cell's mean over its body
    /// (`cpu::cell_average`).
    pub cell_average_volumetric: bool,
    /// Saturated soil: the pore fluid per material and the drained nodes
    /// (`pore`); None in a dry scene.
    pub pore: Option<pore::Pore>,
    pub probes: Vec<Probe>,
    /// A manufactured solution's body force, applied to every particle at
    /// its reference position each step.
    pub manufactured: Option<AlignedVibration>,
    /// The bodies' shapes, kept for GMM (`solver.method = "gmm"`: a cloud
    /// node's distance from the body is measured to them); empty otherwise.
    pub outline: BodyOutline,
}

impl Model {
    /// Builds grid and particles. Fails (with the key to fix) on bodies that
    /// yield no particles, bodies outside an explicit grid and constraints
    /// that match no node.
    pub fn new(scene: &Scene) -> Result<Model, SceneError> {
        let f = &scene.file;
        // The materials' own keys (the registry checks them, naming each).
        let materials: Vec<Material> = material::check(f)?;
        let h = f.grid.h;
        let bbox = seed::bodies_bbox(scene);
        let anchor = f.grid.origin.unwrap_or([bbox[0], bbox[1]]);
        let ppc = scene.bodies().next().map(|(_, b)| b.ppc).unwrap_or(2);
        let shape = Shape::new(scene.solver(), h, ppc, f.grid.perturb);
        // The extent first: it refuses an unaddressable grid before seeding.
        let GridExtent { lo, nx, ny } = grid_extent(scene, &shape)?;
        let seeds = seed::seed_particles(scene, anchor, h);

        let body_names: Vec<String> = scene.bodies().map(|(n, _)| n.clone()).collect();
        check_not_empty(&seeds, &body_names, h)?;

        let grid = Grid::regular(h, lo, nx, ny).perturbed(f.grid.perturb, f.grid.seed);

        check_inside(&grid, &seeds, &body_names, shape.edge_margin(h))?;

        let body_material: Vec<u32> = scene
            .bodies()
            .map(|(_, b)| scene.material_index(&b.material) as u32)
            .collect();
        let velocities: Vec<[f64; 2]> = scene.bodies().map(|(_, b)| b.velocity).collect();
        let integrator = match f.solver.integrator {
            IntegratorKind::Fe => Integrator::Fe,
            IntegratorKind::Npc => Integrator::Npc {
                gamma: f.solver.npc_gamma,
                position: f.solver.npc_position,
            },
            IntegratorKind::Musl => Integrator::Musl,
            IntegratorKind::Implicit => Integrator::Implicit(ImplicitSettings {
                beta: f.solver.newmark_beta,
                gamma: f.solver.newmark_gamma,
                static_analysis: f.solver.static_analysis,
                load_steps: f.solver.load_steps,
                tol: f.solver.newton_tol,
                max_iter: f.solver.newton_max_iter,
                reuse_jacobian: f.solver.newton_jacobian == crate::scene::NewtonJacobian::Reuse,
                max_cuts: f.solver.newton_max_cuts,
                lumped_mass: f.solver.implicit_mass == ImplicitMass::Lumped,
                consistent_start: f.solver.implicit_start == ImplicitStart::Consistent,
                gmm: (f.solver.method == SolverMethod::Gmm).then_some(GmmSettings {
                    basis: f.solver.gmm_basis,
                    gamma: f.solver.lme_gamma,
                    search_radius: f.solver.gmm_search_radius,
                    dilation: f.solver.gmm_dilation,
                }),
            }),
        };
        let mut particles = Particles::from_seeds(
            &seeds,
            |b| materials[body_material[b as usize] as usize].density(),
            |b| velocities[b as usize],
            matches!(integrator, Integrator::Npc { .. } | Integrator::Implicit(_)),
            matches!(shape, Shape::Lme(_)),
            materials.iter().any(Material::needs_deformation_gradient),
            materials.iter().any(Material::needs_plastic_state),
        );
        // Each model's initial state (zero stress and state unless the
        // model starts elsewhere, as Cam-clay at p′0 on its unloading line).
        for i in 0..particles.len() {
            let m = &materials[body_material[particles.body[i] as usize] as usize];
            let (s, q) = m.initial_state();
            particles.stress[i] = s;
            if let Some(p) = particles.plastic.get_mut(i) {
                *p = q;
            }
        }
        let pore = pore::Pore::from_scene(scene, &grid)?;
        if let Some(pore) = &pore {
            let saturated = |i: usize| {
                let b = particles.body[i] as usize;
                pore.particle_fluid(body_material[b] as usize, b, particles.x0[i][1])
                    .is_some()
            };
            pore.check_reached(&grid, &particles.x, saturated)?;
            particles.pore_pressure = vec![0.0; particles.len()];
        }
        geostatic_start(
            scene,
            &materials,
            &body_material,
            pore.as_ref(),
            &mut particles,
        )?;

        let mut constraints = build_constraints(scene, &grid)?;
        let regions: Vec<(&[u32], u8)> = constraints
            .groups
            .iter()
            .map(|g| (&g.nodes[..], g.fix))
            .collect();
        // GMM's node cloud ends at the body's cells, so its constraints
        // select the body's own nodes on the region's edge: no points (and
        // their weights, over grid nodes, would not index the cloud).
        if scene.file.solver.method != SolverMethod::Gmm {
            let placed = constraint_points::place(scene, &grid, &shape, &particles, &regions)?;
            constraints.hold_at(placed);
        }
        moving_points(scene, &grid, &constraints)?;
        let mut walls = Walls::new(scene, &grid)?;
        let p_wave = materials
            .iter()
            .map(|m| {
                let (l, mu) = m.lame_shear();
                l + 2.0 * mu
            })
            .fold(0.0, f64::max);
        walls.set_contact(p_wave, grid.h, &particles);
        check_not_behind_walls(&walls, &seeds, &body_names)?;
        let gravity = f.gravity.as_ref().map(|g| Gravity {
            g: g.g,
            ramp: g.ramp,
            period: g.ramp_period.unwrap_or(0.0),
        });
        // A manufactured solution sets each particle's initial velocity.
        let manufactured = AlignedVibration::from_scene(scene);
        if let Some(m) = &manufactured {
            for i in 0..particles.len() {
                particles.v[i] = m.velocity(particles.x0[i], 0.0);
            }
        }
        let probes = build_probes(scene, &particles)?;
        let external = ExternalForces::from_scene(scene, &particles)?;

        let mut model = Model {
            grid,
            shape,
            particles,
            materials,
            body_material,
            body_names,
            constraints,
            walls,
            contact: Contacts::from_scene(scene),
            gravity,
            external,
            integrator,
            cfl: f.solver.cfl,
            t_end: f.solver.t_end,
            fixed_dt: f.solver.dt,
            mls: f.solver.mls,
            mls_support: f.solver.mls_support,
            mls_scope: f.solver.mls_scope,
            pic_fraction: f.solver.pic_fraction.unwrap_or(0.0),
            local_damping: f.solver.local_damping,
            cell_average_volumetric: f.solver.volumetric_strain
                == crate::scene::VolumetricStrain::CellAverage,
            pore,
            probes,
            manufactured,
            outline: if f.solver.method == SolverMethod::Gmm {
                BodyOutline {
                    rects: f.bodies.values().flat_map(|b| b.rects.clone()).collect(),
                    disks: f.bodies.values().flat_map(|b| b.disks.clone()).collect(),
                    polygons: f.bodies.values().flat_map(|b| b.polygons.clone()).collect(),
                }
            } else {
                BodyOutline::default()
            },
        };
        // The explicit integrators' walls give a body at rest its
        // discrete reaction (the implicit one solves for it).
        if !matches!(model.integrator, Integrator::Implicit(_)) {
            model.walls.pre_fit = preload_fit::preload_fit(
                &model.shape,
                &model.grid,
                &model.particles,
                &model.walls,
                model.gravity.map_or([0.0; 2], |g| g.g),
                model.contact.is_some(),
                model.mls,
            );
        }
        Ok(model)
    }

    /// Names of the reactions a sample reports, in order: the constraints',
    /// the walls', then the contact pairs' (the force on the pair's first
    /// body).
    pub fn reaction_names(&self) -> Vec<String> {
        self.constraints
            .groups
            .iter()
            .map(|g| g.name.clone())
            .chain(self.walls.list.iter().map(|w| w.name.clone()))
            .chain(
                self.contact
                    .iter()
                    .flat_map(|c| c.pairs.iter().map(|p| p.name.clone())),
            )
            .collect()
    }

    /// Copies of the grid's nodal fields (1 without contact pairs).
    pub fn n_fields(&self) -> usize {
        self.contact.as_ref().map_or(1, |c| c.n_fields)
    }

    /// Material of particle `p`.
    #[inline]
    pub fn material_of(&self, p: usize) -> &Material {
        &self.materials[self.material_index_of(p)]
    }

    /// The index in `materials` of particle p's material.
    pub fn material_index_of(&self, p: usize) -> usize {
        self.body_material[self.particles.body[p] as usize] as usize
    }
}

/// Where the grid lies: its lower-left node and node counts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridExtent {
    /// Lower-left node on the unperturbed lattice (m).
    pub lo: [f64; 2],
    pub nx: usize,
    pub ny: usize,
}

/// Most nodes a grid may have: node indices are u32 on both backends, and
/// the GPU keeps a sign bit free.
pub const MAX_NODES: u64 = u32::MAX as u64 / 2;

/// The grid extent rule, without seeding: the bodies' bounding box plus
/// `grid.margin` plus the cells `shape` reaches, stopped at walls, snapped
/// outward to the lattice through `grid.origin` (or `grid.min`/`grid.max`
/// when given). Counts are formed in f64 and refused above `MAX_NODES`
/// before any integer conversion, so an absurd h costs nothing.
pub fn grid_extent(scene: &Scene, shape: &Shape) -> Result<GridExtent, SceneError> {
    let f = &scene.file;
    let h = f.grid.h;
    let bbox = seed::bodies_bbox(scene);
    let anchor = f.grid.origin.unwrap_or([bbox[0], bbox[1]]);
    // Grid extent on the lattice through `anchor`.
    let snap = |v: f64, a: f64, up: bool| {
        let q = (v - a) / h;
        let q = if (q - q.round()).abs() < 1e-9 {
            q.round()
        } else {
            q
        };
        a + h * if up { q.ceil() } else { q.floor() }
    };
    let (lo, hi) = match (f.grid.min, f.grid.max) {
        (Some(lo), Some(hi)) => (lo, hi),
        _ => {
            let pad = scene.margin + shape.reach_cells() as f64 * h;
            let mut lo = [bbox[0] - pad, bbox[1] - pad];
            let mut hi = [bbox[2] + pad, bbox[3] + pad];
            // A wall stops the grid: nothing moves into it, and nodes
            // inside it would only pin the body over the support width.
            let ghost = shape.wall_ghost_cells() as f64 * h;
            for (axis, upper, at) in walls(scene, bbox) {
                if upper {
                    hi[axis] = hi[axis].min(at + ghost);
                } else {
                    lo[axis] = lo[axis].max(at - ghost);
                }
            }
            (lo, hi)
        }
    };
    let lo = [snap(lo[0], anchor[0], false), snap(lo[1], anchor[1], false)];
    let hi = [snap(hi[0], anchor[0], true), snap(hi[1], anchor[1], true)];
    let fx = ((hi[0] - lo[0]) / h).round() + 1.0;
    let fy = ((hi[1] - lo[1]) / h).round() + 1.0;
    // NaN counts (never from a validated scene) are refused too.
    if fx * fy > MAX_NODES as f64 || (fx * fy).is_nan() {
        let (key, why) = if f.grid.min.is_some() {
            ("grid.h` / `grid.min` / `grid.max", String::new())
        } else if scene.margin > 0.0 {
            (
                "grid.h` / `grid.margin",
                format!(
                    " (the grid spans the bodies plus a margin of {:e} m{})",
                    scene.margin,
                    if f.grid.margin.is_none() {
                        ", the fastest body's speed × solver.t_end"
                    } else {
                        ""
                    }
                ),
            )
        } else {
            ("grid.h", String::new())
        };
        return Err(SceneError::invalid(
            key,
            format!(
                "gives {fx:.3e} x {fy:.3e} = {:.3e} nodes{why}, more than 2^31 (node indices are \
                 32-bit): use a larger h or a smaller grid",
                fx * fy
            ),
        ));
    }
    let (nx, ny) = (fx as usize, fy as usize);
    if let Shape::Bspline(b) = shape {
        if nx < b.degree + 2 || ny < b.degree + 2 {
            return Err(SceneError::invalid(
                "grid.h",
                format!(
                    "gives {nx} x {ny} nodes; degree-{} B-splines need at least {} per direction",
                    b.degree,
                    b.degree + 2
                ),
            ));
        }
    }
    if nx < 2 || ny < 2 {
        return Err(SceneError::invalid(
            "grid.max",
            "the grid must span at least one cell",
        ));
    }
    // The B-spline paper's knots on the grid lines: n_c + p bases over n_c
    // cells, whose Greville points lie e = (p − 1)/2 cells out from the
    // lines' lattice (`model::shape::bspline`).
    if let Shape::Bspline(b) = shape {
        let e = b.end() * h;
        let extra = b.extra_nodes();
        return Ok(GridExtent {
            lo: [lo[0] - e, lo[1] - e],
            nx: nx + extra,
            ny: ny + extra,
        });
    }
    Ok(GridExtent { lo, nx, ny })
}

/// Every body holds at least one particle.
fn check_not_empty(seeds: &[seed::Seed], body_names: &[String], h: f64) -> Result<(), SceneError> {
    for (bi, name) in body_names.iter().enumerate() {
        if !seeds.iter().any(|s| s.body == bi as u32) {
            return Err(SceneError::invalid(
                format!("bodies.{name}"),
                format!(
                    "is empty: its shapes hold no particle point at h = {h} (shapes smaller than a cell?)"
                ),
            ));
        }
    }
    Ok(())
}

/// No body lies wholly behind a wall (on the side its normal points
/// away from): the wall would hold every node the body maps to, so the
/// body could never move; almost surely a normal of the wrong sign.
fn check_not_behind_walls(
    walls: &Walls,
    seeds: &[seed::Seed],
    body_names: &[String],
) -> Result<(), SceneError> {
    for w in &walls.list {
        let behind = |x: [f64; 2]| {
            (x[0] - w.point[0]) * w.normal[0] + (x[1] - w.point[1]) * w.normal[1] < 0.0
        };
        for (b, name) in body_names.iter().enumerate() {
            let mut of_body = seeds.iter().filter(|s| s.body as usize == b).peekable();
            if of_body.peek().is_some() && of_body.all(|s| behind(s.x)) {
                return Err(SceneError::invalid(
                    format!("walls.{}", w.name),
                    format!(
                        "body `{name}` lies wholly behind the wall (its normal {:?} points away \
                         from the body): the normal points into the material's side; flip it, \
                         or move the wall",
                        w.normal
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Every seeded particle lies inside the grid, `margin` (m) from its edge.
fn check_inside(
    grid: &Grid,
    seeds: &[seed::Seed],
    body_names: &[String],
    margin: f64,
) -> Result<(), SceneError> {
    if let Some(s) = seeds.iter().find(|s| !grid.contains(s.x, margin)) {
        return Err(SceneError::invalid(
            format!("bodies.{}", body_names[s.body as usize]),
            format!(
                "has a particle at ({:.6}, {:.6}) outside the grid ({:.6}, {:.6}) to ({:.6}, {:.6}){}: \
                 enlarge grid.min/grid.max or drop them to derive the extent",
                s.x[0],
                s.x[1],
                grid.min[0],
                grid.min[1],
                grid.max()[0],
                grid.max()[1],
                if margin > 0.0 {
                    format!(" or within {margin:.6} m of its edge")
                } else {
                    String::new()
                }
            ),
        ));
    }
    Ok(())
}

/// Probes on the particle nearest to each requested point; a point more
/// than a cell from every particle is refused.
fn build_probes(scene: &Scene, particles: &Particles) -> Result<Vec<Probe>, SceneError> {
    let h = scene.file.grid.h;
    scene
        .file
        .output
        .probes
        .iter()
        .map(|(name, &point)| {
            let particle = particles.nearest(point);
            let x = particles.x[particle];
            let d = (x[0] - point[0]).hypot(x[1] - point[1]);
            // A probe off the body would silently track some other point.
            if d > h {
                return Err(SceneError::invalid(
                    format!("output.probes.{name}"),
                    format!(
                        "is {d:.4e} m from the nearest particle, more than one cell (h = {h} m): \
                         put it on a body"
                    ),
                ));
            }
            Ok(Probe {
                name: name.clone(),
                point,
                particle,
            })
        })
        .collect()
}

/// Constraints that are walls: a half-plane region beyond the bodies
/// (e.g. `min = [L, -inf], max = [inf, inf]`) fixing its normal direction.
/// Yields (axis, on the upper side, position of the wall).
fn walls(scene: &Scene, bbox: [f64; 4]) -> Vec<(usize, bool, f64)> {
    let mut out = Vec::new();
    for c in scene.file.constraints.values() {
        let fixes = |axis: usize| match c.fix {
            Fix::X => axis == 0,
            Fix::Y => axis == 1,
            Fix::Xy => true,
        };
        for axis in 0..2 {
            let other = 1 - axis;
            let spans_other = c.min[other] == f64::NEG_INFINITY && c.max[other] == f64::INFINITY;
            if !spans_other || !fixes(axis) {
                continue;
            }
            let tol = 1e-9 * scene.file.grid.h;
            if c.max[axis] == f64::INFINITY
                && c.min[axis].is_finite()
                && c.min[axis] >= bbox[axis + 2] - tol
            {
                out.push((axis, true, c.min[axis]));
            }
            if c.min[axis] == f64::NEG_INFINITY
                && c.max[axis].is_finite()
                && c.max[axis] <= bbox[axis] + tol
            {
                out.push((axis, false, c.max[axis]));
            }
        }
    }
    out
}

fn build_constraints(scene: &Scene, grid: &Grid) -> Result<Constraints, SceneError> {
    let mut c = Constraints {
        fix: vec![0; grid.n_nodes()],
        groups: Vec::new(),
        points: Vec::new(),
        freed: Vec::new(),
        platens: Vec::new(),
    };
    for (name, spec) in &scene.file.constraints {
        let bits = match spec.fix {
            Fix::X => FIX_X,
            Fix::Y => FIX_Y,
            Fix::Xy => FIX_X | FIX_Y,
        };
        let mut nodes = Vec::new();
        let mut cells = [usize::MAX, 0, usize::MAX, 0];
        for (i, j) in grid.region(spec.min, spec.max) {
            let n = grid.index(i, j);
            c.fix[n] |= bits;
            nodes.push(n as u32);
            cells = [
                cells[0].min(i),
                cells[1].max(i),
                cells[2].min(j),
                cells[3].max(j),
            ];
        }
        if nodes.is_empty() {
            return Err(SceneError::invalid(
                format!("constraints.{name}"),
                format!(
                    "matches no node: the grid spans ({:.6}, {:.6}) to ({:.6}, {:.6}) with spacing {}",
                    grid.min[0],
                    grid.min[1],
                    grid.max()[0],
                    grid.max()[1],
                    grid.h
                ),
            ));
        }
        c.groups.push(ConstraintGroup {
            name: name.clone(),
            nodes,
            fix: bits,
            velocity: spec.velocity,
            ramp_time: spec.ramp_time,
            cells,
            shifted: [0, 0],
        });
    }
    for (name, spec) in &scene.file.platens {
        let axis = spec.axis.index();
        let bit = if axis == 0 { FIX_X } else { FIX_Y };
        let nodes: Vec<u32> = grid
            .region(spec.min, spec.max)
            .map(|(i, j)| grid.index(i, j) as u32)
            .collect();
        if nodes.is_empty() {
            return Err(SceneError::invalid(
                format!("platens.{name}"),
                format!(
                    "matches no node: the grid spans ({:.6}, {:.6}) to ({:.6}, {:.6}) with spacing {}",
                    grid.min[0],
                    grid.min[1],
                    grid.max()[0],
                    grid.max()[1],
                    grid.h
                ),
            ));
        }
        if let Some(&n) = nodes.iter().find(|&&n| c.fix[n as usize] & bit != 0) {
            return Err(SceneError::invalid(
                format!("platens.{name}"),
                format!(
                    "holds node {n}, which a [constraints] region fixes along the platen's axis: \
                     a platen moves, a fixed node does not (shrink one of the two regions)"
                ),
            ));
        }
        c.platens.push(Platen {
            name: name.clone(),
            nodes,
            axis,
            force: spec.force,
            ramp_time: spec.ramp_time,
        });
    }
    Ok(c)
}

/// A moving group's region moves with its velocity by whole node
/// spacings (`Constraints::move_to`); one that holds the body at points
/// on its edge (`constraint_points`: weights fixed at t = 0) or one on
/// GMM's node cloud (its groups are fixed when the cloud is built) cannot
/// move, so it may travel less than half a spacing by `t_end`, and is
/// refused otherwise.
fn moving_points(scene: &Scene, grid: &Grid, c: &Constraints) -> Result<(), SceneError> {
    let t_end = scene.file.solver.t_end;
    let gmm = scene.file.solver.method == SolverMethod::Gmm;
    for (k, g) in c.groups.iter().enumerate() {
        let points = c.freed.get(k).is_some_and(|f| !f.is_empty());
        if !g.moves() || !(points || gmm) || g.shift(t_end, grid.h) == [0, 0] {
            continue;
        }
        let d = g.travel(t_end);
        let why = if gmm {
            "on GMM's node cloud (solver.method = \"gmm\") a constraint's nodes are chosen once, at t = 0"
        } else {
            "its region holds the body at points on its edge, placed once at t = 0 (an edge inside \
             the grid beside the body, with this shape function; linear shapes on a node line do \
             not need them)"
        };
        return Err(SceneError::invalid(
            format!("constraints.{}.velocity", g.name),
            format!(
                "moves the region by ({:.6}, {:.6}) m by t_end = {t_end} s, half a node spacing \
                 ({}) or more, but {why}: shorten the run or lower the velocity",
                d[0],
                d[1],
                0.5 * grid.h
            ),
        ));
    }
    Ok(())
}

/// Bodies with `initial_stress = "geostatic"`: σ_v from the overburden
/// above each particle, σ_h = σ_zz = k0 σ_v (`geostatic`); with a
/// `water_table`, the saturated particles below it start at the
/// hydrostatic p = ρ_w g (table − y) and the effective stress σ'_v = σ_v +
/// p, σ'_h = σ'_zz = k0 σ'_v. Refused, naming the key, for a material that
/// keeps F or starts at a state of its own.
fn geostatic_start(
    scene: &Scene,
    materials: &[Material],
    body_material: &[u32],
    pore: Option<&pore::Pore>,
    particles: &mut Particles,
) -> Result<(), SceneError> {
    use crate::scene::InitialStress;
    let bodies: Vec<(&String, &crate::scene::BodySpec)> = scene.bodies().collect();
    if bodies
        .iter()
        .all(|(_, b)| b.initial_stress != InitialStress::Geostatic)
    {
        return Ok(());
    }
    let density: Vec<f64> = body_material
        .iter()
        .map(|&m| materials[m as usize].density())
        .collect();
    let mut k0 = Vec::with_capacity(bodies.len());
    for (bi, (name, b)) in bodies.iter().enumerate() {
        let m = &materials[body_material[bi] as usize];
        if b.initial_stress == InitialStress::Geostatic {
            let own_start = m.initial_state() != ([0.0; 3], [0.0; 4]);
            if m.needs_deformation_gradient() || own_start {
                let stress_only = material::names_where(|e| {
                    e.state != material::StateKind::DefGrad && !e.own_start
                });
                return Err(SceneError::invalid(
                    format!("bodies.{name}.initial_stress"),
                    format!(
                        "= \"geostatic\" needs a material whose state is its stress ({}); model = \"{}\" {}",
                        stress_only.join(", "),
                        m.entry().name,
                        if own_start {
                            "starts at a stress of its own"
                        } else {
                            "keeps a deformation gradient"
                        }
                    ),
                ));
            }
        }
        let spec = &scene.file.materials[&b.material];
        k0.push(b.k0.unwrap_or_else(|| geostatic::default_k0(spec)));
    }
    let g = scene.file.gravity.as_ref().map_or(0.0, |g| -g.g[1]);
    for i in 0..particles.len() {
        let b = particles.body[i] as usize;
        if bodies[b].1.initial_stress != InitialStress::Geostatic {
            continue;
        }
        let mut sv = -g * geostatic::overburden(scene, &density, particles.x[i]);
        let y = particles.x[i][1];
        let fluid = pore.and_then(|pore| {
            let table = pore.tables[b]?;
            Some((pore.particle_fluid(body_material[b] as usize, b, y)?, table))
        });
        if let Some((f, table)) = fluid {
            let p = f.rho_w * g * (table - y);
            particles.pore_pressure[i] = p;
            sv += p;
        }
        particles.stress[i] = [k0[b] * sv, sv, 0.0];
        if let Some(q) = particles.plastic.get_mut(i) {
            q[material::plastic::SZZ] = k0[b] * sv;
        }
    }
    Ok(())
}
