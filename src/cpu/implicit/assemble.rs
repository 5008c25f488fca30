//! The implicit step's discrete weak form (implicit-MPM paper eqs. 28–37)
//! on the grid of the step's start, which moves with the Newton iterate:
//! particles ride on it, so N_I(x_p) and ∇N_I (taken at the step's start)
//! stay fixed through the step and the iterate is the nodal displacement
//! increment Δu.
//!
//! Per particle: ΔF = I + Σ_I Δu_I ⊗ ∇N_I, the material's stress at ΔF
//! (`Material::increment`), and the first Piola–Kirchhoff stress relative
//! to the step's start, P = det(ΔF) σ ΔF⁻ᵀ. Then
//!   f_int,I = Σ_p V_p P ∇N_I,
//!   f_ext,I = Σ_p m_p N_I b_p,
//!   (M a)_I = Σ_p m_p N_I Σ_K N_K a_K   (consistent mass, eq. 35),
//!        or Σ_p m_p N_I a_I             (lumped, `solver.implicit_mass`),
//!   R = f_ext − f_int − M a + f_contact,
//! and the Jacobian K = −∂R/∂Δu:
//!   K_IK = Σ_p V_p ∇N_I · A · ∇N_K + M_IK / (β Δt²) + K_contact,
//! with A = ∂P/∂ΔF. Pulled back to the step's start this is exactly the
//! paper's spatial geometric + material stiffness (eqs. 32–34): the same
//! linearisation written in the other configuration. Wall contact forces
//! and their stiffness are `contact`'s, per contact state.

use super::contact::{self, ContactPair, ContactState};
use crate::cpu::ShapeCache;
use crate::model::fault::{Fault, FaultKind};
use crate::model::material::Material;
use crate::model::material::increment::{StepState, mul};
use crate::model::{ConstraintPoint, Model};
use faer::sparse::SymbolicSparseColMat;
use faer::sparse::linalg::solvers::SymbolicLu;
use rayon::prelude::*;

/// Marks a node component that is not an unknown (no mass, or fixed).
pub const NO_DOF: u32 = u32::MAX;

/// Contact penalty stiffness relative to the stiffest material's P-wave
/// modulus (N/m per metre of thickness): a wall node then gives way by
/// about 1e-4 of the strain the contact force would cause in the material.
pub const PENALTY_REL: f64 = 1e4;

/// Constraint-point penalty relative to the stiffest material's P-wave
/// modulus (N/m per metre of thickness, per point), as the walls'
/// (`PENALTY_REL`): with two points per cell along the edge, the edge
/// gives way by about 1 / (2 · 1e4) of the strain its force would cause in
/// a cell of the material (the stiff cantilever's points move by ~1e-8 m
/// against a tip deflection of 6.8e-3 m). 1e6 stalls Newton at a residual
/// of 3e-8 of the step's reference (the penalty forces' round-off).
pub const POINT_PENALTY_REL: f64 = 1e4;

/// The unknowns of one step: two per node with mass (equations 2·id and
/// 2·id + 1). Held components (constraints, stick walls) stay in the
/// system as identity rows with their prescribed Δu, so every node's block
/// has the same layout.
#[derive(Debug, Clone, Default)]
pub struct Dofs {
    /// Per node: its index among the nodes with mass, or `NO_DOF`.
    pub id: Vec<u32>,
    /// Per node: held components (`FIX_X | FIX_Y` bits).
    pub held: Vec<u8>,
    /// Nodes with mass.
    pub active: usize,
}

impl Dofs {
    /// Component `c` of node `n` is an unknown.
    #[inline]
    pub fn free(&self, n: usize, c: usize) -> bool {
        self.id[n] != NO_DOF && self.held[n] & (1 << c) == 0
    }

    /// Equations in the system.
    pub fn count(&self) -> usize {
        2 * self.active
    }
}

/// The Newmark parameters of a step.
#[derive(Debug, Clone, Copy)]
pub struct Newmark {
    pub beta: f64,
    pub gamma: f64,
    pub dt: f64,
    /// Static analysis: no inertia.
    pub is_static: bool,
}

impl Newmark {
    /// Nodal acceleration at the step's end from Δu and the nodal velocity
    /// and acceleration at its start (eq. 44).
    #[inline]
    pub fn accel(&self, du: [f64; 2], v: [f64; 2], a: [f64; 2]) -> [f64; 2] {
        if self.is_static {
            return [0.0; 2];
        }
        let (b, dt) = (self.beta, self.dt);
        let k = 1.0 / (b * dt * dt);
        std::array::from_fn(|i| k * (du[i] - dt * v[i] - dt * dt * (0.5 - b) * a[i]))
    }

    /// ∂a/∂Δu (1/s²).
    #[inline]
    pub fn accel_slope(&self) -> f64 {
        if self.is_static {
            0.0
        } else {
            1.0 / (self.beta * self.dt * self.dt)
        }
    }
}

/// A particle at the current iterate.
#[derive(Debug, Clone, Copy)]
pub struct ParticleIterate {
    pub df: [f64; 4],
    pub state: StepState,
    /// First Piola–Kirchhoff stress relative to the step's start, [iJ] as
    /// [xx, xy, yx, yy] (Pa).
    pub p: [f64; 4],
    /// det ΔF.
    pub j: f64,
}

/// ΔF of particle `p` from the nodal increments.
#[inline]
pub fn incremental_gradient(cache: &ShapeCache, p: usize, du: &[[f64; 2]]) -> [f64; 4] {
    let (nodes, w) = cache.particle(p);
    let mut df = [1.0, 0.0, 0.0, 1.0];
    for (&n, wk) in nodes.iter().zip(w) {
        let u = du[n as usize];
        df[0] += u[0] * wk[1];
        df[1] += u[0] * wk[2];
        df[2] += u[1] * wk[1];
        df[3] += u[1] * wk[2];
    }
    df
}

/// Inverse of a 2 × 2 [xx, xy, yx, yy] with determinant `j`.
#[inline]
fn inverse(f: &[f64; 4], j: f64) -> [f64; 4] {
    [f[3] / j, -f[1] / j, -f[2] / j, f[0] / j]
}

/// σ as a full 2 × 2 [xx, xy, yx, yy].
#[inline]
fn full(s: &[f64; 3]) -> [f64; 4] {
    [s[0], s[2], s[2], s[1]]
}

/// The material update at ΔF and P = J σ ΔF⁻ᵀ.
pub fn particle_iterate(
    material: &Material,
    df: [f64; 4],
    start: &StepState,
) -> Result<ParticleIterate, FaultKind> {
    let state = material.increment(&df, start)?;
    let j = df[0] * df[3] - df[1] * df[2];
    let g = inverse(&df, j);
    // P = J σ G^T: P_iJ = J Σ_j σ_ij G_Jj.
    let s = full(&state.stress);
    let gt = [g[0], g[2], g[1], g[3]];
    let sg = mul(&s, &gt);
    let p = sg.map(|v| j * v);
    if !p.iter().all(|v| v.is_finite()) {
        return Err(FaultKind::NonFinite { field: "stress" });
    }
    Ok(ParticleIterate { df, state, p, j })
}

/// A = ∂P/∂ΔF as a 4 × 4 over [iJ] × [kL] (both in [xx, xy, yx, yy] order):
///   A_iJkL = J G_Lk σ_ij G_Jj + J (∂σ_ij/∂ΔF_kL) G_Jj − J σ_ij G_Jk G_Lj,
/// with G = ΔF⁻¹, summed over j.
pub fn piola_tangent(
    material: &Material,
    it: &ParticleIterate,
    start: &StepState,
) -> Result<[[f64; 4]; 4], FaultKind> {
    let ds = material.increment_tangent(&it.df, start)?;
    let (j, g) = (it.j, inverse(&it.df, it.j));
    let s = full(&it.state.stress);
    // ∂σ_ij/∂ΔF_kL as a full 2 × 2 in ij per column kL.
    let dsf = |i: usize, jj: usize, c: usize| match (i, jj) {
        (0, 0) => ds[0][c],
        (1, 1) => ds[1][c],
        _ => ds[2][c],
    };
    let mut a = [[0.0; 4]; 4];
    for i in 0..2 {
        for big_j in 0..2 {
            for k in 0..2 {
                for l in 0..2 {
                    let mut v = 0.0;
                    for jj in 0..2 {
                        let sij = s[2 * i + jj];
                        let gjj = g[2 * big_j + jj];
                        v += j * g[2 * l + k] * sij * gjj;
                        v += j * dsf(i, jj, 2 * k + l) * gjj;
                        v -= j * sij * g[2 * big_j + k] * g[2 * l + jj];
                    }
                    a[2 * i + big_j][2 * k + l] = v;
                }
            }
        }
    }
    Ok(a)
}

/// Inputs of the residual and Jacobian that stay fixed through a step.
pub struct StepInputs<'a> {
    pub cache: &'a ShapeCache,
    /// Particles' mass and material, the walls.
    pub model: &'a Model,
    /// V_p at the step's start (m²).
    pub volume: &'a [f64],
    /// Body force per unit mass at the step's end, load factor applied (m/s²).
    pub body: &'a [[f64; 2]],
    pub start: &'a [StepState],
    /// Nodal velocity and acceleration at the step's start.
    pub v: &'a [[f64; 2]],
    pub a: &'a [[f64; 2]],
    pub newmark: Newmark,
    pub dofs: &'a Dofs,
    /// Wall contact penalty k (N/m per metre of thickness).
    pub penalty: f64,
    /// The step's wall contacts: unknown nodes behind `slip` and
    /// `friction` walls (the grid), or near any wall (a GMM cloud).
    pub pairs: &'a [ContactPair],
    /// Lumped mass, M_II = Σ_p m_p N_I, instead of the consistent one.
    pub lumped_mass: bool,
    /// Per constraint point (`model.constraints.points`): its prescribed
    /// Δu over the step (m), and the points' penalty α (N/m per metre).
    pub point_target: &'a [[f64; 2]],
    pub point_penalty: f64,
}

/// Nodal residual of the particles at the iterate `du` (N per metre of
/// thickness), every node and component, fixed ones included (their
/// residual is minus the support's reaction), with the particle iterates it
/// used; wall contact is added by `add_contact`.
pub fn residual(
    inp: &StepInputs,
    du: &[[f64; 2]],
    iterates: &mut [ParticleIterate],
    r: &mut [[f64; 2]],
) -> Result<(), Fault> {
    let nn = du.len();
    // Particle updates first (they may fault), then one scatter.
    let fault = iterates
        .par_iter_mut()
        .enumerate()
        .with_min_len(256)
        .map(|(p, it)| {
            let df = incremental_gradient(inp.cache, p, du);
            match particle_iterate(inp.model.material_of(p), df, &inp.start[p]) {
                Ok(x) => {
                    *it = x;
                    None
                }
                Err(kind) => Some(Fault::at(p, kind)),
            }
        })
        .reduce(|| None, Fault::first);
    if let Some(f) = fault {
        return Err(f);
    }
    let nw = inp.newmark;
    let chunk = 4096;
    let partial = iterates
        .par_chunks(chunk)
        .enumerate()
        .fold(
            || vec![[0.0; 2]; nn],
            |mut sum, (c, its)| {
                for (k, it) in its.iter().enumerate() {
                    let p = c * chunk + k;
                    let (nodes, w) = inp.cache.particle(p);
                    let (m, vol) = (inp.model.particles.mass[p], inp.volume[p]);
                    // Particle acceleration at the step's end (eq. 47),
                    // for the consistent mass.
                    let mut ap = [0.0; 2];
                    if !nw.is_static && !inp.lumped_mass {
                        for (&n, wk) in nodes.iter().zip(w) {
                            let n = n as usize;
                            let an = nw.accel(du[n], inp.v[n], inp.a[n]);
                            ap[0] += wk[0] * an[0];
                            ap[1] += wk[0] * an[1];
                        }
                    }
                    let b = inp.body[p];
                    for (&n, wk) in nodes.iter().zip(w) {
                        let n = n as usize;
                        // Lumped: the node's own acceleration.
                        let acc = if inp.lumped_mass {
                            nw.accel(du[n], inp.v[n], inp.a[n])
                        } else {
                            ap
                        };
                        let f = &mut sum[n];
                        for i in 0..2 {
                            let internal = vol * (it.p[2 * i] * wk[1] + it.p[2 * i + 1] * wk[2]);
                            f[i] += wk[0] * m * (b[i] - acc[i]) - internal;
                        }
                    }
                }
                sum
            },
        )
        .reduce_with(|mut a, b| {
            for (x, y) in a.iter_mut().zip(&b) {
                x[0] += y[0];
                x[1] += y[1];
            }
            a
        })
        .unwrap_or_else(|| vec![[0.0; 2]; nn]);
    r.copy_from_slice(&partial);
    Ok(())
}

/// Adds the walls' contact forces at `du` to `r`, each pair under its
/// `states` entry, or under Coulomb's law itself when `states` is None;
/// `wall_force`, when given, receives each wall's force on the material.
pub fn add_contact(
    inp: &StepInputs,
    du: &[[f64; 2]],
    states: Option<&[ContactState]>,
    r: &mut [[f64; 2]],
    mut wall_force: Option<&mut [[f64; 2]]>,
) {
    if let Some(wf) = wall_force.as_deref_mut() {
        wf.fill([0.0; 2]);
    }
    let walls = &inp.model.walls.list;
    for (i, pair) in inp.pairs.iter().enumerate() {
        let (n, k) = (pair.node as usize, pair.wall as usize);
        let state = states.map_or_else(
            || contact::natural_state(&walls[k], pair.gap, du[n]),
            |s| s[i],
        );
        let (f, _) = contact::force(&walls[k], pair.gap, du[n], inp.penalty, state);
        r[n][0] += f[0];
        r[n][1] += f[1];
        if let Some(wf) = wall_force.as_deref_mut() {
            wf[k][0] += f[0];
            wf[k][1] += f[1];
        }
    }
}

/// Adds the constraint points' penalty forces at `du` to `r`: at each
/// point b, on each held component c, f = −α (Σ_a N_a(x_b) Δu_a,c − ū_b,c)
/// spread to the nodes by N_a(x_b); `reactions`, when given, receives each
/// group's sum (the support's force on the body).
pub fn add_points(
    inp: &StepInputs,
    du: &[[f64; 2]],
    r: &mut [[f64; 2]],
    mut reactions: Option<&mut [[f64; 2]]>,
) {
    for (p, target) in inp.model.constraints.points.iter().zip(inp.point_target) {
        for c in 0..2 {
            if p.fix & (1 << c) == 0 {
                continue;
            }
            let u: f64 = p
                .nodes
                .iter()
                .zip(&p.n)
                .map(|(&a, &w)| w * du[a as usize][c])
                .sum();
            let f = -inp.point_penalty * (u - target[c]);
            for (&a, &w) in p.nodes.iter().zip(&p.n) {
                r[a as usize][c] += w * f;
            }
            if let Some(re) = reactions.as_deref_mut() {
                re[p.group as usize][c] += f;
            }
        }
    }
}

/// Each pair's state under Coulomb's law at `du`.
pub fn natural_states(inp: &StepInputs, du: &[[f64; 2]], states: &mut Vec<ContactState>) {
    let walls = &inp.model.walls.list;
    states.clear();
    states.extend(
        inp.pairs
            .iter()
            .map(|p| contact::natural_state(&walls[p.wall as usize], p.gap, du[p.node as usize])),
    );
}

/// The Jacobian's sparsity for one step, in compressed columns: node b's
/// two columns hold rows 2a, 2a + 1 for every node a a particle couples
/// with b (`adj`, sorted), so entry (2a + i, 2b + k) sits at
/// `col_ptr[2b + k] + 2 j + i`, j the position of a in b's list.
pub struct Pattern {
    pub symbolic: SymbolicSparseColMat<usize>,
    pub lu: SymbolicLu<usize>,
    /// Per active node b: its neighbours' ids, `adj[adj_start[b]..adj_start[b + 1]]`.
    pub adj_start: Vec<usize>,
    pub adj: Vec<u32>,
    pub nnz: usize,
}

impl Pattern {
    /// The structure of this step's Jacobian; `previous`, the last step's,
    /// is kept (with its symbolic LU, the dearer part) when the couplings
    /// are the same. Fails only when faer cannot build the structure (out
    /// of memory).
    pub fn new(
        cache: &ShapeCache,
        dofs: &Dofs,
        particles: usize,
        points: &[ConstraintPoint],
        previous: Option<Pattern>,
    ) -> Result<Pattern, Fault> {
        let fail = |_| Fault {
            particle: None,
            kind: FaultKind::NonFinite {
                field: "Jacobian structure",
            },
        };
        let mut pairs: Vec<u64> = Vec::new();
        let stencils = (0..particles)
            .map(|p| cache.particle(p).0)
            .chain(points.iter().map(|p| &p.nodes[..]));
        for nodes in stencils {
            for &b in nodes {
                let ib = dofs.id[b as usize];
                for &a in nodes {
                    let ia = dofs.id[a as usize];
                    if ia != NO_DOF && ib != NO_DOF {
                        pairs.push(((ib as u64) << 32) | ia as u64);
                    }
                }
            }
        }
        pairs.par_sort_unstable();
        pairs.dedup();
        let n = dofs.active;
        let mut adj_start = vec![0usize; n + 1];
        for &pr in &pairs {
            adj_start[(pr >> 32) as usize + 1] += 1;
        }
        for b in 0..n {
            adj_start[b + 1] += adj_start[b];
        }
        let adj: Vec<u32> = pairs.iter().map(|&pr| pr as u32).collect();
        if let Some(prev) = previous {
            if prev.adj_start == adj_start && prev.adj == adj {
                return Ok(prev);
            }
        }
        let mut col_ptr = Vec::with_capacity(2 * n + 1);
        let mut row_idx = Vec::with_capacity(4 * adj.len());
        for b in 0..n {
            let list = &adj[adj_start[b]..adj_start[b + 1]];
            for _k in 0..2 {
                col_ptr.push(row_idx.len());
                for &a in list {
                    row_idx.push(2 * a as usize);
                    row_idx.push(2 * a as usize + 1);
                }
            }
        }
        col_ptr.push(row_idx.len());
        let nnz = row_idx.len();
        let symbolic = SymbolicSparseColMat::new_checked(2 * n, 2 * n, col_ptr, None, row_idx);
        let lu = SymbolicLu::try_new(symbolic.as_ref()).map_err(fail)?;
        Ok(Pattern {
            symbolic,
            lu,
            adj_start,
            adj,
            nnz,
        })
    }

    /// Index in the values of entry (2a + i, 2b + k), a and b active ids.
    #[inline]
    pub fn slot(&self, a: u32, b: u32, i: usize, k: usize) -> usize {
        let (s, e) = (self.adj_start[b as usize], self.adj_start[b as usize + 1]);
        let j = self.adj[s..e]
            .binary_search(&a)
            .expect("every coupled pair is in the pattern");
        // Column 2b starts at 4 s; column 2b + 1 after its 2 (e − s) rows.
        4 * s + k * 2 * (e - s) + 2 * j + i
    }
}

/// Per active node: the particles whose support holds it, each with the
/// node's position in the particle's list (`ShapeCache::particle`).
#[derive(Debug, Clone, Default)]
pub struct Incidence {
    start: Vec<usize>,
    entries: Vec<(u32, u32)>,
}

impl Incidence {
    pub fn new(cache: &ShapeCache, dofs: &Dofs, particles: usize) -> Incidence {
        let mut start = vec![0usize; dofs.active + 1];
        for p in 0..particles {
            for &n in cache.particle(p).0 {
                let id = dofs.id[n as usize];
                if id != NO_DOF {
                    start[id as usize + 1] += 1;
                }
            }
        }
        for b in 0..dofs.active {
            start[b + 1] += start[b];
        }
        let mut next = start.clone();
        let mut entries = vec![(0, 0); start[dofs.active]];
        for p in 0..particles {
            for (k, &n) in cache.particle(p).0.iter().enumerate() {
                let id = dofs.id[n as usize];
                if id != NO_DOF {
                    entries[next[id as usize]] = (p as u32, k as u32);
                    next[id as usize] += 1;
                }
            }
        }
        Incidence { start, entries }
    }

    /// (particle, position of the node in its list) for active node `id`.
    #[inline]
    pub fn of(&self, id: usize) -> &[(u32, u32)] {
        &self.entries[self.start[id]..self.start[id + 1]]
    }
}

/// Fills `values` (the `Pattern`'s slots) with the Jacobian at `du`:
/// particles' stiffness and inertia, walls' contact stiffness (each pair
/// under its `states` entry), and the identity on held components.
pub fn jacobian(
    inp: &StepInputs,
    pattern: &Pattern,
    du: &[[f64; 2]],
    incidence: &Incidence,
    iterates: &[ParticleIterate],
    states: &[ContactState],
    values: &mut Vec<f64>,
) -> Result<(), Fault> {
    values.clear();
    values.resize(pattern.nnz, 0.0);
    let inertia = inp.newmark.accel_slope();
    // N_I N_K (consistent) or N_I on the diagonal (lumped).
    let lumped = inp.lumped_mass;
    let mass_weight = |na: f64, nb: f64, same: bool| {
        if !lumped {
            na * nb
        } else if same {
            na
        } else {
            0.0
        }
    };
    // A = ∂P/∂ΔF per particle, in parallel; then the columns in parallel.
    let tangents: Result<Vec<[[f64; 4]; 4]>, Fault> = iterates
        .par_iter()
        .enumerate()
        .with_min_len(64)
        .map(|(p, it)| {
            piola_tangent(inp.model.material_of(p), it, &inp.start[p]).map_err(|k| Fault::at(p, k))
        })
        .collect();
    let tangents = tangents?;
    let dofs = inp.dofs;
    // Node b's two columns are one run of `values`; each is summed over
    // the particles that touch b, in particle order (so the sum does not
    // depend on the threads).
    let mut columns: Vec<&mut [f64]> = Vec::with_capacity(dofs.active);
    let mut rest = values.as_mut_slice();
    for b in 0..dofs.active {
        let len = 4 * (pattern.adj_start[b + 1] - pattern.adj_start[b]);
        let (col, r) = rest.split_at_mut(len);
        columns.push(col);
        rest = r;
    }
    columns
        .into_par_iter()
        .enumerate()
        .with_min_len(16)
        .for_each(|(ib, col)| {
            let list = &pattern.adj[pattern.adj_start[ib]..pattern.adj_start[ib + 1]];
            let col_len = 2 * list.len();
            for &(p, kb) in incidence.of(ib) {
                let p = p as usize;
                let a = &tangents[p];
                let (nodes, w) = inp.cache.particle(p);
                let wb = w[kb as usize];
                let (m, vol) = (inp.model.particles.mass[p], inp.volume[p]);
                // A ∇N_b, per (i, J) and k.
                let mut ab = [[0.0; 2]; 4];
                for (row, abr) in a.iter().zip(ab.iter_mut()) {
                    for (k, v) in abr.iter_mut().enumerate() {
                        *v = row[2 * k] * wb[1] + row[2 * k + 1] * wb[2];
                    }
                }
                for (&na, wa) in nodes.iter().zip(w) {
                    let ia = dofs.id[na as usize];
                    if ia == NO_DOF {
                        continue;
                    }
                    let j = list
                        .binary_search(&ia)
                        .expect("every coupled pair is in the pattern");
                    let inertia_ab = m * inertia * mass_weight(wa[0], wb[0], ia as usize == ib);
                    for k in 0..2 {
                        for i in 0..2 {
                            let mut v = vol * (wa[1] * ab[2 * i][k] + wa[2] * ab[2 * i + 1][k]);
                            if i == k {
                                v += inertia_ab;
                            }
                            col[k * col_len + 2 * j + i] += v;
                        }
                    }
                }
            }
        });
    let walls = &inp.model.walls.list;
    for (pair, &state) in inp.pairs.iter().zip(states) {
        let n = pair.node as usize;
        let id = dofs.id[n];
        let (_, dk) = contact::force(
            &walls[pair.wall as usize],
            pair.gap,
            du[n],
            inp.penalty,
            state,
        );
        for i in 0..2 {
            for c in 0..2 {
                values[pattern.slot(id, id, i, c)] += dk[2 * i + c];
            }
        }
    }
    // Constraint points: α N_a N_b on each held component.
    for p in &inp.model.constraints.points {
        for (&a, &wa) in p.nodes.iter().zip(&p.n) {
            let ia = dofs.id[a as usize];
            if ia == NO_DOF {
                continue;
            }
            for (&b, &wb) in p.nodes.iter().zip(&p.n) {
                let ib = dofs.id[b as usize];
                if ib == NO_DOF {
                    continue;
                }
                for c in 0..2 {
                    if p.fix & (1 << c) != 0 {
                        values[pattern.slot(ia, ib, c, c)] += inp.point_penalty * wa * wb;
                    }
                }
            }
        }
    }
    // Held components: identity rows and columns.
    for (n, &id) in dofs.id.iter().enumerate() {
        if id == NO_DOF || dofs.held[n] == 0 {
            continue;
        }
        let s = pattern.adj_start[id as usize];
        let e = pattern.adj_start[id as usize + 1];
        for c in 0..2 {
            if dofs.held[n] & (1 << c) == 0 {
                continue;
            }
            // Column 2 id + c, then row 2 id + c in every neighbour's columns.
            for jj in s..e {
                let nb = pattern.adj[jj];
                for i in 0..2 {
                    values[pattern.slot(nb, id, i, c)] = 0.0;
                    values[pattern.slot(id, nb, c, i)] = 0.0;
                }
            }
            values[pattern.slot(id, id, c, c)] = 1.0;
        }
    }
    Ok(())
}
