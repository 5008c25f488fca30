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
//!   R = f_ext − f_int − M a + f_contact,
//! and the Jacobian K = −∂R/∂Δu:
//!   K_IK = Σ_p V_p ∇N_I · A · ∇N_K + Σ_p m_p N_I N_K / (β Δt²) + K_contact,
//! with A = ∂P/∂ΔF. Pulled back to the step's start this is exactly the
//! paper's spatial geometric + material stiffness (eqs. 32–34): the same
//! linearisation written in the other configuration.

use crate::cpu::ShapeCache;
use crate::model::Model;
use crate::model::fault::{Fault, FaultKind};
use crate::model::material::Material;
use crate::model::material::increment::{StepState, mul};
use crate::model::walls::{CONTACT_FRICTION, Wall};
use faer::sparse::SymbolicSparseColMat;
use faer::sparse::linalg::solvers::SymbolicLu;
use rayon::prelude::*;

/// Marks a node component that is not an unknown (no mass, or fixed).
pub const NO_DOF: u32 = u32::MAX;

/// Contact penalty stiffness relative to the stiffest material's P-wave
/// modulus (N/m per metre of thickness): a wall node then gives way by
/// about 1e-4 of the strain the contact force would cause in the material.
pub const PENALTY_REL: f64 = 1e4;

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
    pub penalty: f64,
}

/// Nodal residual at the iterate `du` (N per metre of thickness), every
/// node and component, fixed ones included (their residual is minus the
/// support's reaction), with the particle iterates it used. `wall_force`
/// receives each wall's contact force on the material.
pub fn residual(
    inp: &StepInputs,
    du: &[[f64; 2]],
    iterates: &mut [ParticleIterate],
    r: &mut [[f64; 2]],
    wall_force: &mut [[f64; 2]],
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
            |mut acc, (c, its)| {
                for (k, it) in its.iter().enumerate() {
                    let p = c * chunk + k;
                    let (nodes, w) = inp.cache.particle(p);
                    let (m, vol) = (inp.model.particles.mass[p], inp.volume[p]);
                    // Particle acceleration at the step's end (eq. 47).
                    let mut ap = [0.0; 2];
                    if !nw.is_static {
                        for (&n, wk) in nodes.iter().zip(w) {
                            let n = n as usize;
                            let an = nw.accel(du[n], inp.v[n], inp.a[n]);
                            ap[0] += wk[0] * an[0];
                            ap[1] += wk[0] * an[1];
                        }
                    }
                    let b = inp.body[p];
                    for (&n, wk) in nodes.iter().zip(w) {
                        let f = &mut acc[n as usize];
                        for i in 0..2 {
                            let internal = vol * (it.p[2 * i] * wk[1] + it.p[2 * i + 1] * wk[2]);
                            f[i] += wk[0] * m * (b[i] - ap[i]) - internal;
                        }
                    }
                }
                acc
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
    for f in wall_force.iter_mut() {
        *f = [0.0; 2];
    }
    if !inp.model.walls.list.is_empty() {
        for (n, &mask) in inp.model.walls.mask.iter().enumerate() {
            if mask == 0 || inp.dofs.id[n] == NO_DOF {
                continue;
            }
            for (k, wall) in inp.model.walls.list.iter().enumerate() {
                if mask & (1 << k) != 0 {
                    let (f, _) = contact(wall, du[n], inp.penalty);
                    r[n][0] += f[0];
                    r[n][1] += f[1];
                    wall_force[k][0] += f[0];
                    wall_force[k][1] += f[1];
                }
            }
        }
    }
    Ok(())
}

/// A wall's penalty force on a node displaced by `du` into it, and the
/// force's derivative −∂f/∂Δu (2 × 2, row-major). The node is in contact
/// when Δu·n ≤ 0 (it moves further behind the line): the normal force is
/// −k (Δu·n) n; ``friction` adds Coulomb's law on the tangential
/// displacement (stick −k Δu_t up to μ |f_n|, then μ |f_n| against the
/// slip), `slip` nothing. Stick walls are fixed components instead.
pub fn contact(wall: &Wall, du: [f64; 2], k: f64) -> ([f64; 2], [f64; 4]) {
    let n = wall.normal;
    let g = du[0] * n[0] + du[1] * n[1];
    // g = 0 counts as contact (zero force, full stiffness): a node resting
    // on the wall starts each step in the active set, so Newton does not
    // chatter between free fall and the penalty's push-back.
    if g > 0.0 {
        return ([0.0; 2], [0.0; 4]);
    }
    let fnorm = -k * g;
    let mut f = [fnorm * n[0], fnorm * n[1]];
    let mut kt = [
        k * n[0] * n[0],
        k * n[0] * n[1],
        k * n[1] * n[0],
        k * n[1] * n[1],
    ];
    if wall.contact == CONTACT_FRICTION {
        let t = [-n[1], n[0]];
        let s = du[0] * t[0] + du[1] * t[1];
        let stick = k * s.abs() <= wall.mu * fnorm;
        if stick {
            f[0] -= k * s * t[0];
            f[1] -= k * s * t[1];
            for a in 0..2 {
                for b in 0..2 {
                    kt[2 * a + b] += k * t[a] * t[b];
                }
            }
        } else {
            // f_t = −μ k |g| sign(s) t = μ k g sign(s) t.
            let sg = s.signum();
            f[0] += wall.mu * k * g * sg * t[0];
            f[1] += wall.mu * k * g * sg * t[1];
            for a in 0..2 {
                for b in 0..2 {
                    kt[2 * a + b] -= wall.mu * k * sg * t[a] * n[b];
                }
            }
        }
    }
    (f, kt)
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
    /// Fails only when faer cannot build the structure (out of memory).
    pub fn new(cache: &ShapeCache, dofs: &Dofs, particles: usize) -> Result<Pattern, Fault> {
        let fail = |_| Fault {
            particle: None,
            kind: FaultKind::NonFinite {
                field: "Jacobian structure",
            },
        };
        let mut pairs: Vec<u64> = Vec::new();
        for p in 0..particles {
            let (nodes, _) = cache.particle(p);
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

/// Fills `values` (the `Pattern`'s slots) with the Jacobian at `du`:
/// particles' stiffness and inertia, walls' contact stiffness, and the
/// identity on held components.
pub fn jacobian(
    inp: &StepInputs,
    pattern: &Pattern,
    du: &[[f64; 2]],
    iterates: &[ParticleIterate],
    values: &mut Vec<f64>,
) -> Result<(), Fault> {
    values.clear();
    values.resize(pattern.nnz, 0.0);
    let inertia = inp.newmark.accel_slope();
    // A = ∂P/∂ΔF per particle, in parallel; then one ordered scatter.
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
    for (p, a) in tangents.iter().enumerate() {
        let (nodes, w) = inp.cache.particle(p);
        let (m, vol) = (inp.model.particles.mass[p], inp.volume[p]);
        for (&nb, wb) in nodes.iter().zip(w) {
            let ib = dofs.id[nb as usize];
            if ib == NO_DOF {
                continue;
            }
            for (&na, wa) in nodes.iter().zip(w) {
                let ia = dofs.id[na as usize];
                if ia == NO_DOF {
                    continue;
                }
                let base = pattern.slot(ia, ib, 0, 0);
                let col_len = pattern.slot(ia, ib, 0, 1) - base;
                for k in 0..2 {
                    for i in 0..2 {
                        let mut v = 0.0;
                        for big_j in 0..2 {
                            let ga = wa[1 + big_j];
                            v += ga
                                * (a[2 * i + big_j][2 * k] * wb[1]
                                    + a[2 * i + big_j][2 * k + 1] * wb[2]);
                        }
                        v *= vol;
                        if i == k {
                            v += m * wa[0] * wb[0] * inertia;
                        }
                        values[base + k * col_len + i] += v;
                    }
                }
            }
        }
    }
    for (n, &mask) in inp.model.walls.mask.iter().enumerate() {
        let id = dofs.id.get(n).copied().unwrap_or(NO_DOF);
        if mask == 0 || id == NO_DOF {
            continue;
        }
        for (k, wall) in inp.model.walls.list.iter().enumerate() {
            if mask & (1 << k) != 0 {
                let (_, dk) = contact(wall, du[n], inp.penalty);
                for i in 0..2 {
                    for c in 0..2 {
                        values[pattern.slot(id, id, i, c)] += dk[2 * i + c];
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
