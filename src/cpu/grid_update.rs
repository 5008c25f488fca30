//! Stage `grid_update`, in two passes around the force computation.
//! `wall_touch` (walls only, before `predict`): the walls each node is in
//! contact with, from where the body is: a node touches wall k when a
//! particle whose domain reaches the wall line holds it in its stencil.
//! `predict`: nodal velocity from the scattered momentum, v_I = q_I / m_I,
//! then the walls' contact rules (each wall the node is behind and
//! touches, in scene order), then the Dirichlet conditions (fixed components set to the
//! constraint's prescribed velocity at the step's end, zero by default):
//! a constraint wins over a wall.
//! `correct`: reactions on fixed nodes, their force components zeroed, then
//! v_I += γ Δt f_I / m_I (NPC corrector; FE is γ = 1: the nodal momentum
//! update p_I += Δt f_I of Zhang et al.); then the walls' rules on the
//! corrected velocity, whose change Δv becomes the wall's force
//! m Δv / (γ Δt), added to f_I (so the particles feel it) and to the wall's
//! reaction. Fixed components keep their prescribed value.
//! With `solver.local_damping` α > 0 (Cundall), `correct` first takes
//! α |f_i| sign(v_i) off each component of the unbalanced force of a node
//! with mass, v_I the nodal velocity it is about to correct (the
//! predicted one), before the velocity update, so the nodes and the
//! particles' FLIP update (`g2p`) feel the damped force.
//! GPU twin: `shaders/grid_update.wgsl` (built without and with `CORRECT`)
//! and `shaders/wall_touch.wgsl`.

use super::stage_inputs::ShapeCache;
use crate::model::walls::{CONTACT_FRICTION, CONTACT_STICK};
use crate::model::{ConstraintGroup, FIX_X, FIX_Y, Wall, Walls};
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

/// A wall's contact rule on a node velocity `v` (m/s), for a node in
/// contact: a separating or resting velocity (v·n ≥ 0) is free under every
/// law; an approaching one loses its normal component, and then stick
/// stops it (no slip where in contact, so a disk can roll: the nodes that
/// lift off behind the contact are released), slip keeps the tangential
/// part, and friction applies Coulomb's law with the normal velocity
/// change Δv_n = −v·n as the impulse per unit mass: a tangential velocity
/// |v_t| ≤ μ Δv_n stops, a larger one loses μ Δv_n along −v_t/|v_t|.
#[inline]
pub fn wall_velocity(v: [f64; 2], normal: [f64; 2], contact: u32, mu: f64) -> [f64; 2] {
    let vn = v[0] * normal[0] + v[1] * normal[1];
    if vn >= 0.0 {
        return v;
    }
    if contact == CONTACT_STICK {
        return [0.0, 0.0];
    }
    let vt = [v[0] - vn * normal[0], v[1] - vn * normal[1]];
    if contact != CONTACT_FRICTION {
        return vt;
    }
    let dvn = -vn;
    let speed = vt[0].hypot(vt[1]);
    if speed <= mu * dvn {
        return [0.0, 0.0];
    }
    let k = 1.0 - mu * dvn / speed;
    [k * vt[0], k * vt[1]]
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

/// The rules of every wall in `mask` (bit k = wall k), in order.
#[inline]
fn walls_velocity(mut v: [f64; 2], mask: u32, walls: &[Wall]) -> [f64; 2] {
    for (k, w) in walls.iter().enumerate() {
        if mask & (1 << k) != 0 {
            v = wall_velocity(v, w.normal, w.contact, w.mu);
        }
    }
    v
}

/// Per node, the bit set of the walls it touches (bit k = wall k): the
/// nodes of the stencil (weight > 0) of every particle p whose domain
/// reaches the wall line, (x_p − point)·n − l_p (|n_x| + |n_y|) ≤ s l_p
/// (s = `WALL_TOUCH_SLACK`), with
/// l_p = ½ sqrt(m_p / ρ_p) the half-width of its (square) domain. A node
/// behind a wall that no touching particle reaches is free: the body is
/// not at the wall there, whatever its velocity (before, every node
/// behind the wall that held mass got the rule, so the patch of about
/// sqrt(2 R h) under a disk dragged on it; docs/methods.md, "Walls").
/// `touch` is zeroed first (its GPU twin is zeroed by `clear_grid`).
/// Only the walls that act in the step starting at `t` (s) are touched
/// (`Wall::active_at`: a gate's `appear_at` ≤ t < `remove_at`), so a
/// removed gate is nowhere in contact.
pub fn wall_touch(
    cache: &ShapeCache,
    x: &[[f64; 2]],
    mass: &[f64],
    rho: &[f64],
    walls: &Walls,
    t: f64,
    touch: &mut [u32],
) {
    touch.fill(0);
    let active = walls
        .list
        .iter()
        .enumerate()
        .fold(0u32, |bits, (k, w)| bits | (u32::from(w.active_at(t)) << k));
    if active == 0 {
        return;
    }
    for p in 0..x.len() {
        let bits = touching_walls(x[p], mass[p], rho[p], &walls.list) & active;
        if bits == 0 {
            continue;
        }
        let (nodes, w) = cache.particle(p);
        for (&n, wk) in nodes.iter().zip(w) {
            if wk[0] > 0.0 {
                touch[n as usize] |= bits;
            }
        }
    }
}

/// Slack of the touch test, relative to the particle's half-width: a
/// domain whose edge lies on the line (a body seeded against a wall with
/// the uniform layout) touches it on both backends, whatever the f32
/// round-off of the GPU's positions (about 1e-7 of the grid's size).
pub const WALL_TOUCH_SLACK: f64 = 1e-3;

/// The walls (bit k = wall k) that the domain of a particle at `x` (m)
/// with mass `m` and density `rho` reaches.
#[inline]
pub fn touching_walls(x: [f64; 2], m: f64, rho: f64, walls: &[Wall]) -> u32 {
    let lp = 0.5 * (m / rho).sqrt();
    let mut bits = 0;
    for (k, w) in walls.iter().enumerate() {
        let d = (x[0] - w.point[0]) * w.normal[0] + (x[1] - w.point[1]) * w.normal[1];
        if d - lp * (w.normal[0].abs() + w.normal[1].abs()) <= WALL_TOUCH_SLACK * lp {
            bits |= 1 << k;
        }
    }
    bits
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
/// time (s); `touch` is `wall_touch`'s (empty without walls). With
/// contact pairs `mv` holds one copy of the nodes per field, stacked
/// (`model::contact`); `fix` and the walls' mask are per grid node.
pub fn predict(
    mv: &mut [[f64; 3]],
    fix: &[u8],
    groups: &[ConstraintGroup],
    walls: &Walls,
    touch: &[u32],
    t: f64,
    mass_eps: f64,
) {
    let wl = &walls.list;
    let n_nodes = fix.len();
    for (field, mv) in mv.chunks_mut(n_nodes).enumerate() {
        let base = field * n_nodes;
        mv.par_iter_mut()
            .zip(fix)
            .enumerate()
            .with_min_len(4096)
            .for_each(|(i, (n, &f))| {
                if n[0] > mass_eps {
                    let mut v = [n[1] / n[0], n[2] / n[0]];
                    if let Some(&mask) = walls.mask.get(i) {
                        let mask = mask & touch[base + i];
                        if mask != 0 {
                            v = walls_velocity(v, mask, wl);
                        }
                    }
                    zero_fixed(&mut v, f);
                    *n = [n[0], v[0], v[1]];
                } else {
                    *n = [n[0], 0.0, 0.0];
                }
            });
        prescribe(mv, groups, t, mass_eps);
    }
}

/// Records reactions per constraint group (the force the support exerts,
/// −f_I on each fixed component), zeroes those components, corrects the
/// velocities by `gamma_dt` · f/m, then applies the walls on the nodes
/// that touch them (`touch`, as in `predict`). `reactions` holds the
/// constraint groups' then the walls'. `damping` is Cundall's α
/// (`local_damping`; 0 leaves the force as it is).
#[allow(clippy::too_many_arguments)]
pub fn correct(
    mv: &mut [[f64; 3]],
    force: &mut [[f64; 2]],
    fix: &[u8],
    groups: &[ConstraintGroup],
    walls: &Walls,
    touch: &[u32],
    reactions: &mut [[f64; 2]],
    gamma_dt: f64,
    damping: f64,
    mass_eps: f64,
) {
    let n_nodes = fix.len();
    let (group_r, wall_r) = reactions.split_at_mut(groups.len());
    for (g, r) in groups.iter().zip(group_r.iter_mut()) {
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
    for r in wall_r.iter_mut() {
        *r = [0.0; 2];
    }
    if walls.is_empty() {
        return;
    }
    // Each wall's velocity change on its nodes, one wall after another in
    // scene order (a node behind two walls gets both), as on the GPU.
    for (node, &t) in touch.iter().enumerate() {
        let i = node % n_nodes;
        let mask = walls.mask[i] & t;
        let n = &mut mv[node];
        if mask == 0 || n[0] <= mass_eps {
            continue;
        }
        let m = n[0];
        let mut v = [n[1], n[2]];
        for (k, w) in walls.list.iter().enumerate() {
            if mask & (1 << k) == 0 {
                continue;
            }
            let mut new = wall_velocity(v, w.normal, w.contact, w.mu);
            // A constraint wins: its components keep their value.
            if fix[i] & FIX_X != 0 {
                new[0] = v[0];
            }
            if fix[i] & FIX_Y != 0 {
                new[1] = v[1];
            }
            let fw = [
                m * (new[0] - v[0]) / gamma_dt,
                m * (new[1] - v[1]) / gamma_dt,
            ];
            wall_r[k][0] += fw[0];
            wall_r[k][1] += fw[1];
            force[node][0] += fw[0];
            force[node][1] += fw[1];
            v = new;
        }
        n[1] = v[0];
        n[2] = v[1];
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::walls::CONTACT_SLIP;

    const N: [f64; 2] = [0.0, 1.0];

    #[test]
    fn stick_stops_approach_and_frees_separation() {
        assert_eq!(
            wall_velocity([1.0, -2.0], N, CONTACT_STICK, 0.0),
            [0.0, 0.0]
        );
        assert_eq!(wall_velocity([1.0, 2.0], N, CONTACT_STICK, 0.0), [1.0, 2.0]);
    }

    #[test]
    fn touch_from_the_particle_domain() {
        let wall = Wall {
            name: "w".into(),
            point: [0.0, 0.0],
            normal: N,
            contact: CONTACT_STICK,
            mu: 0.0,
            nodes: Vec::new(),
            appear_at: 0.0,
            remove_at: f64::INFINITY,
        };
        // Domain 0.1 m wide (m / ρ = 0.01): it reaches the line from 0.05 m.
        let walls = [
            wall.clone(),
            Wall {
                point: [0.0, -1.0],
                ..wall
            },
        ];
        assert_eq!(touching_walls([0.3, 0.05], 10.0, 1000.0, &walls), 1);
        assert_eq!(touching_walls([0.3, 0.05004], 10.0, 1000.0, &walls), 1);
        assert_eq!(touching_walls([0.3, 0.0501], 10.0, 1000.0, &walls), 0);
        assert_eq!(touching_walls([0.3, -0.96], 10.0, 1000.0, &walls), 3);
    }

    #[test]
    fn local_damping_opposes_motion() {
        // α = 0.5: a force along the motion loses half, one against it
        // grows by half; no motion, no change.
        assert_eq!(local_damping([2.0, -2.0], [1.0, 1.0], 0.5), [1.0, -3.0]);
        assert_eq!(local_damping([2.0, -2.0], [0.0, 0.0], 0.5), [2.0, -2.0]);
        assert_eq!(local_damping([2.0, 0.0], [-1.0, 3.0], 0.5), [3.0, 0.0]);
    }

    #[test]
    fn gates_act_between_their_times() {
        let w = Wall {
            name: "gate".into(),
            point: [0.0, 0.0],
            normal: N,
            contact: CONTACT_SLIP,
            mu: 0.0,
            nodes: Vec::new(),
            appear_at: 0.1,
            remove_at: 0.5,
        };
        assert!(!w.active_at(0.0));
        assert!(w.active_at(0.1));
        assert!(w.active_at(0.4999));
        assert!(!w.active_at(0.5));
    }

    #[test]
    fn slip_removes_approach_only() {
        assert_eq!(wall_velocity([1.0, -2.0], N, CONTACT_SLIP, 0.0), [1.0, 0.0]);
        assert_eq!(wall_velocity([1.0, 2.0], N, CONTACT_SLIP, 0.0), [1.0, 2.0]);
    }

    #[test]
    fn friction_is_coulomb() {
        // Δv_n = 2, μ Δv_n = 1: a tangential speed of 3 loses 1, 0.5 stops.
        assert_eq!(
            wall_velocity([3.0, -2.0], N, CONTACT_FRICTION, 0.5),
            [2.0, 0.0]
        );
        assert_eq!(
            wall_velocity([-0.5, -2.0], N, CONTACT_FRICTION, 0.5),
            [0.0, 0.0]
        );
        // Separating: untouched.
        assert_eq!(
            wall_velocity([3.0, 2.0], N, CONTACT_FRICTION, 0.5),
            [3.0, 2.0]
        );
    }
}
