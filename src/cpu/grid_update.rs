//! Stage `grid_update`, in two passes around the force computation.
//! `wall_touch` (walls only, before `predict`): per node, the weight S_I of
//! the particles in contact with a wall (their domain reaches past its
//! contact line), and T_I, the same with the weights their friction acts
//! with (at the wall's line for linear shapes).
//! `predict`: nodal velocity from the scattered momentum, v_I = q_I / m_I,
//! then the Dirichlet conditions (fixed components set to the
//! constraint's prescribed velocity at the step's end, zero by default).
//! `wall_contact` (walls only, before `correct`): the walls' forces at the
//! contact points, the particles in contact: a penalty normal force with
//! some damping, and Coulomb friction capped by it that stops the slip of
//! the body at the point (docs/methods.md, "Walls"); onto the nodes with
//! the particle's weights (the preload and, for linear shapes, the
//! friction with the weights at the wall's line), and into the walls'
//! reactions.
//! `correct`: the walls' forces added to f_I, reactions on fixed nodes,
//! their force components zeroed, then v_I += γ Δt f_I / m_I (NPC
//! corrector; FE is γ = 1: the nodal momentum update p_I += Δt f_I of
//! Zhang et al.). Fixed components keep their prescribed value: a
//! constraint wins over a wall.
//! With `solver.local_damping` α > 0 (Cundall), `correct` first takes
//! α |f_i| sign(v_i) off each component of the unbalanced force of a node
//! with mass (the walls' forces included), v_I the nodal velocity it is
//! about to correct (the predicted one), before the velocity update, so
//! the nodes and the particles' FLIP update (`g2p`) feel the damped force.
//! Only the walls that act in the step (`Wall::active_at`: a gate's
//! `appear_at` ≤ t < `remove_at`) are in contact.
//! GPU twins: `shaders/grid_update.wgsl` (built without and with
//! `CORRECT`), `shaders/wall_touch.wgsl` and `shaders/wall_contact.wgsl`.

use super::stage_inputs::ShapeCache;
use crate::model::shape::Shape;
use crate::model::walls::{
    self, CONTACT_FRICTION, CONTACT_STICK, STICK_MU, WALL_DAMPING, face_weight, half_width,
    wall_depth,
};
use crate::model::{ConstraintGroup, FIX_X, FIX_Y, Grid, Walls};
use rayon::prelude::*;

pub use crate::model::MASS_EPS_REL;

#[inline]
fn zero_fixed(v: &mut [f64], fix: u8) {
    if fix & FIX_X != 0 {
        v[0] = 0.0;
    }
    if fix & FIX_Y != 0 {
        v[1] = 0.0;
    }
}

/// Cundall's non-viscous local damping of a nodal force `f` (N) at nodal
/// velocity `v` (m/s): f_i − α |f_i| sign(v_i) per component, sign(0) = 0
/// (WGSL's `sign`). It opposes the motion by a share of the unbalanced
/// force, whatever the frequency, and vanishes at equilibrium (f = 0) and
/// at rest (v = 0).
#[inline]
pub fn local_damping(f: [f64; 2], v: [f64; 2], alpha: f64) -> [f64; 2] {
    let sign = |x: f64| {
        if x > 0.0 {
            1.0
        } else if x < 0.0 {
            -1.0
        } else {
            0.0
        }
    };
    [
        f[0] - alpha * f[0].abs() * sign(v[0]),
        f[1] - alpha * f[1].abs() * sign(v[1]),
    ]
}

/// `walls::contact_spring` of particle `p` on wall `k`, read from `pt`:
/// (spring force, preload), N per unit thickness.
#[inline]
fn contact_spring(p: usize, k: usize, pt: &ContactParticles, walls: &Walls) -> (f64, f64) {
    walls::contact_spring(
        walls,
        p,
        k,
        pt.x[p],
        pt.mass[p],
        pt.rho[p],
        pt.stress[p],
        pt.gravity,
    )
}

/// What the contact reads of the particles: positions (m), masses (kg
/// per unit thickness), densities (kg/m³), stresses (Pa, for the
/// preload) and the scene's full gravity (m/s², zero without).
pub struct ContactParticles<'a> {
    pub x: &'a [[f64; 2]],
    pub mass: &'a [f64],
    pub rho: &'a [f64],
    pub stress: &'a [[f64; 3]],
    pub v: &'a [[f64; 2]],
    pub gravity: [f64; 2],
    /// The shape and grid by which the preload's weights at the wall's
    /// line are evaluated exactly (`LineWeights`), for B-splines; `None`
    /// keeps the first-order `face_weight`.
    pub line: Option<(&'a Shape, &'a Grid)>,
}

/// Most nodes of a B-spline's support (cubic: 4 × 4).
const LINE_NODES: usize = 16;

/// The nodes and weights N_I(x_p − d n) of a contact's point on the wall's
/// line, evaluated by the shape itself (B-splines; `ContactParticles::line`).
/// Fixed-size, so that a step allocates nothing (tests/no_alloc.rs).
struct LineWeights {
    nodes: [u32; LINE_NODES],
    w: [[f64; 3]; LINE_NODES],
    len: usize,
}

impl LineWeights {
    fn new(line: Option<(&Shape, &Grid)>) -> Self {
        assert!(
            line.is_none_or(|(s, _)| s.max_nodes() <= LINE_NODES),
            "line weights hold B-spline supports of at most {LINE_NODES} nodes"
        );
        LineWeights {
            nodes: [0; LINE_NODES],
            w: [[0.0; 3]; LINE_NODES],
            len: 0,
        }
    }

    /// Evaluates the weights at the point `d` (m) behind `x` along `n`,
    /// in the field of the particle whose first node is `first` (contact
    /// pairs stack a field per body: `cpu::contact::offset_nodes`); false
    /// when there is no shape to evaluate (or it fails there).
    fn at(
        &mut self,
        line: Option<(&Shape, &Grid)>,
        first: u32,
        x: [f64; 2],
        n: [f64; 2],
        d: f64,
    ) -> bool {
        let Some((shape, grid)) = line else {
            return false;
        };
        let xl = [x[0] - d * n[0], x[1] - d * n[1]];
        match shape.eval(grid, xl, &mut [0.0; 2], &mut self.nodes, &mut self.w) {
            Ok(k) => {
                let per_field = grid.n_nodes() as u32;
                let off = first / per_field * per_field;
                for node in &mut self.nodes[..k] {
                    *node += off;
                }
                self.len = k;
                true
            }
            Err(_) => false,
        }
    }

    fn iter(&self) -> impl Iterator<Item = (usize, f64)> + '_ {
        self.nodes[..self.len]
            .iter()
            .zip(&self.w[..self.len])
            .map(|(&n, w)| (n as usize, w[0]))
    }
}

/// Per node, `touch[n] = [S_I, T_I]`: the contact weight S_I = Σ_p N_Ip
/// over the particles in contact with a wall (`contact_spring` > 0; a
/// particle in contact with two walls counts twice), and the friction's
/// T_I = Σ_p F_Ip over the same contacts, F_Ip the weights the contact's
/// friction goes to the nodes with (`friction_weight`: at the wall's line
/// for linear shapes, else N_Ip), by which `wall_contact` sizes the
/// friction. Only the walls that act in the step
/// starting at `t` (s) count (`Wall::active_at`), so a removed gate, or
/// one not there yet, is nowhere in contact. With preloads
/// (`Walls::preload`; `pre_force` is empty without), each contact's
/// preload P n onto the nodes at the wall's line (`face_weight`), into
/// `pre_force`: the load the walls carry whatever the body does, which
/// `wall_contact` counts in the body's velocity before it decides the
/// rest (else a stick floor's friction at a corner would also take up
/// the side wall's preload). `touch` and `pre_force` are zeroed first
/// (their GPU twins by `clear_grid`).
pub fn wall_touch(
    cache: &ShapeCache,
    pt: &ContactParticles,
    walls: &Walls,
    t: f64,
    touch: &mut [[f64; 2]],
    pre_force: &mut [[f64; 2]],
) {
    touch.fill([0.0; 2]);
    pre_force.fill([0.0; 2]);
    let fit_on = walls.fit_at(t);
    let mut lw = LineWeights::new(pt.line);
    for p in 0..pt.x.len() {
        let (nodes, w) = cache.particle(p);
        let lp = half_width(pt.mass[p], pt.rho[p]);
        let mut count = 0;
        for (k, wl) in walls.list.iter().enumerate() {
            if !wl.active_at(t) {
                continue;
            }
            let (spring, pre) = contact_spring(p, k, pt, walls);
            if spring <= 0.0 {
                continue;
            }
            count += 1;
            let d = wall_depth(pt.x[p], lp, wl);
            let on_line = line_weights_positive(w, wl.normal, d);
            for (&n, wk) in nodes.iter().zip(w) {
                touch[n as usize][1] += friction_weight(wk, wl.normal, d, on_line);
            }
            if pre > 0.0
                && lw.at(
                    pt.line,
                    nodes.first().copied().unwrap_or(0),
                    pt.x[p],
                    wl.normal,
                    d,
                )
            {
                for (n, wn) in lw.iter() {
                    pre_force[n][0] += pre * wn * wl.normal[0];
                    pre_force[n][1] += pre * wn * wl.normal[1];
                }
            } else if pre > 0.0 {
                for (&n, wk) in nodes.iter().zip(w) {
                    let f = pre * face_weight(wk, wl.normal, d);
                    pre_force[n as usize][0] += f * wl.normal[0];
                    pre_force[n as usize][1] += f * wl.normal[1];
                }
            }
            // The fit to the discrete reaction (`Walls::pre_fit`; empty
            // where the line's weights already give it).
            if pre > 0.0 && fit_on {
                for (&n, wk) in nodes.iter().zip(w) {
                    let a = walls.pre_fit[n as usize];
                    pre_force[n as usize][0] += pre * wk[0] * a[0];
                    pre_force[n as usize][1] += pre * wk[0] * a[1];
                }
            }
        }
        if count == 0 {
            continue;
        }
        for (&n, wk) in nodes.iter().zip(w) {
            touch[n as usize][0] += count as f64 * wk[0];
        }
    }
}

/// Whether the weights at the wall's line (`face_weight`) of a particle
/// with weights `wt` ([N, ∇N] per node), at distance `d` (m) from the
/// line along `n`, are all non-negative (to `LINE_WEIGHT_EPS`): always for linear
/// shapes while the line is in the particle's cell; LME's and the
/// B-splines' wider stencils extrapolate to negative weights on the nodes
/// away from the line. The friction acts on the line only where they are
/// (docs/methods.md, "Walls": with negative weights the geostatic LME
/// column moved at 1.1e-2 m/s).
#[inline]
fn line_weights_positive(wt: &[[f64; 3]], n: [f64; 2], d: f64) -> bool {
    wt.iter()
        .all(|wk| face_weight(wk, n, d) >= -LINE_WEIGHT_EPS)
}

/// The weight of a node in a contact's friction: at the wall's line
/// (`face_weight`) where the line's weights are all non-negative
/// (`on_line`, from `line_weights_positive`), else the particle's N.
#[inline]
fn friction_weight(wk: &[f64; 3], n: [f64; 2], d: f64, on_line: bool) -> f64 {
    if on_line {
        face_weight(wk, n, d)
    } else {
        wk[0]
    }
}

/// Round-off allowance of `line_weights_positive`: the weights are O(1)
/// and the GPU twin computes them in f32 (a linear particle's node above
/// the line gets 0 exactly in exact arithmetic, ±1e-7 in f32), so both
/// decide alike.
pub const LINE_WEIGHT_EPS: f64 = 1e-6;

/// The walls' forces at their contact points: every particle in contact
/// with a wall gets a normal force F_n = k pen 2 l_p (penalty) plus its
/// preload (`contact_spring`), less a damping of its approach, and a
/// tangential force that stops the particle's slip (stick), capped by
/// μ F_n (friction), or none (slip); the force goes to the particle's
/// nodes with its weights, into `wall_force`, and to the wall's reaction.
/// The damping reads the body's velocity at the particle, corrected
/// without the walls, Σ N (v_I + γΔt f_I / m_I); the friction the
/// particle's next velocity without the walls, v_p + `slip_dt` Σ N f_I /
/// m_I (its slip, v_t, is what must stop: a particle that the nodes' PIC
/// velocity holds still can still creep by its own), and the tangential
/// force that stops it is −v_t / w_t with
/// w_t = `slip_dt` Σ N_I T_I / m_I (T_I from `wall_touch`: the friction's
/// weights of every contact, so w_t is the change of the particle's
/// velocity per unit friction when its neighbours in contact pull alike,
/// with the weights the friction really goes to the nodes with; `slip_dt`
/// the time over which the particles feel a nodal force, (2 − γ)Δt for
/// NPC, Δt for FE and MUSL). The damping's w = γΔt Σ N_I S_I / m_I
/// (`gamma_dt`; S_I from `wall_touch`, the normal force goes with N). With preloads,
/// the body's velocity counts the walls' preloads (`pre_force`, from
/// `wall_touch`). Only the walls that act in the step
/// starting at `t` (s) push (`Wall::active_at`). The preload's share of
/// F_n acts where the wall's traction does, on the wall's line, at
/// x_p − d n (d from `wall_depth`):
/// it goes to the nodes with N_I − d n·∇N_I (the weights there, to first
/// order; exact for linear shapes across the wall's row of cells), so a
/// geostatic body's boundary nodes get the load their own forces lack,
/// not a share of it spread a cell into the body. The friction acts
/// there too, where those weights have no negative part
/// (`line_weights_positive`: linear shapes), so a rolling body's torque
/// about its contact is gravity's alone; elsewhere at the particle.
#[allow(clippy::too_many_arguments)]
pub fn wall_contact(
    cache: &ShapeCache,
    pt: &ContactParticles,
    mv: &[[f64; 3]],
    force: &[[f64; 2]],
    walls: &Walls,
    t: f64,
    touch: &[[f64; 2]],
    pre_force: &[[f64; 2]],
    wall_force: &mut [[f64; 2]],
    wall_r: &mut [[f64; 2]],
    gamma_dt: f64,
    slip_dt: f64,
    mass_eps: f64,
) {
    wall_force.fill([0.0; 2]);
    for r in wall_r.iter_mut() {
        *r = [0.0; 2];
    }
    let fit_on = walls.fit_at(t);
    let mut lw = LineWeights::new(pt.line);
    for p in 0..pt.x.len() {
        let lp = half_width(pt.mass[p], pt.rho[p]);
        for (k, wl) in walls.list.iter().enumerate() {
            if !wl.active_at(t) {
                continue;
            }
            let (spring, pre) = contact_spring(p, k, pt, walls);
            if spring <= 0.0 {
                continue;
            }
            let (nodes, wt) = cache.particle(p);
            // v: the body's corrected velocity at the particle (for the
            // damping); vp: the particle's own next velocity (for the
            // friction); both without the walls' contact forces, with
            // their preloads.
            let (mut v, mut w, mut wf, mut w_own) = ([0.0; 2], 0.0, 0.0, 0.0);
            let mut vp = pt.v[p];
            for (&n, wk) in nodes.iter().zip(wt) {
                let node = &mv[n as usize];
                if node[0] > mass_eps {
                    let mut f = force[n as usize];
                    if let Some(pf) = pre_force.get(n as usize) {
                        f = [f[0] + pf[0], f[1] + pf[1]];
                    }
                    v[0] += wk[0] * (node[1] + gamma_dt * f[0] / node[0]);
                    v[1] += wk[0] * (node[2] + gamma_dt * f[1] / node[0]);
                    vp[0] += wk[0] * slip_dt * f[0] / node[0];
                    vp[1] += wk[0] * slip_dt * f[1] / node[0];
                    w += wk[0] * touch[n as usize][0] / node[0];
                    wf += wk[0] * touch[n as usize][1] / node[0];
                    w_own += wk[0] * wk[0] / node[0];
                }
            }
            if w <= 0.0 {
                continue;
            }
            // S_I counts this contact's own weights (S_I ≥ N_Ip), so
            // w ≥ Σ N²/m; but `wall_touch` decided contact before the
            // stress update, and a preloaded particle whose spring crosses
            // zero in between is in contact here without its weights in S:
            // w then held only its neighbours' tails (8e-10 against 8e-6)
            // and the damping's ζ v_n / w kicked it off the wall at 130 m/s
            // (LME granular collapse, docs/methods.md "Granular collapse:
            // runs that stop").
            w = w.max(w_own);
            w *= gamma_dt;
            let nrm = wl.normal;
            let vn = v[0] * nrm[0] + v[1] * nrm[1];
            let fnorm = (spring - WALL_DAMPING * vn / w).max(0.0);
            let vpn = vp[0] * nrm[0] + vp[1] * nrm[1];
            let vt = [vp[0] - vpn * nrm[0], vp[1] - vpn * nrm[1]];
            let mu = match wl.contact {
                CONTACT_STICK => STICK_MU,
                CONTACT_FRICTION => wl.mu,
                _ => 0.0,
            };
            // Coulomb: the force that stops the particle's slip, at most
            // μ F_n. The particle feels it over `slip_dt` (NPC: Δt in v_p
            // and (1 − γ)Δt more in the next predictor), so that is the
            // step it is sized for. Sized on the corrected nodal velocity
            // over γΔt instead, the stick loop's gain was (2 − γ)/γ = 3 and
            // a slip grew (the geostatic column's bottom row: from 1e-16
            // to 1 m/s in 100 steps). And with the weights it acts with
            // (T_I): sized with the particle's (S_I) while it acts on the
            // line, a stick loop's gain was about 1.28, which left the
            // held particles a steady slip against their load and a
            // stick-held slab crept under a block (docs/methods.md,
            // "Walls"). A point whose nodes carry no friction weight (T
            // is never negative beyond round-off) falls back on S.
            let ws = slip_dt * if wf > 0.0 { wf } else { w / gamma_dt };
            let mut ft = [-vt[0] / ws, -vt[1] / ws];
            let mag = ft[0].hypot(ft[1]);
            let cap = mu * fnorm;
            if mag > cap {
                ft = [ft[0] * cap / mag, ft[1] * cap / mag];
            }
            let fw = [fnorm * nrm[0] + ft[0], fnorm * nrm[1] + ft[1]];
            wall_r[k][0] += fw[0];
            wall_r[k][1] += fw[1];
            // The preload's share and the friction at the wall's line, the
            // rest (the penalty and the damping) at the particle. The
            // friction acts at the contact (a rolling body's torque about
            // its contact is then gravity's alone), where the line's
            // weights are a partition of unity without negative parts
            // (`line_weights_positive`), else at the particle.
            let f_pre = pre.min(fnorm);
            let d = wall_depth(pt.x[p], lp, wl);
            let ft_line = if line_weights_positive(wt, nrm, d) {
                ft
            } else {
                [0.0; 2]
            };
            let exact = f_pre > 0.0
                && lw.at(
                    pt.line,
                    nodes.first().copied().unwrap_or(0),
                    pt.x[p],
                    nrm,
                    d,
                );
            if exact {
                for (n, wn) in lw.iter() {
                    wall_force[n][0] += wn * f_pre * nrm[0];
                    wall_force[n][1] += wn * f_pre * nrm[1];
                }
            }
            let f_at = [
                fw[0] - f_pre * nrm[0] - ft_line[0],
                fw[1] - f_pre * nrm[1] - ft_line[1],
            ];
            // The preload's fit to the body's discrete reaction
            // (`Walls::pre_fit`) goes with the preload it carries now.
            if f_pre > 0.0 && fit_on {
                for (&n, wk) in nodes.iter().zip(wt) {
                    let a = walls.pre_fit[n as usize];
                    let f = [wk[0] * f_pre * a[0], wk[0] * f_pre * a[1]];
                    wall_force[n as usize][0] += f[0];
                    wall_force[n as usize][1] += f[1];
                    wall_r[k][0] += f[0];
                    wall_r[k][1] += f[1];
                }
            }
            let f_pre = if exact { 0.0 } else { f_pre };
            for (&n, wk) in nodes.iter().zip(wt) {
                let face = face_weight(wk, nrm, d);
                let o = &mut wall_force[n as usize];
                o[0] += wk[0] * f_at[0] + face * (f_pre * nrm[0] + ft_line[0]);
                o[1] += wk[0] * f_at[1] + face * (f_pre * nrm[1] + ft_line[1]);
            }
        }
    }
}

/// Prescribed velocities at time `t` (s) on the fixed components of the
/// groups that move (later groups win on shared nodes); nodes without
/// mass stay at rest.
fn prescribe(mv: &mut [[f64; 3]], groups: &[ConstraintGroup], t: f64, mass_eps: f64) {
    for g in groups.iter().filter(|g| g.moves()) {
        let v = g.velocity_at(t);
        for &n in &g.nodes {
            let node = &mut mv[n as usize];
            if node[0] > mass_eps {
                if g.fix & FIX_X != 0 {
                    node[1] = v[0];
                }
                if g.fix & FIX_Y != 0 {
                    node[2] = v[1];
                }
            }
        }
    }
}

/// `mv[n] = [m, qx, qy]` in, `[m, vx, vy]` out; `t` is the step's end
/// time (s). With contact pairs `mv` holds one copy of the nodes per
/// field, stacked (`model::contact`); `fix` is per grid node.
pub fn predict(mv: &mut [[f64; 3]], fix: &[u8], groups: &[ConstraintGroup], t: f64, mass_eps: f64) {
    for mv in mv.chunks_mut(fix.len()) {
        mv.par_iter_mut()
            .zip(fix)
            .with_min_len(4096)
            .for_each(|(n, &f)| {
                if n[0] > mass_eps {
                    let mut v = [n[1] / n[0], n[2] / n[0]];
                    zero_fixed(&mut v, f);
                    *n = [n[0], v[0], v[1]];
                } else {
                    *n = [n[0], 0.0, 0.0];
                }
            });
        prescribe(mv, groups, t, mass_eps);
    }
}

/// Adds the walls' forces (`wall_contact`'s `wall_force`; empty without
/// walls) to the nodal forces, records reactions per constraint group
/// (the force the support exerts, −f_I on each fixed component), zeroes
/// those components, then corrects the velocities by `gamma_dt` · f/m.
/// `reactions` holds the constraint groups' (the walls' are
/// `wall_contact`'s). `damping` is Cundall's α (`local_damping`; 0 leaves
/// the force as it is).
#[allow(clippy::too_many_arguments)]
pub fn correct(
    mv: &mut [[f64; 3]],
    force: &mut [[f64; 2]],
    fix: &[u8],
    groups: &[ConstraintGroup],
    wall_force: &[[f64; 2]],
    reactions: &mut [[f64; 2]],
    gamma_dt: f64,
    damping: f64,
    mass_eps: f64,
) {
    let n_nodes = fix.len();
    if !wall_force.is_empty() {
        force
            .par_iter_mut()
            .zip(wall_force)
            .with_min_len(4096)
            .for_each(|(f, w)| {
                f[0] += w[0];
                f[1] += w[1];
            });
    }
    for (g, r) in groups.iter().zip(reactions.iter_mut()) {
        *r = [0.0; 2];
        for field in force.chunks(n_nodes) {
            for &n in &g.nodes {
                let f = field[n as usize];
                if g.fix & FIX_X != 0 {
                    r[0] -= f[0];
                }
                if g.fix & FIX_Y != 0 {
                    r[1] -= f[1];
                }
            }
        }
    }
    for (mv, force) in mv.chunks_mut(n_nodes).zip(force.chunks_mut(n_nodes)) {
        mv.par_iter_mut()
            .zip(force.par_iter_mut())
            .zip(fix)
            .with_min_len(4096)
            .for_each(|((n, f), &fx)| {
                zero_fixed(f, fx);
                if n[0] > mass_eps {
                    if damping > 0.0 {
                        *f = local_damping(*f, [n[1], n[2]], damping);
                    }
                    n[1] += gamma_dt * f[0] / n[0];
                    n[2] += gamma_dt * f[1] / n[0];
                }
            });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Wall;
    use crate::model::walls::CONTACT_SLIP;

    /// One particle at `x` on one node (weight 1) of mass 2 kg moving at
    /// `v` (m/s), against a level wall at y = 0 with k = 1e6 Pa/m; the
    /// particle's domain is 0.1 m wide (m / ρ = 0.01). Returns the wall's
    /// force on the material (N per unit thickness).
    fn contact(x: [f64; 2], v: [f64; 2], law: u32, mu: f64) -> [f64; 2] {
        contact_at(x, v, law, mu, 0.0, f64::INFINITY, 0.0)
    }

    /// `contact` against a gate there for `appear_at` ≤ t < `remove_at`,
    /// at time `t` (s).
    fn contact_at(
        x: [f64; 2],
        v: [f64; 2],
        law: u32,
        mu: f64,
        appear_at: f64,
        remove_at: f64,
        t: f64,
    ) -> [f64; 2] {
        let wall = Wall {
            name: "w".into(),
            point: [0.0, 0.0],
            normal: [0.0, 1.0],
            contact: law,
            mu,
            nodes: Vec::new(),
            stiffness: 1e6,
            offset: 0.0,
            appear_at,
            remove_at,
        };
        let walls = Walls {
            list: vec![wall],
            mask: vec![1],
            preload: Vec::new(),
            pre_fit: Vec::new(),
        };
        let mut cache = ShapeCache::new(1, 1);
        cache.count[0] = 1;
        cache.w[0] = [1.0, 0.0, 0.0];
        let (xs, mass, rho) = ([x], [10.0], [1000.0]);
        let pt = ContactParticles {
            x: &xs,
            mass: &mass,
            rho: &rho,
            stress: &[[0.0; 3]],
            v: &[v],
            gravity: [0.0; 2],
            line: None,
        };
        let mut touch = [[0.0; 2]];
        wall_touch(&cache, &pt, &walls, t, &mut touch, &mut []);
        let mv = [[2.0, v[0], v[1]]];
        let (mut wf, mut r) = ([[0.0; 2]], [[0.0; 2]]);
        wall_contact(
            &cache,
            &pt,
            &mv,
            &[[0.0; 2]],
            &walls,
            t,
            &touch,
            &[],
            &mut wf,
            &mut r,
            0.01,
            0.01,
            1e-9,
        );
        assert_eq!(wf[0], r[0]);
        r[0]
    }

    #[test]
    fn penalty_pushes_only_where_the_domain_reaches_past_the_line() {
        // Reaches 0.05 m: 0.01 m past the line at y = 0.04 m.
        assert_eq!(
            contact([0.3, 0.06], [0.0, 0.0], CONTACT_SLIP, 0.0),
            [0.0, 0.0]
        );
        let f = contact([0.3, 0.04], [0.0, 0.0], CONTACT_SLIP, 0.0);
        // k pen 2 l_p = 1e6 · 0.01 · 0.1.
        assert!((f[1] - 1e3).abs() < 1e-9 && f[0] == 0.0, "{f:?}");
        // Approaching at 1 m/s adds the damping: WALL_DAMPING · 1 / w,
        // w = γΔt S/m = 0.01 / 2.
        let f = contact([0.3, 0.04], [0.0, -1.0], CONTACT_SLIP, 0.0);
        assert!((f[1] - 1e3 - WALL_DAMPING * 200.0).abs() < 1e-9, "{f:?}");
    }

    #[test]
    fn friction_is_coulomb_at_the_contact_point_and_stick_stops_the_slip() {
        // Stopping 1 m/s of slip takes 1 / w = 200 N; μ F_n = 0.1 · 1e3.
        let f = contact([0.3, 0.04], [1.0, 0.0], CONTACT_FRICTION, 0.1);
        assert!((f[0] + 100.0).abs() < 1e-9, "{f:?}");
        let f = contact([0.3, 0.04], [1.0, 0.0], CONTACT_FRICTION, 0.5);
        assert!((f[0] + 200.0).abs() < 1e-9, "{f:?}");
        let f = contact([0.3, 0.04], [1.0, 0.0], CONTACT_STICK, 0.0);
        assert!((f[0] + 200.0).abs() < 1e-9, "{f:?}");
        let f = contact([0.3, 0.04], [1.0, 0.0], CONTACT_SLIP, 0.0);
        assert_eq!(f[0], 0.0);
    }

    /// A stick wall's friction, acting on the wall's line, stops the
    /// particle's slip in one step: its step is sized with the weights it
    /// acts with. One particle at y = 0.04 m over a level wall at y = 0
    /// between a node on the line (N 0.75) and one 0.16 m above it (N
    /// 0.25), as a linear shape's column: the line's weights are 1 and 0.
    /// Sized with the particle's weights instead, the friction overshot
    /// the slip by Σ N T/m ÷ Σ N S/m = 0.75/m_0 ÷ (0.5625/m_0 + 0.0625/m_1).
    #[test]
    fn stick_friction_on_the_line_stops_the_slip_in_one_step() {
        let wall = Wall {
            name: "w".into(),
            point: [0.0, 0.0],
            normal: [0.0, 1.0],
            contact: CONTACT_STICK,
            mu: 0.0,
            nodes: Vec::new(),
            stiffness: 1e6,
            offset: 0.0,
            appear_at: 0.0,
            remove_at: f64::INFINITY,
        };
        let walls = Walls {
            list: vec![wall],
            mask: vec![1],
            preload: Vec::new(),
            pre_fit: Vec::new(),
        };
        let mut cache = ShapeCache::new(1, 2);
        cache.count[0] = 2;
        cache.nodes[..2].copy_from_slice(&[0, 1]);
        cache.w[0] = [0.75, 0.0, -1.0 / 0.16];
        cache.w[1] = [0.25, 0.0, 1.0 / 0.16];
        let v = [1.0, 0.0];
        let pt = ContactParticles {
            x: &[[0.3, 0.04]],
            mass: &[10.0],
            rho: &[1000.0],
            stress: &[[0.0; 3]],
            v: &[v],
            gravity: [0.0; 2],
            line: None,
        };
        let mut touch = [[0.0; 2]; 2];
        wall_touch(&cache, &pt, &walls, 0.0, &mut touch, &mut []);
        assert!((touch[0][1] - 1.0).abs() < 1e-12 && touch[1][1].abs() < 1e-12);
        let mv = [[1.5, v[0], v[1]], [4.0, v[0], v[1]]];
        let (mut wf, mut r) = ([[0.0; 2]; 2], [[0.0; 2]]);
        let slip_dt = 0.015;
        wall_contact(
            &cache,
            &pt,
            &mv,
            &[[0.0; 2]; 2],
            &walls,
            0.0,
            &touch,
            &[],
            &mut wf,
            &mut r,
            0.01,
            slip_dt,
            1e-9,
        );
        // All the friction on the line's node, none on the other.
        assert!(wf[1][0].abs() < 1e-9, "{wf:?}");
        let next = v[0] + slip_dt * (0.75 * wf[0][0] / 1.5 + 0.25 * wf[1][0] / 4.0);
        assert!(next.abs() < 1e-12, "slip left {next}");
    }

    #[test]
    fn gates_push_only_between_their_times() {
        // Pressed 0.01 m into a gate there for 0.1 <= t < 0.5 s.
        let at = |t| contact_at([0.3, 0.04], [0.0, 0.0], CONTACT_SLIP, 0.0, 0.1, 0.5, t);
        assert_eq!(at(0.0), [0.0, 0.0]);
        assert!((at(0.1)[1] - 1e3).abs() < 1e-9);
        assert!((at(0.4999)[1] - 1e3).abs() < 1e-9);
        assert_eq!(at(0.5), [0.0, 0.0]);
    }

    #[test]
    fn local_damping_opposes_motion() {
        // α = 0.5: a force along the motion loses half, one against it
        // grows by half; no motion, no change.
        assert_eq!(local_damping([2.0, -2.0], [1.0, 1.0], 0.5), [1.0, -3.0]);
        assert_eq!(local_damping([2.0, -2.0], [0.0, 0.0], 0.5), [2.0, -2.0]);
        assert_eq!(local_damping([2.0, 0.0], [-1.0, 3.0], 0.5), [3.0, 0.0]);
    }
}
