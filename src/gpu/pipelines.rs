//! Compute pipelines built for one scene: each pass's WGSL is expanded with
//! the scene's flags (shape, integrator, material count, grid layout, atomic
//! mode), validated by naga, and its bind group made from naga's list of the
//! bindings it declares, so no binding number is repeated at a call site.

use super::buffers::{Buf, Buffers};
use super::context::{AtomicMode, GpuContext};
use super::layout::{PROBES_WG, WG};
use super::preprocess::{self, Defines};
use crate::error::{Error, Result};
use crate::model::shape::Shape;
use crate::model::{Integrator, Model};
use crate::scene::NpcPosition;
use crate::solver::Stage;

/// One GPU pass: a WGSL file and entry point, run over a domain.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Pass {
    Cfl,
    StepBegin,
    ClearGrid,
    LmeNewton,
    /// Particles binned by cell (shared/bins.wgsl): for MLS in `p2g`, for
    /// the gather passes in `shape_eval`.
    BinClear,
    BinCount,
    BinScan,
    BinFill,
    /// p2g.wgsl as a scatter with float atomics, or built with GATHER as
    /// one invocation per node over the binned particles (no atomics).
    P2g,
    P2gGather,
    /// p2g.wgsl built with PATCH: one invocation per bin of particles that
    /// share a stencil (linear and B-splines on a regular grid, LME), summing
    /// their contributions in registers, then one atomic per node and
    /// component of the stencil.
    P2gPatch,
    MlsP2g,
    /// Walls only: the walls each node touches (wall_touch.wgsl), before
    /// `GridPredict`.
    WallTouch,
    GridPredict,
    Stress,
    /// `stress` then `forces` in one pass (stress.wgsl built with FORCES):
    /// what a whole step runs without MLS. Not in `ALL`, which lists the
    /// passes of the stages one by one.
    StressForces,
    /// `StressForces` built with PATCH: per bin, as `P2gPatch`. Not in `ALL`.
    StressForcesPatch,
    /// forces.wgsl as a scatter, or built with GATHER as `P2gGather` is.
    Forces,
    ForcesGather,
    /// forces.wgsl built with PATCH, as `P2gPatch`.
    ForcesPatch,
    MlsForces,
    GridCorrect,
    G2p,
    /// MUSL's remap: zero the nodal momentum (remap.wgsl built with CLEAR),
    /// then scatter the new velocities from particles (`Remap`) or Gauss
    /// points (`MlsRemap`).
    RemapClear,
    Remap,
    MlsRemap,
    StepEnd,
    Probes,
    Energy,
}

/// What a pass's invocations run over.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Domain {
    Particles,
    /// Nodes, and at least 2 per constraint group and wall (clear_grid zeroes reactions).
    Nodes,
    One,
    Probes,
    /// Grid cells or integration cells, whichever are more (MLS).
    Cells,
    /// Gauss points (MLS).
    GaussPoints,
}

impl Pass {
    pub const ALL: [Pass; 27] = [
        Pass::Cfl,
        Pass::StepBegin,
        Pass::ClearGrid,
        Pass::LmeNewton,
        Pass::BinClear,
        Pass::BinCount,
        Pass::BinScan,
        Pass::BinFill,
        Pass::P2g,
        Pass::P2gGather,
        Pass::P2gPatch,
        Pass::MlsP2g,
        Pass::WallTouch,
        Pass::GridPredict,
        Pass::Stress,
        Pass::Forces,
        Pass::ForcesGather,
        Pass::ForcesPatch,
        Pass::MlsForces,
        Pass::GridCorrect,
        Pass::G2p,
        Pass::RemapClear,
        Pass::Remap,
        Pass::MlsRemap,
        Pass::StepEnd,
        Pass::Probes,
        Pass::Energy,
    ];

    /// The WGSL file (under shaders/).
    pub fn file(self) -> &'static str {
        match self {
            Pass::Cfl => "cfl.wgsl",
            Pass::StepBegin => "step_begin.wgsl",
            Pass::ClearGrid => "clear_grid.wgsl",
            Pass::LmeNewton => "lme_newton.wgsl",
            Pass::P2g | Pass::P2gGather | Pass::P2gPatch => "p2g.wgsl",
            Pass::WallTouch => "wall_touch.wgsl",
            Pass::GridPredict | Pass::GridCorrect => "grid_update.wgsl",
            Pass::Stress | Pass::StressForces | Pass::StressForcesPatch => "stress.wgsl",
            Pass::Forces | Pass::ForcesGather | Pass::ForcesPatch => "forces.wgsl",
            Pass::G2p => "g2p.wgsl",
            Pass::StepEnd => "step_end.wgsl",
            Pass::Probes => "probes.wgsl",
            Pass::Energy => "energy.wgsl",
            Pass::BinClear => "bin_clear.wgsl",
            Pass::BinCount => "bin_count.wgsl",
            Pass::BinScan => "bin_scan.wgsl",
            Pass::BinFill => "bin_fill.wgsl",
            Pass::MlsP2g => "mls_p2g.wgsl",
            Pass::MlsForces => "mls_forces.wgsl",
            Pass::RemapClear | Pass::Remap => "remap.wgsl",
            Pass::MlsRemap => "mls_remap.wgsl",
        }
    }

    fn domain(self) -> Domain {
        match self {
            Pass::StepBegin | Pass::StepEnd | Pass::BinScan => Domain::One,
            Pass::BinClear | Pass::P2gPatch | Pass::ForcesPatch | Pass::StressForcesPatch => {
                Domain::Cells
            }
            Pass::MlsP2g | Pass::MlsForces | Pass::MlsRemap => Domain::GaussPoints,
            Pass::ClearGrid
            | Pass::GridPredict
            | Pass::GridCorrect
            | Pass::RemapClear
            | Pass::P2gGather
            | Pass::ForcesGather => Domain::Nodes,
            Pass::Probes => Domain::Probes,
            _ => Domain::Particles,
        }
    }

    /// The GPU passes that do a solver stage. `Cfl` is the reduction plus
    /// the one-invocation Δt/stop pass; shape evaluation is LME's Newton
    /// solve and, for the gather passes, the binning (the weights
    /// themselves are evaluated inline where used). With MLS, `p2g` and
    /// `forces` work at Gauss points.
    pub fn for_stage(stage: Stage, plan: StepPlan) -> &'static [Pass] {
        const BINS: [Pass; 4] = [Pass::BinClear, Pass::BinCount, Pass::BinScan, Pass::BinFill];
        match stage {
            Stage::Cfl => &[Pass::Cfl, Pass::StepBegin],
            Stage::ClearGrid => &[Pass::ClearGrid],
            Stage::ShapeEval if (plan.gather || plan.patch) && plan.lme => {
                &[Pass::LmeNewton, BINS[0], BINS[1], BINS[2], BINS[3]]
            }
            Stage::ShapeEval if plan.gather || plan.patch => &BINS,
            Stage::ShapeEval if plan.lme => &[Pass::LmeNewton],
            Stage::ShapeEval => &[],
            Stage::P2g if plan.mls => &[BINS[0], BINS[1], BINS[2], BINS[3], Pass::MlsP2g],
            Stage::P2g if plan.gather => &[Pass::P2gGather],
            Stage::P2g if plan.patch => &[Pass::P2gPatch],
            Stage::P2g => &[Pass::P2g],
            Stage::Forces if plan.mls => &[Pass::MlsForces],
            Stage::Forces if plan.gather => &[Pass::ForcesGather],
            Stage::Forces if plan.patch => &[Pass::ForcesPatch],
            // `WallTouch` is built only with walls (`Variant::uses`).
            Stage::GridPredict => &[Pass::WallTouch, Pass::GridPredict],
            Stage::Stress => &[Pass::Stress],
            Stage::Forces => &[Pass::Forces],
            Stage::GridCorrect => &[Pass::GridCorrect],
            Stage::G2p => &[Pass::G2p],
            Stage::Remap if plan.mls => &[Pass::RemapClear, Pass::MlsRemap, Pass::GridPredict],
            Stage::Remap => &[Pass::RemapClear, Pass::Remap, Pass::GridPredict],
        }
    }
}

/// How a scene's stages map onto passes (`Pass::for_stage`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StepPlan {
    pub lme: bool,
    pub mls: bool,
    pub musl: bool,
    /// `p2g` and `forces` gather at nodes over particles binned in
    /// `shape_eval` (`Variant::gather`).
    pub gather: bool,
    /// `p2g` and `forces` scatter per bin of particles binned in
    /// `shape_eval` (`Variant::patch`).
    pub patch: bool,
}

/// Everything that selects a shader variant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Variant {
    pub shape: crate::scene::ShapeKind,
    pub integrator: Integrator,
    pub perturbed: bool,
    pub multi_material: bool,
    pub atomics: AtomicMode,
    /// LME search box side (nodes); 1 for other shapes.
    pub lme_side: u32,
    /// LME weights stored per slot (`GpuOptions::lme_stored`).
    pub lme_stored: bool,
    /// Material models compiled in.
    pub linear_elastic: bool,
    pub neo_hookean: bool,
    pub mohr_coulomb: bool,
    pub drucker_prager: bool,
    /// Particles carry a deformation gradient F (`Particles::f`, the
    /// `DefGrad` buffer): some material needs it. Neo-Hookean does today;
    /// a finite-strain plastic model would too, which is why this is not
    /// the `neo_hookean` flag.
    pub def_grad: bool,
    /// Particles carry a plastic state (`Particles::plastic`, the `Plastic`
    /// buffer): some material is plastic.
    pub plastic: bool,
    /// A manufactured solution's body force is applied.
    pub mms: bool,
    /// MLS reconstruction at Gauss points.
    pub mls: bool,
    /// Rigid walls (the `Walls`, `WallMask` and `WallTouch` buffers, the
    /// `WallTouch` pass).
    pub walls: bool,
    /// Tractions or point loads (the `ExtForce` buffer).
    pub ext_force: bool,
    /// `p2g` and `forces` as node-centred gathers over particles binned by
    /// cell, without atomics (GATHER): FE and NPC without MLS, unless
    /// `GpuOptions::scatter`. MUSL (whose remap scatters from the step's
    /// start positions) and MLS scatter.
    pub gather: bool,
    /// B-splines on a grid too small for the edge tables
    /// (`bspline::table_fits`): the open-knot recursion instead.
    pub bspline_small_grid: bool,
    /// `p2g` and `forces` (and the fused `StressForces`) scatter per bin of
    /// particles that share their stencil's anchor, summing in registers
    /// before the atomics (PATCH): linear and B-splines on a regular grid,
    /// LME, where they do not gather (`GpuOptions::patches`).
    pub patch: bool,
}

impl Variant {
    pub fn of(model: &Model, atomics: AtomicMode, opts: &super::GpuOptions) -> Variant {
        use crate::model::material::Material;
        Variant {
            linear_elastic: model
                .materials
                .iter()
                .any(|m| matches!(m, Material::LinearElastic(_))),
            neo_hookean: model
                .materials
                .iter()
                .any(|m| matches!(m, Material::NeoHookean(_))),
            mohr_coulomb: model
                .materials
                .iter()
                .any(|m| matches!(m, Material::MohrCoulomb(_))),
            drucker_prager: model
                .materials
                .iter()
                .any(|m| matches!(m, Material::DruckerPrager(_))),
            def_grad: !model.particles.f.is_empty(),
            plastic: !model.particles.plastic.is_empty(),
            lme_stored: opts.lme_stored && matches!(model.shape, Shape::Lme(_)),
            shape: model.shape.kind(),
            integrator: model.integrator,
            perturbed: model.grid.is_perturbed(),
            multi_material: model.materials.len() > 1,
            atomics,
            lme_side: lme_side(model),
            mms: model.manufactured.is_some(),
            mls: model.mls,
            walls: !model.walls.is_empty(),
            ext_force: model.external.is_some(),
            gather: opts.gathers(model),
            patch: opts.patches(model),
            bspline_small_grid: match &model.shape {
                Shape::Bspline(b) => {
                    !(crate::model::shape::bspline::table_fits(model.grid.nx, b.degree)
                        && crate::model::shape::bspline::table_fits(model.grid.ny, b.degree))
                }
                _ => false,
            },
        }
    }

    pub fn plan(&self) -> StepPlan {
        StepPlan {
            lme: self.shape == crate::scene::ShapeKind::Lme,
            mls: self.mls,
            musl: self.integrator == Integrator::Musl,
            gather: self.gather,
            patch: self.patch,
        }
    }

    /// Flags and values the WGSL is expanded with.
    pub fn defines(&self) -> Defines {
        use crate::scene::ShapeKind;
        let mut d = Defines::default();
        for b in Buf::ALL {
            d.value(&b.token(), b.binding());
        }
        d.flag("SHAPE_LINEAR", self.shape == ShapeKind::Linear)
            .flag("SHAPE_UGIMP", self.shape == ShapeKind::Ugimp)
            .flag("SHAPE_LME", self.shape == ShapeKind::Lme)
            .flag(
                "SHAPE_BSPLINE",
                matches!(self.shape, ShapeKind::Bspline2 | ShapeKind::Bspline3),
            )
            .flag("PERTURBED", self.perturbed)
            .flag("MULTI_MATERIAL", self.multi_material)
            .flag("FLOAT_ATOMICS", self.atomics == AtomicMode::Float)
            .flag("LME_STORED", self.lme_stored)
            .flag("MAT_LINEAR_ELASTIC", self.linear_elastic)
            .flag("MAT_NEO_HOOKEAN", self.neo_hookean)
            .flag("MAT_MOHR_COULOMB", self.mohr_coulomb)
            .flag("MAT_DRUCKER_PRAGER", self.drucker_prager)
            .flag("DEF_GRAD", self.def_grad)
            .flag("PLASTIC", self.plastic)
            .flag("MMS", self.mms)
            .flag("MLS", self.mls)
            .flag("WALLS", self.walls)
            .flag("EXT_FORCE", self.ext_force)
            .flag("ANCHOR_BINS", self.gather || self.patch)
            .flag("BSPLINE_SMALL_GRID", self.bspline_small_grid)
            .flag("MUSL", self.integrator == Integrator::Musl);
        if let Integrator::Npc { position, .. } = self.integrator {
            d.flag("NPC", true)
                .flag("NPC_POSITION_CORRECTED", position == NpcPosition::Corrected)
                .flag("NPC_POSITION_NEWMARK", position == NpcPosition::Newmark);
        }
        d.value(
            "ATOMIC_T",
            match self.atomics {
                AtomicMode::Float => "atomic<f32>",
                AtomicMode::CompareExchange => "atomic<u32>",
            },
        );
        d.value("LME_SIDE", self.lme_side);
        d.value(
            "BSPLINE_DEGREE",
            match self.shape {
                ShapeKind::Bspline2 => 2,
                ShapeKind::Bspline3 => 3,
                _ => 1,
            },
        );
        d
    }

    /// Whether the scene needs this pass.
    pub fn uses(&self, pass: Pass) -> bool {
        match pass {
            Pass::LmeNewton => self.shape == crate::scene::ShapeKind::Lme,
            Pass::BinClear | Pass::BinCount | Pass::BinScan | Pass::BinFill => {
                self.mls || self.gather || self.patch
            }
            Pass::MlsP2g | Pass::MlsForces => self.mls,
            Pass::P2g | Pass::Forces => !self.mls && !self.gather && !self.patch,
            Pass::P2gGather | Pass::ForcesGather => self.gather,
            Pass::P2gPatch | Pass::ForcesPatch | Pass::StressForcesPatch => self.patch,
            // MUSL runs the stress last, apart from the forces.
            Pass::StressForces => {
                !self.mls && !self.gather && !self.patch && self.integrator != Integrator::Musl
            }
            Pass::RemapClear => self.integrator == Integrator::Musl,
            Pass::Remap => self.integrator == Integrator::Musl && !self.mls,
            Pass::MlsRemap => self.integrator == Integrator::Musl && self.mls,
            Pass::WallTouch => self.walls,
            _ => true,
        }
    }
}

/// Side of the LME search box: the integers in [q − R, q + R] number at
/// most floor(2R) + 1.
pub fn lme_side(model: &Model) -> u32 {
    match &model.shape {
        Shape::Lme(l) => (2.0 * (l.radius + l.search_extra) / l.h).floor() as u32 + 1,
        _ => 1,
    }
}

/// Expands a pass's WGSL for `d`, adding the pass's own flags: WALK where
/// the pass puts per-particle terms on nodes through shared/bins.wgsl's
/// walks, GATHER or PATCH for which walk.
pub fn expand(pass: Pass, d: &Defines) -> Result<String> {
    let mut d = d.clone();
    d.flag(
        "WALK",
        matches!(
            pass,
            Pass::P2g
                | Pass::P2gGather
                | Pass::P2gPatch
                | Pass::Forces
                | Pass::ForcesGather
                | Pass::ForcesPatch
                | Pass::StressForces
                | Pass::StressForcesPatch
        ),
    )
    .flag(
        "GATHER",
        matches!(pass, Pass::P2gGather | Pass::ForcesGather),
    )
    .flag("CORRECT", pass == Pass::GridCorrect)
    .flag(
        "PATCH",
        matches!(
            pass,
            Pass::P2gPatch | Pass::ForcesPatch | Pass::StressForcesPatch
        ),
    )
    .flag(
        "FORCES",
        matches!(pass, Pass::StressForces | Pass::StressForcesPatch),
    )
    .flag("CLEAR", pass == Pass::RemapClear);
    preprocess::expand(pass.file(), &d).map_err(|e| Error::Gpu(format!("WGSL preprocessing: {e}")))
}

/// Parses and validates WGSL with naga (no GPU needed).
pub fn validate(src: &str, name: &str, atomics: AtomicMode) -> Result<naga::Module> {
    let module = naga::front::wgsl::parse_str(src).map_err(|e| {
        Error::Gpu(format!(
            "WGSL parse error:\n{}",
            e.emit_to_string_with_path(src, name)
        ))
    })?;
    let mut caps = naga::valid::Capabilities::default();
    if atomics == AtomicMode::Float {
        caps |= naga::valid::Capabilities::SHADER_FLOAT32_ATOMIC;
    }
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), caps)
        .validate(&module)
        .map_err(|e| {
            Error::Gpu(format!(
                "WGSL validation error:\n{}",
                e.emit_to_string_with_path(src, name)
            ))
        })?;
    Ok(module)
}

/// A declared binding: its buffer and whether the pass writes it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Binding {
    pub buf: Buf,
    pub uniform: bool,
    pub writable: bool,
}

/// The bindings a module declares, from naga's reflection.
pub fn bindings(module: &naga::Module) -> Vec<Binding> {
    let mut out: Vec<Binding> = module
        .global_variables
        .iter()
        .filter_map(|(_, v)| {
            let rb = v.binding.as_ref()?;
            let buf = Buf::from_binding(rb.binding)?;
            let (uniform, writable) = match v.space {
                naga::AddressSpace::Uniform => (true, false),
                naga::AddressSpace::Storage { access } => {
                    (false, access.contains(naga::StorageAccess::STORE))
                }
                _ => return None,
            };
            Some(Binding {
                buf,
                uniform,
                writable,
            })
        })
        .collect();
    out.sort_by_key(|b| b.buf);
    out
}

struct Built {
    pass: Pass,
    pipeline: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
    domain: Domain,
}

/// Every pass the scene needs, ready to dispatch.
pub struct Pipelines {
    built: Vec<Built>,
    n_particles: u32,
    n_nodes_or_groups: u32,
    n_probes: u32,
    n_cells: u32,
    n_gauss: u32,
    max_groups: u32,
    pub plan: StepPlan,
}

impl Pipelines {
    pub fn new(
        ctx: &GpuContext,
        model: &Model,
        buffers: &Buffers,
        opts: &super::GpuOptions,
    ) -> Result<Pipelines> {
        let variant = Variant::of(model, ctx.atomics, opts);
        let d = variant.defines();
        let mut built = Vec::new();
        for pass in Pass::ALL
            .into_iter()
            .chain([Pass::StressForces, Pass::StressForcesPatch])
        {
            if !variant.uses(pass) {
                continue;
            }
            let src = expand(pass, &d)?;
            if let Some(dir) = std::env::var_os("LME_MPM_DUMP_WGSL") {
                let _ = std::fs::create_dir_all(&dir);
                let _ = std::fs::write(
                    std::path::Path::new(&dir).join(format!("{pass:?}.wgsl")),
                    &src,
                );
            }
            let module = validate(&src, pass.file(), ctx.atomics)?;
            let binds = bindings(&module);
            let scope = ctx.device.push_error_scope(wgpu::ErrorFilter::Validation);
            let shader = ctx
                .device
                .create_shader_module(wgpu::ShaderModuleDescriptor {
                    label: Some(pass.file()),
                    source: wgpu::ShaderSource::Wgsl(src.into()),
                });
            let entries: Vec<wgpu::BindGroupLayoutEntry> = binds
                .iter()
                .map(|b| wgpu::BindGroupLayoutEntry {
                    binding: b.buf.binding(),
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::Buffer {
                        ty: if b.uniform {
                            wgpu::BufferBindingType::Uniform
                        } else {
                            wgpu::BufferBindingType::Storage {
                                read_only: !b.writable,
                            }
                        },
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                })
                .collect();
            let bgl = ctx
                .device
                .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                    label: Some(pass.file()),
                    entries: &entries,
                });
            let layout = ctx
                .device
                .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                    label: Some(pass.file()),
                    bind_group_layouts: &[Some(&bgl)],
                    immediate_size: 0,
                });
            let pipeline = ctx
                .device
                .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                    label: Some(&format!("{pass:?}")),
                    layout: Some(&layout),
                    module: &shader,
                    entry_point: Some("main"),
                    compilation_options: Default::default(),
                    cache: None,
                });
            let group_entries: Vec<wgpu::BindGroupEntry> = binds
                .iter()
                .map(|b| wgpu::BindGroupEntry {
                    binding: b.buf.binding(),
                    resource: buffers.get(b.buf).as_entire_binding(),
                })
                .collect();
            let bind_group = ctx.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(&format!("{pass:?}")),
                layout: &bgl,
                entries: &group_entries,
            });
            if let Some(e) = pollster::block_on(scope.pop()) {
                return Err(Error::Gpu(format!("building the {pass:?} pipeline: {e}")));
            }
            built.push(Built {
                pass,
                pipeline,
                bind_group,
                domain: pass.domain(),
            });
        }
        Ok(Pipelines {
            built,
            n_particles: buffers.n_particles as u32,
            n_nodes_or_groups: buffers
                .n_nodes
                .max(2 * (buffers.n_groups + buffers.n_walls))
                as u32,
            n_probes: buffers.n_probes as u32,
            n_cells: buffers.n_cells.max(buffers.n_gauss / 4) as u32,
            n_gauss: buffers.n_gauss as u32,
            max_groups: ctx.limits.max_compute_workgroups_per_dimension,
            plan: variant.plan(),
        })
    }

    /// Records one dispatch of `pass` (nothing if the scene does not use it).
    pub fn dispatch(&self, cpass: &mut wgpu::ComputePass<'_>, pass: Pass) {
        let Some(b) = self.built.iter().find(|b| b.pass == pass) else {
            return;
        };
        let (x, y) = match b.domain {
            Domain::One => (1, 1),
            Domain::Probes => (self.n_probes.div_ceil(PROBES_WG).max(1), 1),
            Domain::Particles => grid_2d(self.n_particles, self.max_groups),
            Domain::Nodes => grid_2d(self.n_nodes_or_groups, self.max_groups),
            Domain::Cells => grid_2d(self.n_cells, self.max_groups),
            Domain::GaussPoints => grid_2d(self.n_gauss, self.max_groups),
        };
        cpass.set_pipeline(&b.pipeline);
        cpass.set_bind_group(0, &b.bind_group, &[]);
        cpass.dispatch_workgroups(x, y, 1);
    }

    /// The passes of one whole step, in the order of the integrator's
    /// stage list (`solver::stages`); scattering without MLS, and where
    /// `forces` follows `stress` (not MUSL), the two run fused as
    /// `StressForces`.
    pub fn step_passes(plan: StepPlan) -> impl Iterator<Item = Pass> {
        let fuse = !plan.mls && !plan.musl && !plan.gather;
        let list = if plan.musl {
            crate::solver::STEP_MUSL
        } else {
            crate::solver::STEP
        };
        list.iter()
            .flat_map(move |stage| Pass::for_stage(*stage, plan).iter().copied())
            .filter_map(move |pass| match pass {
                Pass::Stress if fuse && plan.patch => Some(Pass::StressForcesPatch),
                Pass::Stress if fuse => Some(Pass::StressForces),
                Pass::Forces | Pass::ForcesPatch if fuse => None,
                p => Some(p),
            })
            .chain([Pass::StepEnd])
    }

    /// Records the passes of one whole step.
    pub fn encode_step(&self, cpass: &mut wgpu::ComputePass<'_>) {
        for pass in Pipelines::step_passes(self.plan) {
            self.dispatch(cpass, pass);
        }
    }
}

/// Workgroups for `n` invocations of size WG, folded into 2D past the
/// per-dimension limit (the shaders' `linear_index` unfolds it).
fn grid_2d(n: u32, max: u32) -> (u32, u32) {
    let groups = n.div_ceil(WG).max(1);
    if groups <= max {
        (groups, 1)
    } else {
        (max, groups.div_ceil(max))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::ShapeKind;

    /// `StressForces` is outside `Pass::ALL` (which tests/gpu_shaders.rs
    /// validates in every variant), so it is validated here.
    #[test]
    fn fused_stress_forces_validates() {
        let npc = Integrator::Npc {
            gamma: 0.5,
            position: NpcPosition::Corrected,
        };
        let mut checked = 0;
        let mut patched = 0;
        for shape in [
            ShapeKind::Linear,
            ShapeKind::Ugimp,
            ShapeKind::Lme,
            ShapeKind::Bspline2,
            ShapeKind::Bspline3,
        ] {
            for integrator in [Integrator::Fe, npc] {
                for perturbed in [false, true] {
                    for atomics in [AtomicMode::Float, AtomicMode::CompareExchange] {
                        for (multi_material, neo_hookean, mms) in [
                            (false, false, false),
                            (true, true, false),
                            (false, true, true),
                        ] {
                            let v = Variant {
                                shape,
                                integrator,
                                perturbed,
                                multi_material,
                                atomics,
                                lme_side: if shape == ShapeKind::Lme { 5 } else { 1 },
                                lme_stored: false,
                                linear_elastic: !neo_hookean || multi_material,
                                neo_hookean,
                                mohr_coulomb: false,
                                drucker_prager: false,
                                def_grad: neo_hookean,
                                plastic: false,
                                mms,
                                mls: false,
                                walls: mms,
                                ext_force: mms,
                                gather: false,
                                bspline_small_grid: perturbed,
                                patch: false,
                            };
                            let src = expand(Pass::StressForces, &v.defines()).unwrap();
                            let m = validate(&src, "stress.wgsl", atomics)
                                .unwrap_or_else(|e| panic!("{v:?}: {e}"));
                            let b = bindings(&m);
                            assert!(b.iter().any(|b| b.buf == Buf::NodeAcc && b.writable));
                            assert!(b.iter().any(|b| b.buf == Buf::Mass));
                            checked += 1;
                            // The per-bin variant, where it applies.
                            if shape == ShapeKind::Lme
                                || matches!(
                                    shape,
                                    ShapeKind::Linear | ShapeKind::Bspline2 | ShapeKind::Bspline3
                                ) && !perturbed
                            {
                                let v = Variant { patch: true, ..v };
                                let src = expand(Pass::StressForcesPatch, &v.defines()).unwrap();
                                let m = validate(&src, "stress.wgsl", atomics)
                                    .unwrap_or_else(|e| panic!("{v:?}: {e}"));
                                assert!(bindings(&m).iter().any(|b| b.buf == Buf::CellOrder));
                                patched += 1;
                            }
                        }
                    }
                }
            }
        }
        assert_eq!(checked, 120);
        assert_eq!(patched, 60);
    }
}
