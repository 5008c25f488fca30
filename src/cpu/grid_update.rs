//! Stage `grid_update`, in two passes around the force computation.
//! `wall_touch` (walls only, before `predict`): per node, the weight S_I of
//! the particles in contact with a wall (their domain reaches past its
//! contact line).
//! `predict`: nodal velocity from the scattered momentum, v_I = q_I / m_I,
//! then the Dirichlet conditions (fixed components set to the
//! constraint's prescribed velocity at the step's end, zero by default).
//! `wall_contact` (walls only, before `correct`): the walls' forces at the
//! contact points, the particles in contact: a penalty normal force with
//! some damping, and Coulomb friction capped by it that stops the slip of
//! the body at the point (docs/methods.md, "Walls"); onto the nodes with
//! the particle's weights, and into the walls' reactions.
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
use crate::model::walls::{
    CONTACT_FRICTION, CONTACT_STICK, STICK_MU, WALL_DAMPING, half_width, wall_penetration,
};
use crate::model::{ConstraintGroup, FIX_X, FIX_Y, Walls};
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

/// Per node, the contact weight S_I = Σ_p N_Ip over the particles in
/// contact with a wall (`wall_penetration` > 0; a particle in contact
/// with two walls counts twice). Only the walls that act in the step
/// starting at `t` (s) count (`Wall::active_at`), so a removed gate, or
/// one not there yet, is nowhere in contact. `touch` is zeroed first (its
/// GPU twin is zeroed by `clear_grid`).
pub fn wall_touch(
    cache: &ShapeCache,
    x: &[[f64; 2]],
    mass: &[f64],
    rho: &[f64],
    walls: &Walls,
    t: f64,
    touch: &mut [f64],
) {
    touch.fill(0.0);
    for p in 0..x.len() {
        let lp = half_width(mass[p], rho[p]);
        let count = walls
            .list
            .iter()
            .filter(|w| w.active_at(t) && wall_penetration(x[p], lp, w) > 0.0)
            .count();
        if count == 0 {
            continue;
        }
        let (nodes, w) = cache.particle(p);
        for (&n, wk) in nodes.iter().zip(w) {
            touch[n as usize] += count as f64 * wk[0];
        }
    }
}

/// The walls' forces at their contact points: every particle in contact
/// with a wall gets a normal force F_n = k pen 2 l_p (penalty) and a
/// tangential force that stops the slip of the body's velocity at the
/// particle (stick), capped by μ F_n (friction), or none (slip); the force
/// goes to the particle's nodes with its weights, into `wall_force`, and
/// to the wall's reaction. The body's velocity at the particle is the
/// corrected one without the walls, Σ N (v_I + γΔt f_I / m_I), and the
/// tangential force that stops it is −v_t / w with
/// w = γΔt Σ N_I S_I / m_I (S_I from `wall_touch`: the neighbours in
/// contact pull on the same nodes). Only the walls that act in the step
/// starting at `t` (s) push (`Wall::active_at`).
#[allow(clippy::too_many_arguments)]
pub fn wall_contact(
    cache: &ShapeCache,
    x: &[[f64; 2]],
    mass: &[f64],
    rho: &[f64],
    mv: &[[f64; 3]],
    force: &[[f64; 2]],
    walls: &Walls,
    t: f64,
    touch: &[f64],
    wall_force: &mut [[f64; 2]],
    wall_r: &mut [[f64; 2]],
    gamma_dt: f64,
    mass_eps: f64,
) {
    wall_force.fill([0.0; 2]);
    for r in wall_r.iter_mut() {
        *r = [0.0; 2];
    }
    for p in 0..x.len() {
        let lp = half_width(mass[p], rho[p]);
        for (k, wl) in walls.list.iter().enumerate() {
            if !wl.active_at(t) {
                continue;
            }
            let pen = wall_penetration(x[p], lp, wl);
            if pen <= 0.0 {
                continue;
            }
            let (nodes, wt) = cache.particle(p);
            let (mut v, mut w) = ([0.0; 2], 0.0);
            for (&n, wk) in nodes.iter().zip(wt) {
                let node = &mv[n as usize];
                if node[0] > mass_eps {
                    let f = force[n as usize];
                    v[0] += wk[0] * (node[1] + gamma_dt * f[0] / node[0]);
                    v[1] += wk[0] * (node[2] + gamma_dt * f[1] / node[0]);
                    w += wk[0] * touch[n as usize] / node[0];
                }
            }
            if w <= 0.0 {
                continue;
            }
            w *= gamma_dt;
            let nrm = wl.normal;
            let vn = v[0] * nrm[0] + v[1] * nrm[1];
            let fnorm = (wl.stiffness * pen * 2.0 * lp - WALL_DAMPING * vn / w).max(0.0);
            let vt = [v[0] - vn * nrm[0], v[1] - vn * nrm[1]];
            let mu = match wl.contact {
                CONTACT_STICK => STICK_MU,
                CONTACT_FRICTION => wl.mu,
                _ => 0.0,
            };
            // Coulomb: the force that stops the slip, at most μ F_n.
            let mut ft = [-vt[0] / w, -vt[1] / w];
            let mag = ft[0].hypot(ft[1]);
            let cap = mu * fnorm;
            if mag > cap {
                ft = [ft[0] * cap / mag, ft[1] * cap / mag];
            }
            let fw = [fnorm * nrm[0] + ft[0], fnorm * nrm[1] + ft[1]];
            wall_r[k][0] += fw[0];
            wall_r[k][1] += fw[1];
            for (&n, wk) in nodes.iter().zip(wt) {
                let o = &mut wall_force[n as usize];
                o[0] += wk[0] * fw[0];
                o[1] += wk[0] * fw[1];
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
/// time (s); `touch` is `wall_touch`'s (empty without walls).
pub fn predict(mv: &mut [[f64; 3]], fix: &[u8], groups: &[ConstraintGroup], t: f64, mass_eps: f64) {
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
        for &n in &g.nodes {
            let f = force[n as usize];
            if g.fix & FIX_X != 0 {
                r[0] -= f[0];
            }
            if g.fix & FIX_Y != 0 {
                r[1] -= f[1];
            }
        }
    }
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
        };
        let mut cache = ShapeCache::new(1, 1);
        cache.count[0] = 1;
        cache.w[0] = [1.0, 0.0, 0.0];
        let (xs, mass, rho) = ([x], [10.0], [1000.0]);
        let mut touch = [0.0];
        wall_touch(&cache, &xs, &mass, &rho, &walls, t, &mut touch);
        let mv = [[2.0, v[0], v[1]]];
        let (mut wf, mut r) = ([[0.0; 2]], [[0.0; 2]]);
        wall_contact(
            &cache,
            &xs,
            &mass,
            &rho,
            &mv,
            &[[0.0; 2]],
            &walls,
            t,
            &touch,
            &mut wf,
            &mut r,
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
