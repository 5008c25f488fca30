//! The GPU path: every stage of the step plan (`crate::step`) as a wgpu compute pass over
//! f32 buffers, many steps per submission, with Δt computed on the device
//! and the state read back only at sample and output times.
//!
//! `context` opens an adapter, `buffers` holds one buffer per field,
//! `pipelines` builds the scene's passes from `shaders/` (expanded by
//! `preprocess`), `layout` defines the structs shared with WGSL.

pub mod buffers;
pub mod constraint_points;
pub mod context;
pub mod layout;
pub mod options;
pub mod pipelines;
pub mod preprocess;

use crate::backend::{Backend, Halt, ProbeState, Sample, State, stop_requested};
use crate::error::{Error, Result};
use crate::model::energy::Energy;
use crate::model::fault::{Fault, FaultKind};
use crate::model::shape::{Shape, ShapeFault};
use crate::model::{Integrator, Model, Particles};
use buffers::{Buf, Buffers};
use context::{AtomicMode, GpuContext};
use layout::*;
pub use options::GpuOptions;
use pipelines::{Pass, Pipelines};
use std::sync::atomic::AtomicBool;

/// Most steps recorded into one submission.
const MAX_BATCH: u64 = 512;
/// LME Newton tolerance on the GPU: |r| ≤ 2e-6 h. f32 sums of ~20 terms of
/// size ~h carry a few 1e-7 h of round-off. Looser stops cost accuracy: at
/// 1e-5 h the gradient-consistency error Σ∇N = −J⁻¹r (~1e-4/h) turns a
/// settling body's motion into spurious strain, and the elastic block
/// settled 3e-4 (relative) off the CPU result; at 2e-6 h it is within 1e-5.
/// Checked to converge in ≤ 8 iterations for γ 0.8–10 on regular and
/// perturbed grids of 1M particles (the CPU's f64 Newton uses 1e-10 h).
pub const LME_TOL_F32: f64 = 2e-6;

/// Runs a `Model` on a GPU adapter.
pub struct GpuBackend {
    pub ctx: GpuContext,
    model: Model,
    params: Params,
    buffers: Buffers,
    pipelines: Pipelines,
    /// Device state at the last read-back.
    sim: Sim,
    /// Host particles match the device.
    fresh: bool,
    /// First Δt, computed on the host, to size the first batch (s).
    dt_hint: f64,
    /// The last stop time `advance` reached (s): the device's two-float time
    /// can sit one f32 rounding below it.
    t_floor: f64,
}

impl GpuBackend {
    /// Uploads `model` and builds its pipelines.
    pub fn new(ctx: GpuContext, model: Model) -> Result<GpuBackend> {
        GpuBackend::with_options(ctx, model, GpuOptions::default())
    }

    pub fn with_options(ctx: GpuContext, model: Model, opts: GpuOptions) -> Result<GpuBackend> {
        if matches!(model.integrator, Integrator::Implicit(_)) {
            return Err(crate::error::SceneError::invalid(
                "solver.integrator",
                "= \"implicit\" runs on the CPU path only (--backend cpu or auto); the GPU \
                 path steps the explicit integrators",
            )
            .into());
        }
        if model.pore.is_some() {
            return Err(crate::error::SceneError::invalid(
                "materials",
                "a saturated material (`permeability`) runs on the CPU path only for now \
                 (--backend cpu or auto)",
            )
            .into());
        }
        if let Some(p) = model.constraints.platens.first() {
            return Err(crate::error::SceneError::invalid(
                format!("platens.{}", p.name),
                "a loaded platen runs on the CPU path only for now (--backend cpu or auto)",
            )
            .into());
        }
        // The points' tables mark freed nodes with a bit per group.
        if !model.constraints.points.is_empty() && model.constraints.groups.len() > 32 {
            return Err(crate::error::SceneError::invalid(
                "constraints",
                format!(
                    "{} groups with constraint points: the GPU path marks the nodes they free \
                     with a bit per group, 32 at most (use --backend cpu, or fewer groups)",
                    model.constraints.groups.len()
                ),
            )
            .into());
        }
        let params = params(&model);
        let buffers = Buffers::new(&ctx, &model, &params, &opts)?;
        let pipelines = Pipelines::new(&ctx, &model, &buffers, &opts)?;
        let dt_hint = crate::model::time_step::time_step(&model, 0.0).0;
        let mut b = GpuBackend {
            ctx,
            model,
            params,
            buffers,
            pipelines,
            sim: buffers::initial_sim(),
            fresh: true,
            dt_hint,
            t_floor: 0.0,
        };
        b.sim = b.read_sim()?;
        Ok(b)
    }

    pub fn atomics(&self) -> AtomicMode {
        self.ctx.atomics
    }

    /// Records `n` whole steps into one submission.
    fn submit_steps(&self, n: u64) {
        let mut enc = self.ctx.device.create_command_encoder(&Default::default());
        {
            let mut cpass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("steps"),
                timestamp_writes: None,
            });
            for _ in 0..n {
                self.pipelines.encode_step(&mut cpass);
            }
        }
        self.ctx.queue.submit([enc.finish()]);
    }

    /// How this scene's stages map onto passes.
    pub fn plan(&self) -> &crate::step::StepPlan {
        &self.pipelines.plan
    }

    /// The GPU's passes of one stage (`StepPlan::gpu_passes_for` for this scene).
    pub fn stage_passes(&self, stage: crate::step::Stage) -> Vec<Pass> {
        self.pipelines.plan.gpu_passes_for(stage)
    }

    /// Runs one pass on its own (per-stage parity tests).
    pub fn run_pass(&mut self, pass: Pass) {
        self.fresh = false;
        let mut enc = self.ctx.device.create_command_encoder(&Default::default());
        {
            let mut cpass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("pass"),
                timestamp_writes: None,
            });
            self.pipelines.dispatch(&mut cpass, pass);
        }
        self.ctx.queue.submit([enc.finish()]);
    }

    /// Copies whole buffers to the host (one staging buffer, one wait).
    pub fn read(&self, bufs: &[Buf]) -> Result<ReadBack> {
        let sizes: Vec<u64> = bufs.iter().map(|b| self.buffers.get(*b).size()).collect();
        let total: u64 = sizes.iter().sum();
        let staging = self.ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("read-back"),
            size: total,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut enc = self.ctx.device.create_command_encoder(&Default::default());
        let mut off = 0;
        for (b, s) in bufs.iter().zip(&sizes) {
            enc.copy_buffer_to_buffer(self.buffers.get(*b), 0, &staging, off, *s);
            off += s;
        }
        self.ctx.queue.submit([enc.finish()]);
        let (tx, rx) = std::sync::mpsc::channel();
        staging.map_async(wgpu::MapMode::Read, .., move |r| {
            let _ = tx.send(r);
        });
        self.ctx
            .device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| Error::Gpu(format!("waiting for the device: {e}")))?;
        rx.recv()
            .map_err(|_| Error::Gpu("read-back callback never ran".into()))?
            .map_err(|e| Error::Gpu(format!("mapping a read-back buffer: {e}")))?;
        let view = staging
            .get_mapped_range(..)
            .map_err(|e| Error::Gpu(format!("reading a mapped buffer: {e}")))?;
        let mut out = ReadBack::default();
        let mut off = 0usize;
        for (b, s) in bufs.iter().zip(&sizes) {
            out.bytes.insert(*b, view[off..off + *s as usize].to_vec());
            off += *s as usize;
        }
        drop(view);
        staging.unmap();
        Ok(out)
    }

    /// The device's run state now.
    pub fn read_sim(&self) -> Result<Sim> {
        Ok(self.read(&[Buf::Sim])?.sim())
    }

    /// Nodal accumulators: per node [mass, vx, vy, fx, fy] (f32), every
    /// field's nodes in turn with contact pairs (as the CPU's `mv`).
    pub fn read_nodes(&self) -> Result<Vec<[f32; NODE_STRIDE]>> {
        let b = self.read(&[Buf::NodeAcc])?;
        Ok(b.f32s(Buf::NodeAcc)
            .chunks_exact(NODE_STRIDE)
            .take(self.buffers.n_nodes * self.buffers.n_fields)
            .map(|c| c.try_into().expect("chunk of NODE_STRIDE"))
            .collect())
    }

    /// Reactions per constraint group, then per wall, then per contact
    /// pair, as last computed on the device.
    pub fn read_reactions(&self) -> Result<Vec<[f64; 2]>> {
        Ok(self
            .read(&[Buf::Reactions])?
            .pairs(Buf::Reactions, self.n_reactions()))
    }

    fn n_reactions(&self) -> usize {
        self.buffers.n_groups + self.buffers.n_walls + self.buffers.n_pairs
    }

    /// Contact pairs' detection as last computed on the device: per pair
    /// and grid node (`pair · n_nodes + node`), the normal (zero where the
    /// pair is not in contact) and the gap (m; `None` where none was
    /// measured), as the CPU's `contact_detect::ContactState`. Empty without pairs.
    pub fn read_contact(&self) -> Result<Vec<([f64; 2], Option<f64>)>> {
        if self.buffers.n_pairs == 0 {
            return Ok(Vec::new());
        }
        let b = self.read(&[Buf::ContactNormal])?;
        Ok(b.f32s(Buf::ContactNormal)
            .chunks_exact(3)
            .take(self.buffers.n_pairs * self.buffers.n_nodes)
            .map(|c| {
                let gap = (c[2] < f32::MAX).then_some(c[2] as f64);
                ([c[0] as f64, c[1] as f64], gap)
            })
            .collect())
    }

    /// Sets the device's stop time (`Sim::t_stop_ticks`) and leaves the
    /// rest of `Sim` as it is.
    fn write_stop(&self, ticks: [u32; 2]) {
        self.ctx.queue.write_buffer(
            self.buffers.get(Buf::Sim),
            std::mem::offset_of!(Sim, t_stop_ticks) as u64,
            bytemuck::cast_slice(&ticks),
        );
    }

    /// Whether the device has reached `stop` as `step_begin.wgsl` decides
    /// it: its ticks plus LAST_STEP_REL of the last Δt, that product
    /// rounded to f32 and then to ticks as the shader does.
    fn stop_reached(&self, stop: [u32; 2]) -> bool {
        let clock = self.clock();
        let slack = crate::model::time_step::LAST_STEP_REL as f32 * self.sim.dt;
        let u = |t: [u32; 2]| ((t[1] as u64) << 32) | t[0] as u64;
        u(self.sim.ticks).saturating_add(u(clock.ticks(slack as f64))) >= u(stop)
    }

    /// The device's clock for this model's t_end.
    fn clock(&self) -> Clock {
        Clock::for_end(self.model.t_end)
    }

    fn write_sim(&self, sim: &Sim) {
        self.ctx
            .queue
            .write_buffer(self.buffers.get(Buf::Sim), 0, bytemuck::bytes_of(sim));
    }

    /// Replaces the device state with `state` (parity tests load the CPU
    /// path's): the particles, the nodal arrays, the time and the step's Δt.
    pub fn upload_state(&mut self, state: &State) {
        self.upload_state_at(state, 0);
    }

    /// `upload_state`, with the step counter set to `steps`.
    fn upload_state_at(&mut self, state: &State, steps: u32) {
        let p = &state.particles;
        let q = &self.ctx.queue;
        let f2 = |v: &[[f64; 2]]| {
            v.iter()
                .flat_map(|x| [x[0] as f32, x[1] as f32])
                .collect::<Vec<f32>>()
        };
        let u: Vec<[f64; 2]> = (0..p.len())
            .map(|i| [p.x[i][0] - p.x0[i][0], p.x[i][1] - p.x0[i][1]])
            .collect();
        q.write_buffer(self.buffers.get(Buf::U), 0, bytemuck::cast_slice(&f2(&u)));
        q.write_buffer(self.buffers.get(Buf::ULo), 0, &vec![0u8; 8 * p.len()]);
        q.write_buffer(self.buffers.get(Buf::V), 0, bytemuck::cast_slice(&f2(&p.v)));
        if !p.a.is_empty() {
            q.write_buffer(self.buffers.get(Buf::A), 0, bytemuck::cast_slice(&f2(&p.a)));
        }
        if !p.lambda.is_empty() {
            q.write_buffer(
                self.buffers.get(Buf::Lambda),
                0,
                bytemuck::cast_slice(&f2(&p.lambda)),
            );
        }
        if !p.f.is_empty() {
            let f: Vec<f32> = p.f.iter().flat_map(|f| f.map(|c| c as f32)).collect();
            q.write_buffer(self.buffers.get(Buf::DefGrad), 0, bytemuck::cast_slice(&f));
        }
        if !p.plastic.is_empty() {
            let pl: Vec<f32> = p.plastic.iter().flat_map(|q| q.map(|c| c as f32)).collect();
            q.write_buffer(self.buffers.get(Buf::Plastic), 0, bytemuck::cast_slice(&pl));
        }
        let rho: Vec<f32> = p.rho.iter().map(|r| *r as f32).collect();
        q.write_buffer(self.buffers.get(Buf::Rho), 0, bytemuck::cast_slice(&rho));
        let s: Vec<f32> = p.stress.iter().flat_map(|s| s.map(|c| c as f32)).collect();
        q.write_buffer(self.buffers.get(Buf::Stress), 0, bytemuck::cast_slice(&s));
        let nodes: Vec<f32> = state
            .mv
            .iter()
            .zip(&state.force)
            .flat_map(|(m, f)| {
                [
                    m[0] as f32,
                    m[1] as f32,
                    m[2] as f32,
                    f[0] as f32,
                    f[1] as f32,
                ]
            })
            .collect();
        q.write_buffer(
            self.buffers.get(Buf::NodeAcc),
            0,
            bytemuck::cast_slice(&nodes),
        );
        let clock = self.clock();
        let ticks = clock.ticks(state.t);
        let (t, t_lo) = split_f64(clock.seconds(ticks));
        let sim = Sim {
            t,
            t_lo,
            ticks,
            t_stop_ticks: clock.ticks(self.model.t_end),
            dt: state.dt as f32,
            running: 1,
            steps,
            ..buffers::initial_sim()
        };
        self.write_sim(&sim);
        self.sim = sim;
        self.t_floor = 0.0;
        self.model.particles = p.clone();
        self.fresh = false;
    }

    /// The fault the device recorded, if any.
    pub fn fault(&self) -> Option<Fault> {
        (self.sim.fault != FAULT_NONE)
            .then(|| decode_fault(&self.model, self.params.lme_max_iter, self.sim.fault))
    }

    fn t(&self) -> f64 {
        self.clock().seconds(self.sim.ticks).max(self.t_floor)
    }
}

/// The scene constants the shaders read.
pub fn params(model: &Model) -> Params {
    let g = &model.grid;
    let min_mass = model.particles.min_mass();
    let clock = Clock::for_end(model.t_end);
    let (gamma, p2g_accel) = match model.integrator {
        // `with_options` refuses implicit models before this is read.
        Integrator::Fe | Integrator::Musl | Integrator::Implicit(_) => (1.0, 0.0),
        Integrator::Npc { gamma, .. } => (gamma, 1.0 - gamma),
    };
    let gravity = model
        .gravity
        .map_or([0.0; 2], |g| [g.g[0] as f32, g.g[1] as f32]);
    let ramp_period = model.gravity.map_or(0.0, |g| match g.ramp {
        crate::scene::Ramp::None => 0.0,
        crate::scene::Ramp::Sine => g.period as f32,
    });
    let mms = model.manufactured.as_ref();
    let mls_spans = [
        crate::model::gauss::breaks(&model.shape, g.nx).len() as u32 - 1,
        crate::model::gauss::breaks(&model.shape, g.ny).len() as u32 - 1,
    ];
    let mls_break_off = match &model.shape {
        Shape::Bspline(b) => 0.5 * (b.degree as f32 - 1.0),
        _ => 0.0,
    };
    let (mut lme_beta, mut lme_r2, mut lme_tol, mut lme_reach) = (0.0, 0.0, 0.0, 0.0);
    if let Shape::Lme(l) = &model.shape {
        lme_beta = l.beta as f32;
        lme_r2 = (l.radius * l.radius) as f32;
        lme_tol = (LME_TOL_F32 * l.h) as f32;
        lme_reach = ((l.radius + l.search_extra) / l.h) as f32;
    }
    Params {
        n_particles: model.particles.len() as u32,
        n_nodes: g.n_nodes() as u32,
        nx: g.nx as u32,
        ny: g.ny as u32,
        h: g.h as f32,
        inv_h: (1.0 / g.h) as f32,
        cfl_h: (model.cfl * g.min_spacing()) as f32,
        mass_eps: (crate::model::MASS_EPS_REL * min_mass) as f32,
        t_end_ticks: clock.ticks(model.t_end),
        gravity,
        ramp_period,
        npc_gamma: gamma as f32,
        p2g_accel: p2g_accel as f32,
        edge_margin: model.shape.edge_margin(g.h) as f32,
        grid_w: ((g.nx - 1) as f64 * g.h) as f32,
        grid_hgt: ((g.ny - 1) as f64 * g.h) as f32,
        lme_beta,
        lme_r2,
        lme_tol,
        lme_reach,
        lme_side: pipelines::lme_side(model),
        lme_max_iter: crate::model::shape::lme::NEWTON_MAX_ITER,
        ugimp_lp: match &model.shape {
            Shape::Ugimp(u) => u.lp_h as f32,
            _ => 0.0,
        },
        n_groups: model.constraints.groups.len() as u32,
        n_probes: model.probes.len() as u32,
        n_materials: model.materials.len() as u32,
        fixed_dt: model.fixed_dt.map_or(0.0, |dt| dt as f32),
        mms_amp: mms.map_or(0.0, |m| m.amplitude as f32),
        mms_origin: mms.map_or([0.0; 2], |m| {
            [
                (m.origin[0] - g.min[0]) as f32,
                (m.origin[1] - g.min[1]) as f32,
            ]
        }),
        mms_k: mms.map_or(0.0, |m| (2.0 * std::f64::consts::PI / m.length) as f32),
        mms_omega: mms.map_or(0.0, |m| (m.c * std::f64::consts::PI / m.length) as f32),
        mms_lame: mms.map_or(0.0, |m| (m.material.lame / m.material.density) as f32),
        mms_shear: mms.map_or(0.0, |m| (m.material.shear / m.material.density) as f32),
        mms_c2: mms.map_or(0.0, |m| (m.c * m.c) as f32),
        mls_spans_x: mls_spans[0],
        mls_spans_y: mls_spans[1],
        mls_break_off,
        mls_weight_scale: (1.5 / model.mls_support) as f32,
        pic_fraction: model.pic_fraction as f32,
        local_damping: model.local_damping as f32,
        tick_exp: clock.exp,
        fixed_dt_ticks: model.fixed_dt.map_or([0; 2], |dt| clock.ticks(dt)),
        opaque_zero: 0,
        _pad_p3: 0,
    }
}

impl Backend for GpuBackend {
    fn name(&self) -> String {
        let atomics = match self.ctx.atomics {
            AtomicMode::Float => "float atomics",
            AtomicMode::CompareExchange => "CAS atomics",
        };
        format!("gpu: {} (f32, {atomics})", self.ctx.adapter.label())
    }

    fn time(&self) -> f64 {
        self.t()
    }

    fn steps(&self) -> u64 {
        self.sim.steps as u64
    }

    fn advance(&mut self, t_stop: f64, stop: &AtomicBool) -> std::result::Result<(), Halt> {
        let t_end = self.model.t_end;
        let clock = self.clock();
        let stop_ticks = clock.ticks(t_stop.min(t_end));
        // The device compares in ticks, a rounding of the f64 stop time.
        let target = clock.seconds(stop_ticks);
        self.write_stop(stop_ticks);
        loop {
            let t = self.t();
            if t >= target || self.stop_reached(stop_ticks) {
                // Reached as the device counts: report the stop time itself.
                self.t_floor = self.t_floor.max(t_stop.min(t_end));
                return Ok(());
            }
            if stop_requested(stop) {
                return Ok(());
            }
            let dt = if self.sim.dt > 0.0 {
                self.sim.dt as f64
            } else {
                self.dt_hint
            };
            let n = (((target - t) / dt).ceil() as u64 + 1).clamp(1, MAX_BATCH);
            let before = self.sim.steps;
            self.submit_steps(n);
            self.fresh = false;
            self.sim = self.read_sim()?;
            if let Some(f) = self.fault() {
                return Err(f.into());
            }
            if self.sim.steps == before && self.t() < target && !self.stop_reached(stop_ticks) {
                // No step ran although time remains: Δt must have become 0 or NaN.
                return Err(Fault {
                    particle: None,
                    kind: FaultKind::NonFinite { field: "time step" },
                }
                .into());
            }
        }
    }

    fn advance_steps(&mut self, n: u64) -> std::result::Result<(), Halt> {
        self.write_stop(self.clock().ticks(self.model.t_end));
        let mut left = n;
        while left > 0 {
            let k = left.min(MAX_BATCH);
            self.submit_steps(k);
            left -= k;
        }
        self.fresh = false;
        self.sim = self.read_sim()?;
        self.fault().map_or(Ok(()), |f| Err(f.into()))
    }

    fn sample(&mut self) -> Result<Sample> {
        let mut enc = self.ctx.device.create_command_encoder(&Default::default());
        enc.clear_buffer(self.buffers.get(Buf::EnergyOut), 0, None);
        {
            let mut cpass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("sample"),
                timestamp_writes: None,
            });
            self.pipelines.dispatch(&mut cpass, Pass::Probes);
            self.pipelines.dispatch(&mut cpass, Pass::Energy);
        }
        self.ctx.queue.submit([enc.finish()]);
        let b = self.read(&[Buf::ProbeOut, Buf::EnergyOut, Buf::Reactions, Buf::Sim])?;
        self.sim = b.sim();
        let pr = b.f32s(Buf::ProbeOut);
        let origin = self.model.grid.min;
        let probes = (0..self.model.probes.len())
            .map(|k| {
                let o = &pr[k * PROBE_STRIDE..];
                ProbeState {
                    x: [o[0] as f64 + origin[0], o[1] as f64 + origin[1]],
                    v: [o[2] as f64, o[3] as f64],
                    stress: [o[4] as f64, o[5] as f64, o[6] as f64],
                    // The GPU refuses saturated scenes.
                    pore_pressure: None,
                }
            })
            .collect();
        let e = b.f32s(Buf::EnergyOut);
        Ok(Sample {
            t: self.t(),
            probes,
            energy: Energy {
                kinetic: e[0] as f64,
                strain: e[1] as f64,
                gravity_work_bound: e[2] as f64,
            },
            reactions: b.pairs(Buf::Reactions, self.n_reactions()),
            newton: None,
        })
    }

    fn particles(&mut self) -> Result<&Particles> {
        if !self.fresh {
            let npc = !self.model.particles.a.is_empty();
            let lme = !self.model.particles.lambda.is_empty();
            let mut want = vec![Buf::U, Buf::ULo, Buf::V, Buf::Rho, Buf::Stress];
            if npc {
                want.push(Buf::A);
            }
            if lme {
                want.push(Buf::Lambda);
            }
            let def_grad = !self.model.particles.f.is_empty();
            if def_grad {
                want.push(Buf::DefGrad);
            }
            let plastic = !self.model.particles.plastic.is_empty();
            if plastic {
                want.push(Buf::Plastic);
            }
            let b = self.read(&want)?;
            let p = &mut self.model.particles;
            let n = p.len();
            let (u, u_lo, v) = (b.f32s(Buf::U), b.f32s(Buf::ULo), b.f32s(Buf::V));
            let (rho, s) = (b.f32s(Buf::Rho), b.f32s(Buf::Stress));
            for i in 0..n {
                // The displacement is the compensated sum u − u_lo.
                p.x[i] = [
                    p.x0[i][0] + (u[2 * i] as f64 - u_lo[2 * i] as f64),
                    p.x0[i][1] + (u[2 * i + 1] as f64 - u_lo[2 * i + 1] as f64),
                ];
                p.v[i] = [v[2 * i] as f64, v[2 * i + 1] as f64];
                p.rho[i] = rho[i] as f64;
                p.stress[i] = [s[3 * i] as f64, s[3 * i + 1] as f64, s[3 * i + 2] as f64];
            }
            if npc {
                p.a = b.pairs(Buf::A, n);
            }
            if lme {
                p.lambda = b.pairs(Buf::Lambda, n);
            }
            if def_grad {
                let g = b.f32s(Buf::DefGrad);
                for (i, f) in p.f.iter_mut().enumerate() {
                    *f = std::array::from_fn(|c| g[4 * i + c] as f64);
                }
            }
            if plastic {
                let g = b.f32s(Buf::Plastic);
                for (i, q) in p.plastic.iter_mut().enumerate() {
                    *q = std::array::from_fn(|c| g[4 * i + c] as f64);
                }
            }
            self.fresh = true;
        }
        Ok(&self.model.particles)
    }

    fn model(&self) -> &Model {
        &self.model
    }

    fn bytes_per_particle(&self) -> f64 {
        self.buffers.bytes() as f64 / self.model.particles.len().max(1) as f64
    }

    fn restore(&mut self, state: &State, steps: u64) -> Result<()> {
        crate::backend::check_state(&self.model, state)?;
        let steps = u32::try_from(steps).map_err(|_| {
            Error::Checkpoint(format!("{steps} steps exceed the GPU's step counter"))
        })?;
        self.upload_state_at(state, steps);
        self.t_floor = state.t;
        // The host copy of the particles is the state itself.
        self.fresh = true;
        Ok(())
    }
}

/// Buffers copied to the host by `GpuBackend::read`, looked up by name.
#[derive(Debug, Default)]
pub struct ReadBack {
    bytes: std::collections::BTreeMap<Buf, Vec<u8>>,
}

impl ReadBack {
    /// The raw bytes of `b`; panics if `b` was not read (a programming error).
    pub fn bytes(&self, b: Buf) -> &[u8] {
        self.bytes
            .get(&b)
            .unwrap_or_else(|| panic!("buffer {b:?} was not read back"))
    }

    /// `b` as f32s.
    pub fn f32s(&self, b: Buf) -> &[f32] {
        bytemuck::cast_slice(self.bytes(b))
    }

    /// The first `n` f32 pairs of `b`, widened.
    pub fn pairs(&self, b: Buf, n: usize) -> Vec<[f64; 2]> {
        self.f32s(b)
            .chunks_exact(2)
            .take(n)
            .map(|c| [c[0] as f64, c[1] as f64])
            .collect()
    }

    /// The `Sim` state.
    pub fn sim(&self) -> Sim {
        bytemuck::pod_read_unaligned(&self.bytes(Buf::Sim)[..std::mem::size_of::<Sim>()])
    }
}

/// The fault of `Sim::fault`'s `word` ((index << 4) | code) for `model`:
/// the solver's codes of `layout`, and from `FAULT_MATERIAL` on the faults
/// the faulting particle's material declares (`Constitutive::FAULTS`).
/// `lme_max_iter` is the scene's LME Newton limit (its fault's message).
pub fn decode_fault(model: &Model, lme_max_iter: u32, word: u32) -> Fault {
    let particle = (word >> 4) as usize;
    if word & 0xf == FAULT_MLS_SINGULAR {
        let at = crate::model::gauss::gauss_point_position(&model.shape, &model.grid, particle);
        return Fault {
            particle: None,
            kind: FaultKind::MlsSingular { at },
        };
    }
    let kind = match word & 0xf {
        FAULT_LEFT_GRID => FaultKind::Shape(ShapeFault::OutsideGrid),
        FAULT_NON_FINITE_STRAIN => FaultKind::NonFinite { field: "strain" },
        FAULT_NON_FINITE_STRESS => FaultKind::NonFinite { field: "stress" },
        FAULT_NON_FINITE_MOTION => FaultKind::NonFinite {
            field: "position or velocity",
        },
        FAULT_DENSITY => FaultKind::NonPositiveDensity,
        FAULT_LME_FEW_NODES => FaultKind::Shape(ShapeFault::LmeTooFewNodes { nodes: None }),
        FAULT_LME_NOT_CONVERGED => FaultKind::Shape(ShapeFault::LmeNotConverged {
            iterations: lme_max_iter,
            residual: None,
        }),
        FAULT_LME_SINGULAR => FaultKind::Shape(ShapeFault::LmeSingular { iterations: 0 }),
        // The material's own fault, through the particle's material;
        // the shader does not report its figure.
        code if code >= FAULT_MATERIAL && particle < model.particles.len() => {
            match model.material_of(particle).entry().fault_of_gpu_code(code) {
                Some(fault) => FaultKind::Material {
                    fault,
                    value: f64::NAN,
                },
                None => FaultKind::NonFinite {
                    field: "unknown material fault code",
                },
            }
        }
        code => FaultKind::NonFinite {
            field: if code == 0 {
                "unknown (fault code 0)"
            } else {
                "unknown fault code"
            },
        },
    };
    Fault::at(particle, kind)
}
