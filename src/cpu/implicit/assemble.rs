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
use crate::model::fault::{Fault, FaultKind};
use crate::model::material::Material;
use crate::model::material::increment::{StepState, mul};
use crate::model::walls::{CONTACT_FRICTION, Wall};
use faer::sparse::{Argsort, Pair, SymbolicSparseColMat};
use rayon::prelude::*;

/// Marks a node component that is not an unknown (no mass, or fixed).
pub const NO_DOF: u32 = u32::MAX;

/// Contact penalty stiffness relative to the stiffest material's P-wave
/// modulus (N/m per metre of thickness): a wall node then gives way by
/// about 1e-4 of the strain the contact force would cause in the material.
pub const PENALTY_REL: f64 = 1e4;

/// The unknowns of one step: two per node with mass, less fixed components.
#[derive(Debug, Clone, Default)]
pub struct Dofs {
    /// Per node: the equation number of its x and y displacement, or `NO_DOF`.
    pub of: Vec<[u32; 2]>,
    pub count: usize,
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
    pub mass: &'a [f64],
    /// V_p at the step's start (m²).
    pub volume: &'a [f64],
    /// Body force per unit mass at the step's end, load factor applied (m/s²).
    pub body: &'a [[f64; 2]],
    pub material: &'a (dyn Fn(usize) -> &'a Material + Sync),
    pub start: &'a [StepState],
    /// Nodal velocity and acceleration at the step's start.
    pub v: &'a [[f64; 2]],
    pub a: &'a [[f64; 2]],
    pub newmark: Newmark,
    pub dofs: &'a Dofs,
    pub walls: &'a [Wall],
    /// Per node, the walls it is behind (bit k = wall k); empty: none.
    pub wall_mask: &'a [u32],
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
            match particle_iterate((inp.material)(p), df, &inp.start[p]) {
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
                    let (m, vol) = (inp.mass[p], inp.volume[p]);
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
    if !inp.walls.is_empty() {
        for (n, &mask) in inp.wall_mask.iter().enumerate() {
            if mask == 0 || inp.dofs.of[n] == [NO_DOF; 2] {
                continue;
            }
            for (k, wall) in inp.walls.iter().enumerate() {
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
/// when Δu·n < 0 (it moves further behind the line): the normal force is
/// −k (Δu·n) n; ``friction` adds Coulomb's law on the tangential
/// displacement (stick −k Δu_t up to μ |f_n|, then μ |f_n| against the
/// slip), `slip` nothing. Stick walls are fixed components instead.
pub fn contact(wall: &Wall, du: [f64; 2], k: f64) -> ([f64; 2], [f64; 4]) {
    let n = wall.normal;
    let g = du[0] * n[0] + du[1] * n[1];
    if g >= 0.0 {
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

/// The Jacobian's sparsity for one step: every (dof, dof) pair a particle
/// couples, then each wall node's 2 × 2 block, in the order `values` fills.
pub struct Pattern {
    pub symbolic: SymbolicSparseColMat<usize>,
    pub argsort: Argsort<usize>,
    /// Per particle, the first entry of its block of values.
    pub offsets: Vec<usize>,
    /// Wall nodes with unknowns, in the order their blocks follow the particles'.
    pub wall_nodes: Vec<usize>,
    pub len: usize,
}

/// Entries particle `p` contributes, in `values`' order.
fn particle_pairs(cache: &ShapeCache, dofs: &Dofs, p: usize, mut emit: impl FnMut(usize, usize)) {
    let (nodes, _) = cache.particle(p);
    for &a in nodes {
        for &b in nodes {
            let (da, db) = (dofs.of[a as usize], dofs.of[b as usize]);
            for ra in da {
                for cb in db {
                    if ra != NO_DOF && cb != NO_DOF {
                        emit(ra as usize, cb as usize);
                    }
                }
            }
        }
    }
}

impl Pattern {
    pub fn new(
        cache: &ShapeCache,
        dofs: &Dofs,
        particles: usize,
        wall_mask: &[u32],
    ) -> Result<Pattern, faer::sparse::CreationError> {
        let mut pairs = Vec::new();
        let mut offsets = Vec::with_capacity(particles + 1);
        for p in 0..particles {
            offsets.push(pairs.len());
            particle_pairs(cache, dofs, p, |r, c| pairs.push(Pair::new(r, c)));
        }
        offsets.push(pairs.len());
        let mut wall_nodes = Vec::new();
        for (n, &mask) in wall_mask.iter().enumerate() {
            let d = dofs.of[n];
            if mask != 0 && d != [NO_DOF; 2] {
                wall_nodes.push(n);
                for r in d {
                    for c in d {
                        if r != NO_DOF && c != NO_DOF {
                            pairs.push(Pair::new(r as usize, c as usize));
                        }
                    }
                }
            }
        }
        let len = pairs.len();
        let (symbolic, argsort) =
            SymbolicSparseColMat::try_new_from_indices(dofs.count, dofs.count, &pairs)?;
        Ok(Pattern {
            symbolic,
            argsort,
            offsets,
            wall_nodes,
            len,
        })
    }
}

/// Fills `values` (in `Pattern` order) with the Jacobian at `du`.
pub fn jacobian(
    inp: &StepInputs,
    pattern: &Pattern,
    du: &[[f64; 2]],
    iterates: &[ParticleIterate],
    values: &mut Vec<f64>,
) -> Result<(), Fault> {
    values.clear();
    values.resize(pattern.len, 0.0);
    let inertia = inp.newmark.accel_slope();
    let (head, tail) = values.split_at_mut(pattern.offsets[iterates.len()]);
    // Split the particles' part of `values` by particle, in parallel.
    let mut slices: Vec<&mut [f64]> = Vec::with_capacity(iterates.len());
    let mut rest = head;
    for p in 0..iterates.len() {
        let (a, b) = rest.split_at_mut(pattern.offsets[p + 1] - pattern.offsets[p]);
        slices.push(a);
        rest = b;
    }
    let fault = slices
        .into_par_iter()
        .enumerate()
        .with_min_len(64)
        .map(|(p, out)| {
            let it = &iterates[p];
            let a = match piola_tangent((inp.material)(p), it, &inp.start[p]) {
                Ok(a) => a,
                Err(kind) => return Some(Fault::at(p, kind)),
            };
            let (nodes, w) = inp.cache.particle(p);
            let (m, vol) = (inp.mass[p], inp.volume[p]);
            let mut e = 0;
            for (&na, wa) in nodes.iter().zip(w) {
                for (&nb, wb) in nodes.iter().zip(w) {
                    let (da, db) = (inp.dofs.of[na as usize], inp.dofs.of[nb as usize]);
                    for i in 0..2 {
                        for k in 0..2 {
                            if da[i] == NO_DOF || db[k] == NO_DOF {
                                continue;
                            }
                            let ga = [wa[1], wa[2]];
                            let gb = [wb[1], wb[2]];
                            let mut v = 0.0;
                            for big_j in 0..2 {
                                for l in 0..2 {
                                    v += ga[big_j] * a[2 * i + big_j][2 * k + l] * gb[l];
                                }
                            }
                            v *= vol;
                            if i == k {
                                v += m * wa[0] * wb[0] * inertia;
                            }
                            out[e] = v;
                            e += 1;
                        }
                    }
                }
            }
            None
        })
        .reduce(|| None, Fault::first);
    if let Some(f) = fault {
        return Err(f);
    }
    let mut e = 0;
    for &n in &pattern.wall_nodes {
        let mut kt = [0.0; 4];
        for (k, wall) in inp.walls.iter().enumerate() {
            if inp.wall_mask[n] & (1 << k) != 0 {
                let (_, dk) = contact(wall, du[n], inp.penalty);
                for (x, y) in kt.iter_mut().zip(dk) {
                    *x += y;
                }
            }
        }
        let d = inp.dofs.of[n];
        for i in 0..2 {
            for k in 0..2 {
                if d[i] != NO_DOF && d[k] != NO_DOF {
                    tail[e] = kt[2 * i + k];
                    e += 1;
                }
            }
        }
    }
    Ok(())
}
