//! Compute pipelines built for one scene: each pass's WGSL is expanded with
//! the scene's flags (shape, integrator, material count, grid layout, atomic
//! mode), validated by naga, and its bind group made from naga's list of the
//! bindings it declares, so no binding number is repeated at a call site.

use super::buffers::{Buf, Buffers};
use super::constraint_points::PointCounts;
use super::context::{AtomicMode, GpuContext};
use super::layout::{PROBES_WG, WG};
use super::preprocess::{self, Defines};
use crate::error::{Error, Result};
use crate::model::shape::Shape;
use crate::model::{Integrator, Model};
use crate::scene::NpcPosition;
use crate::step::{Domain, PlanInputs, StepPlan};

pub use crate::step::Pass;

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
    /// Material models compiled in: a bit per registry code.
    pub materials: u32,
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
    /// MLS at Gauss points (either scope: the bins mark the occupied
    /// integration cells).
    pub mls: bool,
    /// `solver.mls_scope = "force"`: the fit corrects the internal force
    /// only (forces.wgsl built with MLS_FORCE, mls_fit, mls_force_gauss).
    pub mls_force: bool,
    /// Rigid walls (the `Walls`, `WallTouch` and `WallForce` buffers).
    pub walls: bool,
    /// Some wall appears or goes during the run (GATES: `wall_touch`
    /// compares the step's time with the wall's `appear_at`/`remove_at`).
    pub gates: bool,
    /// Some particle starts flush with a wall and compressed across it
    /// (WALL_PRELOAD: the `WallPreload` buffer, read with the stress by
    /// `shared/wall_spring.wgsl`).
    pub wall_preload: bool,
    /// The walls' preload has a fit to the body's discrete reaction
    /// (WALL_PRE_FIT: the `WallPreFit` buffer, `Walls::pre_fit`).
    pub wall_pre_fit: bool,
    /// `solver.pic_fraction` > 0 (PIC: `g2p` blends Σ N v_I in).
    pub pic: bool,
    /// `solver.local_damping` > 0 (LOCAL_DAMPING: `grid_update` built
    /// with `CORRECT` damps the nodal force).
    pub local_damping: bool,
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
    /// B-splines with their knots on the grid lines
    /// (`solver.bspline_knots = "cells"`, BSPLINE_CELLS).
    pub bspline_cells: bool,
    /// `p2g` and `forces` (and the fused `StressForces`) scatter per bin of
    /// particles that share their stencil's anchor, summing in registers
    /// before the atomics (PATCH): linear and B-splines on a regular grid,
    /// LME, where they do not gather (`GpuOptions::patches`).
    pub patch: bool,
    /// Contact pairs (CONTACT): [fields, pairs] (`model::contact`); the
    /// nodal buffers hold one copy of the nodes per field.
    pub contact: Option<[u32; 2]>,
    /// Constraint points (CONSTRAINT_POINTS): their tables' counts
    /// (`gpu::constraint_points`).
    pub points: Option<PointCounts>,
    /// `solver.volumetric_strain = "cell_average"` (CELL_AVERAGE): the
    /// bodies' count (N_BODIES), the (cell, body) slots per cell; 0 off.
    pub cell_average_bodies: u32,
}

impl Variant {
    pub fn of(model: &Model, atomics: AtomicMode, opts: &super::options::GpuOptions) -> Variant {
        Variant {
            materials: model
                .materials
                .iter()
                .fold(0, |bits, m| bits | 1 << m.entry().code),
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
            mls_force: model.mls && model.mls_scope == crate::scene::MlsScope::Force,
            walls: !model.walls.is_empty(),
            gates: model.walls.timed(),
            wall_preload: !model.walls.preload.is_empty(),
            wall_pre_fit: !model.walls.pre_fit.is_empty(),
            pic: model.pic_fraction > 0.0,
            local_damping: model.local_damping > 0.0,
            ext_force: model.external.is_some(),
            gather: opts.gathers(model),
            patch: opts.patches(model),
            contact: model
                .contact
                .as_ref()
                .map(|c| [c.n_fields as u32, c.pairs.len() as u32]),
            points: super::constraint_points::tables(model).map(|(c, _)| c),
            bspline_small_grid: match &model.shape {
                Shape::Bspline(b) => {
                    !(crate::model::shape::bspline::table_fits(model.grid.nx, b.degree)
                        && crate::model::shape::bspline::table_fits(model.grid.ny, b.degree))
                }
                _ => false,
            },
            bspline_cells: matches!(&model.shape, Shape::Bspline(b) if b.cells),
            cell_average_bodies: if model.cell_average_volumetric {
                model.body_names.len().max(1) as u32
            } else {
                0
            },
        }
    }

    /// The step plan of this variant (`crate::step`).
    pub fn plan(&self) -> StepPlan {
        StepPlan::new(PlanInputs {
            lme: self.shape == crate::scene::ShapeKind::Lme,
            mls: self.mls && !self.mls_force,
            mls_force: self.mls_force,
            musl: self.integrator == Integrator::Musl,
            gather: self.gather,
            patch: self.patch,
            walls: self.walls,
            contact: self.contact.is_some(),
            points: self.points.is_some(),
            cell_average: self.cell_average_bodies > 0,
            // Saturated soil has no WGSL twin: `GpuBackend` refuses it.
            pore: false,
        })
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
            .flag("DEF_GRAD", self.def_grad)
            .flag("PLASTIC", self.plastic)
            .flag("MMS", self.mms)
            .flag("MLS", self.mls)
            .flag("MLS_FORCE", self.mls_force)
            .flag("WALLS", self.walls)
            .flag("GATES", self.gates)
            .flag("WALL_PRELOAD", self.wall_preload)
            .flag("WALL_PRE_FIT", self.wall_pre_fit)
            .flag("PIC", self.pic)
            .flag("LOCAL_DAMPING", self.local_damping)
            .flag("EXT_FORCE", self.ext_force)
            .flag(
                "ANCHOR_BINS",
                self.gather || self.patch || self.contact.is_some(),
            )
            .flag("CONTACT", self.contact.is_some())
            .flag("CONSTRAINT_POINTS", self.points.is_some())
            .flag("BSPLINE_SMALL_GRID", self.bspline_small_grid)
            .flag("BSPLINE_CELLS", self.bspline_cells)
            .flag("MUSL", self.integrator == Integrator::Musl)
            .flag("CELL_AVERAGE", self.cell_average_bodies > 0);
        if self.cell_average_bodies > 0 {
            d.value("N_BODIES", self.cell_average_bodies);
        }
        if let Integrator::Npc { position, .. } = self.integrator {
            d.flag("NPC", true)
                .flag("NPC_POSITION_CORRECTED", position == NpcPosition::Corrected)
                .flag("NPC_POSITION_NEWMARK", position == NpcPosition::Newmark);
        }
        d.generate(
            "generated/materials.wgsl",
            crate::model::material::registry::wgsl(
                &crate::model::material::registry(),
                self.materials,
            ),
        );
        d.value(
            "ATOMIC_T",
            match self.atomics {
                AtomicMode::Float => "atomic<f32>",
                AtomicMode::CompareExchange => "atomic<u32>",
            },
        );
        d.value("LME_SIDE", self.lme_side);
        if let Some([fields, pairs]) = self.contact {
            d.value("N_FIELDS", fields).value("N_PAIRS", pairs);
        }
        if let Some(c) = self.points {
            d.value("POINT_COUNT", c.n_points)
                .value("POINT_SLOTS", c.slots)
                .value("POINT_HELD", c.n_held)
                .value("POINT_SLOTS_AT", c.slots_at())
                .value("POINT_WEIGHTS_AT", c.weights_at())
                .value("POINT_HELD_AT", c.held_at())
                .value("POINT_LIST_AT", c.list_at())
                .value("POINT_FREED_AT", c.freed_at())
                .value("POINT_ENV", c.env)
                .value("POINT_WORK_STRIDE", c.work_stride())
                .value("POINT_FIELDS", c.n_fields);
        }
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
}

/// Side of the LME search box: the integers in [q − R, q + R] number at
/// most floor(2R) + 1.
pub fn lme_side(model: &Model) -> u32 {
    match &model.shape {
        Shape::Lme(l) => (2.0 * (l.radius + l.search_extra) / l.h).floor() as u32 + 1,
        _ => 1,
    }
}

/// Expands a pass's WGSL for `d`, adding the pass's own flags
/// (`Pass::info`): WALK where the pass puts per-particle terms on nodes
/// through shared/bins.wgsl's walks, GATHER or PATCH for which walk,
/// CORRECT, FORCES, CLEAR, PARTICLES for a file's second pass.
pub fn expand(pass: Pass, d: &Defines) -> Result<String> {
    let Some(gpu) = pass.info().gpu else {
        return Err(Error::Gpu(format!(
            "{pass:?} has no WGSL: only the CPU runs it"
        )));
    };
    let mut d = d.clone();
    for flag in gpu.flags {
        d.flag(flag, true);
    }
    preprocess::expand(gpu.file, &d).map_err(|e| Error::Gpu(format!("WGSL preprocessing: {e}")))
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
    pipeline: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
    domain: Domain,
}

/// Every pass the scene needs, ready to dispatch.
pub struct Pipelines {
    /// Indexed by `pass as usize`: the passes of `plan.gpu_passes()`.
    built: Vec<Option<Built>>,
    n_particles: u32,
    n_nodes_or_groups: u32,
    n_pair_nodes: u32,
    n_probes: u32,
    n_cells: u32,
    n_gauss: u32,
    /// Lanes of the constraint points' passes (0 without points).
    n_point_lanes: u32,
    max_groups: u32,
    pub plan: StepPlan,
}

impl Pipelines {
    pub fn new(
        ctx: &GpuContext,
        model: &Model,
        buffers: &Buffers,
        opts: &super::options::GpuOptions,
    ) -> Result<Pipelines> {
        let variant = Variant::of(model, ctx.atomics, opts);
        let plan = variant.plan();
        let d = variant.defines();
        let mut built: Vec<Option<Built>> = Pass::ALL.iter().map(|_| None).collect();
        for pass in plan.gpu_passes() {
            let Some(gpu) = pass.info().gpu else {
                continue; // gpu_passes holds GPU passes only
            };
            let src = expand(pass, &d)?;
            if let Some(dir) = std::env::var_os("LME_MPM_DUMP_WGSL") {
                let _ = std::fs::create_dir_all(&dir);
                let _ = std::fs::write(
                    std::path::Path::new(&dir).join(format!("{pass:?}.wgsl")),
                    &src,
                );
            }
            let module = validate(&src, gpu.file, ctx.atomics)?;
            let binds = bindings(&module);
            let scope = ctx.device.push_error_scope(wgpu::ErrorFilter::Validation);
            let shader = ctx
                .device
                .create_shader_module(wgpu::ShaderModuleDescriptor {
                    label: Some(gpu.file),
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
                    label: Some(gpu.file),
                    entries: &entries,
                });
            let layout = ctx
                .device
                .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                    label: Some(gpu.file),
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
            built[pass as usize] = Some(Built {
                pipeline,
                bind_group,
                domain: gpu.domain,
            });
        }
        Ok(Pipelines {
            built,
            n_particles: buffers.n_particles as u32,
            n_nodes_or_groups: (buffers.n_nodes * buffers.n_fields)
                .max(2 * (buffers.n_groups + buffers.n_walls + buffers.n_pairs))
                as u32,
            n_pair_nodes: (buffers.n_nodes * buffers.n_pairs) as u32,
            n_probes: buffers.n_probes as u32,
            n_cells: buffers.n_cells.max(buffers.n_gauss / 4) as u32,
            n_gauss: buffers.n_gauss as u32,
            n_point_lanes: variant.points.map_or(0, |c| c.lanes()),
            max_groups: ctx.limits.max_compute_workgroups_per_dimension,
            plan,
        })
    }

    /// Records one dispatch of `pass`, a pass of `plan.gpu_passes()`.
    ///
    /// # Panics
    /// On a pass the scene's plan does not use: no pipeline was built for
    /// it (`tests/plan_coverage.rs` holds every plan's passes built).
    pub fn dispatch(&self, cpass: &mut wgpu::ComputePass<'_>, pass: Pass) {
        let Some(b) = &self.built[pass as usize] else {
            panic!("{pass:?} is not a pass of this scene's StepPlan: no pipeline was built");
        };
        let (x, y) = match b.domain {
            Domain::One => (1, 1),
            Domain::Probes => (self.n_probes.div_ceil(PROBES_WG).max(1), 1),
            Domain::Particles => grid_2d(self.n_particles, self.max_groups),
            Domain::Nodes => grid_2d(self.n_nodes_or_groups, self.max_groups),
            Domain::Cells => grid_2d(self.n_cells, self.max_groups),
            Domain::PairNodes => grid_2d(self.n_pair_nodes, self.max_groups),
            Domain::GaussPoints => grid_2d(self.n_gauss, self.max_groups),
            Domain::PointLanes => (self.n_point_lanes, 1),
        };
        cpass.set_pipeline(&b.pipeline);
        cpass.set_bind_group(0, &b.bind_group, &[]);
        cpass.dispatch_workgroups(x, y, 1);
    }

    /// Records the passes of one whole step.
    pub fn encode_step(&self, cpass: &mut wgpu::ComputePass<'_>) {
        for &pass in &self.plan.gpu_step {
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

    /// `StressForces` and its per-bin variant validate in every shape,
    /// integrator and material mix, walls and loads on and off (wider than
    /// the variants of tests/gpu_shaders.rs that fuse them).
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
                                // Registry codes: 0 linear elastic, 1 Neo-Hookean.
                                materials: if neo_hookean && !multi_material {
                                    2
                                } else if neo_hookean {
                                    3
                                } else {
                                    1
                                },
                                def_grad: neo_hookean,
                                plastic: false,
                                mms,
                                mls: false,
                                mls_force: false,
                                walls: mms,
                                gates: mms,
                                wall_preload: mms,
                                wall_pre_fit: mms,
                                pic: mms,
                                local_damping: mms,
                                ext_force: mms,
                                gather: false,
                                bspline_small_grid: perturbed,
                                bspline_cells: mms,
                                patch: false,
                                contact: None,
                                points: None,
                                cell_average_bodies: 0,
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
