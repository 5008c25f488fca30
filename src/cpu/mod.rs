//! The CPU reference path: f64, rayon across all cores, one file per stage
//! mirroring the WGSL twin of the same name. Buffers are allocated once in
//! `CpuBackend::new`; a step allocates nothing.

pub mod cfl;
pub mod clear_grid;
pub mod energy;
pub mod forces;
pub mod g2p;
pub mod grid_update;
pub mod p2g;
pub mod scatter;
pub mod shape_eval;
pub mod stress;

use crate::backend::{Backend, ProbeState, Sample};
use crate::fault::Fault;
use crate::model::{Integrator, Model, Particles};
use crate::solver::{STEP, Stage};
use scatter::Scatter;

/// N and ∇N of every particle for the current step: `stride` slots per
/// particle, `count[p]` of them used.
#[derive(Debug, Clone)]
pub struct ShapeCache {
    pub stride: usize,
    pub count: Vec<u16>,
    pub nodes: Vec<u32>,
    /// [N, ∂N/∂x, ∂N/∂y] per slot.
    pub w: Vec<[f64; 3]>,
}

impl ShapeCache {
    pub fn new(particles: usize, stride: usize) -> Self {
        ShapeCache {
            stride,
            count: vec![0; particles],
            nodes: vec![0; particles * stride],
            w: vec![[0.0; 3]; particles * stride],
        }
    }

    /// The nodes and weights of particle `p`.
    #[inline]
    pub fn particle(&self, p: usize) -> (&[u32], &[[f64; 3]]) {
        let (o, n) = (p * self.stride, self.count[p] as usize);
        (&self.nodes[o..o + n], &self.w[o..o + n])
    }

    /// Bytes held per particle.
    pub fn bytes_per_particle(&self) -> usize {
        2 + self.stride * (4 + 24)
    }
}

/// Runs a `Model` on the CPU.
pub struct CpuBackend {
    pub model: Model,
    pub cache: ShapeCache,
    /// Per node: [mass, momentum or velocity x, y].
    pub mv: Vec<[f64; 3]>,
    /// Per node: force.
    pub force: Vec<[f64; 2]>,
    /// Per constraint group: reaction (N per unit thickness).
    pub reactions: Vec<[f64; 2]>,
    p2g_scatter: Scatter<3>,
    force_scatter: Scatter<2>,
    mass_eps: f64,
    t: f64,
    steps: u64,
    /// Time step of the step in progress (s).
    dt: f64,
}

impl CpuBackend {
    pub fn new(model: Model) -> Self {
        let n = model.particles.len();
        let nodes = model.grid.n_nodes();
        let min_mass = model
            .particles
            .mass
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min);
        CpuBackend {
            cache: ShapeCache::new(n, model.shape.max_nodes()),
            mv: vec![[0.0; 3]; nodes],
            force: vec![[0.0; 2]; nodes],
            reactions: vec![[0.0; 2]; model.constraints.groups.len()],
            p2g_scatter: Scatter::default(),
            force_scatter: Scatter::default(),
            mass_eps: grid_update::MASS_EPS_REL * min_mass,
            t: 0.0,
            steps: 0,
            dt: 0.0,
            model,
        }
    }

    /// Time step the next `step` would take (s).
    pub fn next_dt(&self) -> f64 {
        let m = &self.model;
        let p = &m.particles;
        let c = cfl::max_speed(&p.v, &p.rho, &p.body, &m.materials, &m.body_material);
        (m.cfl * m.grid.min_spacing() / c).min(m.t_end - self.t)
    }

    /// One step: the stages of `solver::STEP` in order.
    pub fn step(&mut self) -> Result<(), Fault> {
        for stage in STEP {
            self.run_stage(*stage)?;
        }
        self.t += self.dt;
        self.steps += 1;
        Ok(())
    }

    /// Runs one stage of the step (public so tests can compare stages one by one).
    pub fn run_stage(&mut self, stage: Stage) -> Result<(), Fault> {
        let m = &mut self.model;
        let p = &mut m.particles;
        let (gamma, npc) = match m.integrator {
            Integrator::Fe => (1.0, false),
            Integrator::Npc { gamma, .. } => (gamma, true),
        };
        match stage {
            Stage::Cfl => {
                let c = cfl::max_speed(&p.v, &p.rho, &p.body, &m.materials, &m.body_material);
                self.dt = (m.cfl * m.grid.min_spacing() / c).min(m.t_end - self.t);
            }
            Stage::ClearGrid => clear_grid::clear_grid(&mut self.mv, &mut self.force),
            Stage::ShapeEval => {
                shape_eval::shape_eval(&m.shape, &m.grid, &p.x, &mut p.lambda, &mut self.cache)?
            }
            Stage::P2g => {
                let a_factor = if npc { (1.0 - gamma) * self.dt } else { 0.0 };
                p2g::p2g(
                    &self.cache,
                    &p.mass,
                    &p.v,
                    &p.a,
                    a_factor,
                    &mut self.mv,
                    &mut self.p2g_scatter,
                );
            }
            Stage::GridPredict => {
                grid_update::predict(&mut self.mv, &m.constraints.fix, self.mass_eps)
            }
            Stage::Stress => stress::stress(
                &self.cache,
                &self.mv,
                self.dt,
                &p.body,
                &m.materials,
                &m.body_material,
                &mut p.stress,
                &mut p.rho,
            )?,
            Stage::Forces => {
                let g = m.gravity.map_or([0.0; 2], |g| g.at(self.t));
                forces::forces(
                    &self.cache,
                    &p.stress,
                    &p.mass,
                    &p.rho,
                    g,
                    &mut self.force,
                    &mut self.force_scatter,
                );
            }
            Stage::GridCorrect => grid_update::correct(
                &mut self.mv,
                &mut self.force,
                &m.constraints.fix,
                &m.constraints.groups,
                &mut self.reactions,
                gamma * self.dt,
                self.mass_eps,
            ),
            Stage::G2p => {
                let prm = g2p::G2pParams {
                    dt: self.dt,
                    integrator: m.integrator,
                    mass_eps: self.mass_eps,
                    edge_margin: m.shape.edge_margin(),
                };
                g2p::g2p(
                    &self.cache,
                    &self.mv,
                    &self.force,
                    &m.grid,
                    prm,
                    &mut p.x,
                    &mut p.v,
                    &mut p.a,
                )?;
            }
        }
        Ok(())
    }
}

impl Backend for CpuBackend {
    fn name(&self) -> String {
        format!("cpu (f64, {} threads)", rayon::current_num_threads())
    }

    fn time(&self) -> f64 {
        self.t
    }

    fn steps(&self) -> u64 {
        self.steps
    }

    fn advance(&mut self, t_stop: f64) -> Result<(), Fault> {
        while self.t < t_stop && self.t < self.model.t_end {
            self.step()?;
        }
        Ok(())
    }

    fn advance_steps(&mut self, n: u64) -> Result<(), Fault> {
        for _ in 0..n {
            if self.t >= self.model.t_end {
                break;
            }
            self.step()?;
        }
        Ok(())
    }

    fn sample(&mut self) -> Sample {
        let p = &self.model.particles;
        Sample {
            t: self.t,
            probes: self
                .model
                .probes
                .iter()
                .map(|pr| ProbeState {
                    x: p.x[pr.particle],
                    v: p.v[pr.particle],
                    stress: p.stress[pr.particle],
                })
                .collect(),
            energy: energy::energy(&self.model),
            reactions: self.reactions.clone(),
        }
    }

    fn particles(&mut self) -> &Particles {
        &self.model.particles
    }

    fn model(&self) -> &Model {
        &self.model
    }

    fn bytes_per_particle(&self) -> f64 {
        let n = self.model.particles.len().max(1) as f64;
        let per_particle = 8.0 * (2.0 + 2.0 + 1.0 + 1.0 + 3.0 + 2.0)
            + 4.0
            + if self.model.particles.a.is_empty() {
                0.0
            } else {
                16.0
            }
            + if self.model.particles.lambda.is_empty() {
                0.0
            } else {
                16.0
            }
            + self.cache.bytes_per_particle() as f64;
        per_particle + (self.mv.len() as f64 * 40.0) / n
    }
}
