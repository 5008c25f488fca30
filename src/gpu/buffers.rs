//! GPU buffers: one per field (so no single binding passes an adapter's
//! limit), made only for what the scene uses (no `a` without NPC, no λ
//! without LME, no node positions on a regular grid). The binding table
//! below is the one place binding numbers are defined: WGSL files write
//! `@binding({{B_X0}})`, the preprocessor fills in the number.

use super::context::GpuContext;
use super::layout::{
    GPU_PARAM_SLOTS, GpuConstraint, GpuContactPair, GpuMaterial, GpuWall, NODE_STRIDE,
    PROBE_STRIDE, Params, Sim,
};
use super::options::GpuOptions;
use crate::error::{Error, Result, SceneError};
use crate::model::material::Material;
use crate::model::shape::Shape;
use crate::model::{FIX_X, FIX_Y, Integrator, Model};
use std::collections::BTreeMap;

/// Every buffer a stage may bind. The binding number is the position here.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Buf {
    Params,
    Sim,
    Materials,
    Constraints,
    X0,
    U,
    ULo,
    V,
    A,
    Mass,
    Rho,
    Stress,
    Mat,
    Lambda,
    LmeCache,
    LmeNodes,
    LmeW,
    DefGrad,
    Plastic,
    NodeAcc,
    NodePos,
    Reactions,
    ProbeIdx,
    ProbeOut,
    EnergyOut,
    /// Particles binned by cell (shared/bins.wgsl), for MLS and the gather
    /// passes: count per cell, start per cell, the particles in cell order,
    /// each particle's cell.
    CellCount,
    CellStart,
    CellOrder,
    CellOf,
    MlsOcc,
    /// Per Gauss point: the fit's c = A⁻¹e₀ (`mls_scope = "all"`, 3 f32)
    /// or σ_h(x_g) then c (`"force"`, 6 f32).
    MlsCoef,
    /// `mls_scope = "force"`: per particle, σ_h(x_p) then its fit's c, 6 f32.
    MlsFit,
    /// `mls_scope = "force"`: ω_g L(x_g) per Gauss point, then V_p L_p per
    /// particle, 4 f32 each (mls_grad.wgsl).
    MlsGrad,
    /// `mls_scope = "force"`: per particle, the strain-rate correction ΔL
    /// (xx, xy, yx, yy; mls_strain.wgsl).
    MlsDl,
    Walls,
    /// Per node: the walls' forces this step (wall_contact.wgsl).
    WallForce,
    /// Per node: the weight of the particles in contact with a wall this
    /// step and their friction's weight (2 f32: S_I, T_I; wall_touch.wgsl).
    WallTouch,
    /// Per particle and wall: the preload traction of the particles that
    /// start flush with a wall and compressed (`Walls::preload`); only
    /// when some particle has one.
    WallPreload,
    /// Per node: the walls' preloads this step (wall_touch.wgsl), which
    /// wall_contact.wgsl counts in the body's velocity; with `WallPreload`.
    WallPreForce,
    /// Per grid node: the preload's fit to the body's discrete reaction
    /// (`Walls::pre_fit`, vec2 f32), read by wall_touch.wgsl and
    /// wall_contact.wgsl; only when there is one.
    WallPreFit,
    ExtForce,
    /// MUSL: each particle's position at the step's start (grid-relative),
    /// for the remap and the stress, which run after g2p has moved it.
    XStart,
    /// Contact pairs only (`model::contact`): per particle, its body's
    /// field (u32), by which `shape_node` offsets its nodes.
    Field,
    /// Contact pairs only: the pairs (`GpuContactPair`).
    ContactPairs,
    /// Contact pairs only: per field node, the mass gradient and volume
    /// [Σ m_p ∇N, Σ N V_p] (contact_grad.wgsl).
    ContactGrad,
    /// Contact pairs only: the smallest particle half-width this step (m,
    /// f32 bits; contact_grad.wgsl), the gap test's slack.
    ContactSlack,
    /// Contact pairs only: per pair and grid node, [n_x, n_y, gap]
    /// (contact_detect.wgsl; n zero where the pair is not in contact).
    ContactNormal,
    /// Contact pairs only: per field, [mass, Σ m_p Δv_p] (f32): the field's
    /// mass (uploaded) and the momentum the interface's PIC share changed
    /// in g2p (float atomics; zeroed by clear_grid), which
    /// contact_conserve.wgsl gives back (`cpu::contact_conserve::conserve`).
    ContactPic,
    /// Constraint points only: their tables (u32; `gpu::constraint_points`),
    /// the last of which, per grid node the groups that freed it, is read
    /// by `grid_update` and `contact_exchange` too.
    PointTable,
    /// Constraint points only: per field and component, the projection's
    /// scratch (f32; `PointCounts::work_stride` each).
    PointWork,
    /// `solver.volumetric_strain = "cell_average"` only: per particle, its
    /// body's index (u32).
    Body,
    /// `solver.volumetric_strain = "cell_average"` only: per grid cell and
    /// body, [Σ V tr L, Σ V] (cell_average.wgsl).
    CellAvg,
}

impl Buf {
    pub const ALL: [Buf; 52] = [
        Buf::Params,
        Buf::Sim,
        Buf::Materials,
        Buf::Constraints,
        Buf::X0,
        Buf::U,
        Buf::ULo,
        Buf::V,
        Buf::A,
        Buf::Mass,
        Buf::Rho,
        Buf::Stress,
        Buf::Mat,
        Buf::Lambda,
        Buf::LmeCache,
        Buf::LmeNodes,
        Buf::LmeW,
        Buf::DefGrad,
        Buf::Plastic,
        Buf::NodeAcc,
        Buf::NodePos,
        Buf::Reactions,
        Buf::ProbeIdx,
        Buf::ProbeOut,
        Buf::EnergyOut,
        Buf::CellCount,
        Buf::CellStart,
        Buf::CellOrder,
        Buf::CellOf,
        Buf::MlsOcc,
        Buf::MlsCoef,
        Buf::MlsFit,
        Buf::MlsGrad,
        Buf::MlsDl,
        Buf::Walls,
        Buf::WallForce,
        Buf::WallTouch,
        Buf::WallPreload,
        Buf::WallPreForce,
        Buf::WallPreFit,
        Buf::ExtForce,
        Buf::XStart,
        Buf::Field,
        Buf::ContactPairs,
        Buf::ContactGrad,
        Buf::ContactSlack,
        Buf::ContactNormal,
        Buf::ContactPic,
        Buf::PointTable,
        Buf::PointWork,
        Buf::Body,
        Buf::CellAvg,
    ];

    pub fn binding(self) -> u32 {
        Buf::ALL.iter().position(|b| *b == self).expect("in ALL") as u32
    }

    pub fn from_binding(b: u32) -> Option<Buf> {
        Buf::ALL.get(b as usize).copied()
    }

    /// Token in WGSL: `{{B_NODE_ACC}}` for `Buf::NodeAcc`.
    pub fn token(self) -> String {
        let name = format!("{self:?}");
        let mut t = String::from("B");
        for c in name.chars() {
            if c.is_uppercase() {
                t.push('_');
            }
            t.push(c.to_ascii_uppercase());
        }
        t
    }
}

/// The buffers of one run and the model they were built from.
pub struct Buffers {
    pub map: BTreeMap<Buf, wgpu::Buffer>,
    pub n_particles: usize,
    /// Grid nodes (one field's).
    pub n_nodes: usize,
    /// Copies of the grid's nodes in the nodal buffers (1 without contact
    /// pairs) and contact pairs (their reactions follow the walls').
    pub n_fields: usize,
    pub n_pairs: usize,
    pub n_probes: usize,
    pub n_groups: usize,
    /// Walls (their reactions follow the groups' in `Buf::Reactions`).
    pub n_walls: usize,
    /// Grid cells where particles are binned (MLS, gather or patch; else 0), and
    /// MLS Gauss points (0 without MLS).
    pub n_cells: usize,
    pub n_gauss: usize,
}

fn f32x2(v: [f64; 2]) -> [f32; 2] {
    [v[0] as f32, v[1] as f32]
}

impl Buffers {
    pub fn get(&self, b: Buf) -> &wgpu::Buffer {
        self.map
            .get(&b)
            .unwrap_or_else(|| panic!("buffer {b:?} not made for this scene"))
    }

    /// Bytes of GPU memory held, and per particle.
    pub fn bytes(&self) -> u64 {
        self.map.values().map(|b| b.size()).sum()
    }

    /// Makes and fills every buffer `model` needs.
    pub fn new(
        ctx: &GpuContext,
        model: &Model,
        params: &Params,
        opts: &GpuOptions,
    ) -> Result<Buffers> {
        let mut data: Vec<(Buf, Vec<u8>)> = vec![
            (Buf::Params, bytemuck::bytes_of(params).to_vec()),
            (Buf::Sim, bytemuck::bytes_of(&initial_sim()).to_vec()),
            (
                Buf::Materials,
                bytemuck::cast_slice(&gpu_materials(model)).to_vec(),
            ),
            (
                Buf::Constraints,
                bytemuck::cast_slice(&constraint_boxes(model)?).to_vec(),
            ),
        ];
        particle_data(model, params, opts, &mut data);
        let bins = binned(model, opts);
        grid_and_output_data(model, params, bins, &mut data);
        let map = upload(ctx, data, model)?;
        let g = &model.grid;
        let groups = model.constraints.groups.len();
        let n = model.particles.len();
        Ok(Buffers {
            map,
            n_particles: n,
            n_nodes: g.n_nodes(),
            n_fields: model.n_fields(),
            n_pairs: model.contact.as_ref().map_or(0, |c| c.pairs.len()),
            n_probes: model.probes.len(),
            n_groups: groups,
            n_walls: model.walls.list.len(),
            n_cells: if bins { (g.nx - 1) * (g.ny - 1) } else { 0 },
            n_gauss: if model.mls {
                4 * (params.mls_spans_x * params.mls_spans_y) as usize
            } else {
                0
            },
        })
    }
}

/// Whether particles are binned by cell: for MLS, the gather and per-bin
/// passes, and contact pairs' gaps (`contact_detect.wgsl`).
pub fn binned(model: &Model, opts: &GpuOptions) -> bool {
    model.mls || opts.gathers(model) || opts.patches(model) || model.contact.is_some()
}

/// The materials as the shaders read them.
pub fn gpu_materials(model: &Model) -> Vec<GpuMaterial> {
    model.materials.iter().map(gpu_material).collect()
}

/// One material as the shaders read it: the elastic header and the
/// model's own parameters, packed by its registry entry.
pub fn gpu_material(m: &Material) -> GpuMaterial {
    let (lame, shear) = m.lame_shear();
    let (youngs, nu) = m.youngs_nu();
    let params = m.gpu_params();
    assert!(
        params.len() <= GPU_PARAM_SLOTS && params.len() == m.entry().gpu_params.len(),
        "{}: {} GPU parameters packed for {} names (at most {GPU_PARAM_SLOTS})",
        m.entry().name,
        params.len(),
        m.entry().gpu_params.len()
    );
    let mut p = [0.0f32; GPU_PARAM_SLOTS];
    p[..params.len()].copy_from_slice(&params);
    GpuMaterial {
        lame: lame as f32,
        shear: shear as f32,
        p_modulus: (lame + 2.0 * shear) as f32,
        youngs: youngs as f32,
        nu: nu as f32,
        model: m.entry().code,
        bulk: (lame + 2.0 * shear / 3.0) as f32,
        p,
    }
}

/// Initial contents of the per-particle buffers.
fn particle_data(
    model: &Model,
    params: &Params,
    opts: &GpuOptions,
    data: &mut Vec<(Buf, Vec<u8>)>,
) {
    let p = &model.particles;
    let n = p.len();
    let g = &model.grid;
    let origin = g.min;
    let rel = |x: [f64; 2]| [(x[0] - origin[0]) as f32, (x[1] - origin[1]) as f32];
    let bytes = |v: &[f32]| bytemuck::cast_slice::<f32, u8>(v).to_vec();
    let flat2 = |it: &mut dyn Iterator<Item = [f32; 2]>| it.flatten().collect::<Vec<f32>>();
    data.push((Buf::X0, bytes(&flat2(&mut p.x0.iter().map(|x| rel(*x))))));
    let u: Vec<f32> =
        flat2(&mut (0..n).map(|i| f32x2([p.x[i][0] - p.x0[i][0], p.x[i][1] - p.x0[i][1]])));
    data.push((Buf::U, bytes(&u)));
    data.push((Buf::ULo, vec![0u8; 8 * n]));
    data.push((Buf::V, bytes(&flat2(&mut p.v.iter().map(|v| f32x2(*v))))));
    if matches!(model.integrator, Integrator::Npc { .. }) {
        data.push((Buf::A, bytes(&flat2(&mut p.a.iter().map(|v| f32x2(*v))))));
    }
    if model.integrator == Integrator::Musl {
        data.push((Buf::XStart, vec![0u8; 8 * n]));
    }
    let to32 = |v: &[f64]| v.iter().map(|x| *x as f32).collect::<Vec<f32>>();
    data.push((Buf::Mass, bytes(&to32(&p.mass))));
    data.push((Buf::Rho, bytes(&to32(&p.rho))));
    let s: Vec<f32> = p.stress.iter().flat_map(|s| s.map(|c| c as f32)).collect();
    data.push((Buf::Stress, bytes(&s)));
    if model.materials.len() > 1 {
        let mat: Vec<u32> = p
            .body
            .iter()
            .map(|b| model.body_material[*b as usize])
            .collect();
        data.push((Buf::Mat, bytemuck::cast_slice(&mat).to_vec()));
    }
    if matches!(model.shape, Shape::Lme(_)) {
        data.push((
            Buf::Lambda,
            bytes(&flat2(&mut p.lambda.iter().map(|v| f32x2(*v)))),
        ));
        if opts.lme_stored {
            let slots = (params.lme_side * params.lme_side) as usize;
            data.push((Buf::LmeNodes, vec![0xffu8; 4 * slots * n]));
            data.push((Buf::LmeW, vec![0u8; 12 * slots * n]));
        } else {
            data.push((Buf::LmeCache, vec![0u8; 16 * n]));
        }
    }
    if !p.f.is_empty() {
        let f: Vec<f32> = p.f.iter().flat_map(|f| f.map(|c| c as f32)).collect();
        data.push((Buf::DefGrad, bytes(&f)));
    }
    if let Some(e) = &model.external {
        // (fx, fy, ramp_time) per particle.
        let f: Vec<f32> = (0..n)
            .flat_map(|i| [e.force[i][0], e.force[i][1], e.ramp_time[i]].map(|c| c as f32))
            .collect();
        data.push((Buf::ExtForce, bytes(&f)));
    }
    if !p.plastic.is_empty() {
        // [σzz, ε̄p, εp_v, return] as vec4<f32>: 16 bytes per particle.
        let q: Vec<f32> = p.plastic.iter().flat_map(|q| q.map(|c| c as f32)).collect();
        data.push((Buf::Plastic, bytes(&q)));
    }
}

/// Initial contents of the nodal, constraint, probe, energy, cell-bin
/// (`bins`: MLS or gather) and MLS buffers.
fn grid_and_output_data(
    model: &Model,
    params: &Params,
    bins: bool,
    data: &mut Vec<(Buf, Vec<u8>)>,
) {
    let n = model.particles.len();
    let g = &model.grid;
    let origin = g.min;
    let rel = |x: [f64; 2]| [(x[0] - origin[0]) as f32, (x[1] - origin[1]) as f32];
    let bytes = |v: &[f32]| bytemuck::cast_slice::<f32, u8>(v).to_vec();
    let flat2 = |it: &mut dyn Iterator<Item = [f32; 2]>| it.flatten().collect::<Vec<f32>>();
    // One copy of the nodes per field (contact pairs), stacked.
    let field_nodes = g.n_nodes() * model.n_fields();
    data.push((Buf::NodeAcc, vec![0u8; 4 * NODE_STRIDE * field_nodes]));
    if g.is_perturbed() {
        data.push((
            Buf::NodePos,
            bytes(&flat2(&mut g.pos.iter().map(|x| rel(*x)))),
        ));
    }
    let reactions = model.reaction_names().len();
    data.push((Buf::Reactions, vec![0u8; 8 * reactions.max(1)]));
    if !model.walls.is_empty() {
        let walls: Vec<GpuWall> = model
            .walls
            .list
            .iter()
            .map(|w| GpuWall {
                point: [
                    (w.point[0] - origin[0]) as f32,
                    (w.point[1] - origin[1]) as f32,
                ],
                normal: f32x2(w.normal),
                mu: w.mu as f32,
                contact: w.contact,
                stiffness: w.stiffness as f32,
                offset: w.offset as f32,
                appear_at: w.appear_at as f32,
                // A finite "never" (WGSL may assume no infinities).
                remove_at: if w.remove_at.is_finite() {
                    w.remove_at as f32
                } else {
                    f32::MAX
                },
            })
            .collect();
        data.push((Buf::Walls, bytemuck::cast_slice(&walls).to_vec()));
        data.push((Buf::WallForce, vec![0u8; 8 * field_nodes]));
        data.push((Buf::WallTouch, vec![0u8; 8 * field_nodes]));
        if !model.walls.preload.is_empty() {
            let pre: Vec<f32> = model.walls.preload.iter().map(|&t| t as f32).collect();
            data.push((Buf::WallPreload, bytemuck::cast_slice(&pre).to_vec()));
            data.push((Buf::WallPreForce, vec![0u8; 8 * field_nodes]));
        }
        if !model.walls.pre_fit.is_empty() {
            let fit: Vec<[f32; 2]> = model.walls.pre_fit.iter().map(|&a| f32x2(a)).collect();
            data.push((Buf::WallPreFit, bytemuck::cast_slice(&fit).to_vec()));
        }
    }
    let probe_idx: Vec<u32> = model.probes.iter().map(|pr| pr.particle as u32).collect();
    let probe_idx = if probe_idx.is_empty() {
        vec![0]
    } else {
        probe_idx
    };
    data.push((Buf::ProbeIdx, bytemuck::cast_slice(&probe_idx).to_vec()));
    data.push((
        Buf::ProbeOut,
        vec![0u8; 4 * PROBE_STRIDE * model.probes.len().max(1)],
    ));
    data.push((Buf::EnergyOut, vec![0u8; 16]));
    if let Some(c) = &model.contact {
        let field: Vec<u32> = model
            .particles
            .body
            .iter()
            .map(|b| c.field_of_body[*b as usize])
            .collect();
        data.push((Buf::Field, bytemuck::cast_slice(&field).to_vec()));
        let first = model.constraints.groups.len() + model.walls.list.len();
        let pairs: Vec<GpuContactPair> = c
            .pairs
            .iter()
            .enumerate()
            .map(|(k, p)| GpuContactPair {
                fields: p.fields,
                law: p.law,
                mu: p.mu as f32,
                reaction: (first + k) as u32,
                _pad: 0,
            })
            .collect();
        data.push((Buf::ContactPairs, bytemuck::cast_slice(&pairs).to_vec()));
        data.push((Buf::ContactGrad, vec![0u8; 12 * field_nodes]));
        // The largest finite f32 (clear_grid resets it each step).
        data.push((Buf::ContactSlack, f32::MAX.to_ne_bytes().to_vec()));
        data.push((
            Buf::ContactNormal,
            vec![0u8; 12 * c.pairs.len() * g.n_nodes()],
        ));
        let mut pic = vec![0f32; 3 * c.n_fields];
        let mut field_mass = vec![0f64; c.n_fields];
        for (f, m) in field.iter().zip(&model.particles.mass) {
            field_mass[*f as usize] += m;
        }
        for (k, m) in field_mass.iter().enumerate() {
            pic[3 * k] = *m as f32;
        }
        data.push((Buf::ContactPic, bytemuck::cast_slice(&pic).to_vec()));
    }
    if model.cell_average_volumetric {
        data.push((
            Buf::Body,
            bytemuck::cast_slice(&model.particles.body).to_vec(),
        ));
        let slots = 2 * (g.nx - 1) * (g.ny - 1) * model.body_names.len().max(1);
        data.push((Buf::CellAvg, vec![0u8; 4 * slots]));
    }
    if let Some((counts, table)) = super::constraint_points::tables(model) {
        data.push((Buf::PointTable, bytemuck::cast_slice(&table).to_vec()));
        data.push((
            Buf::PointWork,
            vec![0u8; 4 * (counts.lanes() * counts.work_stride()) as usize],
        ));
    }
    if bins {
        let cells = (g.nx - 1) * (g.ny - 1);
        data.push((Buf::CellCount, vec![0u8; 4 * cells]));
        data.push((Buf::CellStart, vec![0u8; 4 * (cells + 1)]));
        data.push((Buf::CellOrder, vec![0u8; 4 * n]));
        data.push((Buf::CellOf, vec![0u8; 4 * n]));
    }
    if model.mls {
        let spans = (params.mls_spans_x * params.mls_spans_y) as usize;
        data.push((Buf::MlsOcc, vec![0u8; 4 * spans]));
        if model.mls_scope == crate::scene::MlsScope::Force {
            data.push((Buf::MlsCoef, vec![0u8; 24 * 4 * spans]));
            data.push((Buf::MlsFit, vec![0u8; 24 * n]));
            data.push((Buf::MlsGrad, vec![0u8; 16 * (4 * spans + n)]));
            data.push((Buf::MlsDl, vec![0u8; 16 * n]));
        } else {
            data.push((Buf::MlsCoef, vec![0u8; 12 * 4 * spans]));
        }
    }
}

/// Creates each buffer (the uniform `Params`, the rest storage) with its
/// contents; refuses one larger than the adapter can bind, naming it.
fn upload(
    ctx: &GpuContext,
    data: Vec<(Buf, Vec<u8>)>,
    model: &Model,
) -> Result<BTreeMap<Buf, wgpu::Buffer>> {
    let n = model.particles.len();
    let g = &model.grid;
    let limit = ctx.limits.max_storage_buffer_binding_size;
    let max_buf = ctx.limits.max_buffer_size;
    let mut map = BTreeMap::new();
    for (b, bytes) in data {
        let size = (bytes.len() as u64).max(16).next_multiple_of(4);
        if size > limit.min(max_buf) {
            return Err(Error::Gpu(format!(
                "the {b:?} buffer needs {size} bytes, more than this adapter binds ({} bytes): \
                 the scene has {n} particles and {} nodes; use fewer, or an adapter with larger bindings",
                limit.min(max_buf),
                g.n_nodes()
            )));
        }
        let usage = if b == Buf::Params {
            wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST
        } else {
            wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_DST
                | wgpu::BufferUsages::COPY_SRC
        };
        let buf = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(&format!("{b:?}")),
            size,
            usage,
            mapped_at_creation: false,
        });
        ctx.queue.write_buffer(&buf, 0, &bytes);
        map.insert(b, buf);
    }
    Ok(map)
}

/// The Sim state at t = 0.
pub fn initial_sim() -> Sim {
    Sim {
        t: 0.0,
        t_lo: 0.0,
        ticks: [0; 2],
        t_stop_ticks: [0; 2],
        dt: 0.0,
        steps: 0,
        running: 0,
        final_step: 0,
        cmax_bits: 0,
        fault: super::layout::FAULT_NONE,
    }
}

/// Constraint groups as lattice index boxes (membership is decided on the
/// unperturbed lattice, exactly as `model::build_constraints` does). The
/// GPU fixes every node of the box, less those the group's constraint
/// points freed (`Constraints::freed`, marked in `Buf::PointTable`), so a
/// group whose nodes and freed nodes do not fill their bounding box
/// exactly (not one a scene's `[constraints.*]` rectangle can select) is
/// refused here rather than fixing nodes the CPU leaves free.
pub fn constraint_boxes(model: &Model) -> Result<Vec<GpuConstraint>> {
    let g = &model.grid;
    let mut out = Vec::new();
    for (k, grp) in model.constraints.groups.iter().enumerate() {
        let freed = model.constraints.freed.get(k).map_or(&[][..], |f| &f[..]);
        let nodes: Vec<u32> = grp.nodes.iter().chain(freed).copied().collect();
        let (mut i0, mut i1, mut j0, mut j1) = (u32::MAX, 0, u32::MAX, 0);
        for &n in &nodes {
            let (i, j) = (n % g.nx as u32, n / g.nx as u32);
            i0 = i0.min(i);
            i1 = i1.max(i);
            j0 = j0.min(j);
            j1 = j1.max(j);
        }
        let mut distinct = nodes.clone();
        distinct.sort_unstable();
        distinct.dedup();
        let area = if nodes.is_empty() {
            0
        } else {
            (i1 - i0 + 1) as usize * (j1 - j0 + 1) as usize
        };
        if area == 0 || distinct.len() != area || nodes.len() != area {
            return Err(Error::Scene(SceneError::invalid(
                format!("constraints.{}", grp.name),
                format!(
                    "its {} nodes do not form a box of the lattice (the bounding box holds {area}); \
                     the GPU path needs a rectangle of nodes",
                    nodes.len()
                ),
            )));
        }
        out.push(GpuConstraint {
            i0,
            i1,
            j0,
            j1,
            fix: (grp.fix & FIX_X) as u32 | (grp.fix & FIX_Y) as u32,
            vx: grp.velocity[0] as f32,
            vy: grp.velocity[1] as f32,
            ramp_time: grp.ramp_time as f32,
        });
    }
    if out.is_empty() {
        // A binding may not be empty; n_groups = 0 keeps this one unread.
        out.push(GpuConstraint {
            i0: 1,
            i1: 0,
            j0: 1,
            j1: 0,
            fix: 0,
            vx: 0.0,
            vy: 0.0,
            ramp_time: 0.0,
        });
    }
    Ok(out)
}
