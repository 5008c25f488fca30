//! Pass `wall_contact` of stage `grid_update` (walls only, before
//! `correct`): the walls' forces at the contact points, the particles in
//! contact: a penalty normal force with some damping, and Coulomb
//! friction capped by it that stops the slip of the body at the point
//! (docs/methods.md, "Walls"); onto the nodes with the particle's weights
//! (the preload and, for linear shapes, the friction with the weights at
//! the wall's line), into `wall_force`, which `grid_update::correct` adds
//! to f_I, and into the walls' reactions. Only the walls that act in the
//! step (`Wall::active_at`) are in contact.
//! GPU twin: `shaders/wall_contact.wgsl`.

use super::stage_inputs::ShapeCache;
use super::wall_touch::{ContactParticles, LineWeights, contact_spring, line_weights_positive};
use crate::model::Walls;
use crate::model::walls::{WALL_DAMPING, coulomb_slip, face_weight, half_width, wall_depth};

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
    let nodal = NodeInputs {
        mv,
        force,
        pre_force,
        touch,
        gamma_dt,
        slip_dt,
        mass_eps,
    };
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
            let s = nodal.sums(nodes, wt, pt.v[p]);
            let mut w = s.w;
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
            w = w.max(s.w_own);
            w *= gamma_dt;
            let nrm = wl.normal;
            let vn = s.v[0] * nrm[0] + s.v[1] * nrm[1];
            let fnorm = (spring - WALL_DAMPING * vn / w).max(0.0);
            let ws = slip_dt * if s.wf > 0.0 { s.wf } else { w / gamma_dt };
            let ft = friction(s.vp, nrm, ws, fnorm, wl.coulomb_mu());
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

/// What a contact reads from its particle's nodes (`wall_contact`'s
/// arguments of the same names).
struct NodeInputs<'a> {
    mv: &'a [[f64; 3]],
    force: &'a [[f64; 2]],
    pre_force: &'a [[f64; 2]],
    touch: &'a [[f64; 2]],
    gamma_dt: f64,
    slip_dt: f64,
    mass_eps: f64,
}

/// A contact's sums over its particle's nodes: `v` the body's corrected
/// velocity at the particle (for the damping), `vp` the particle's own
/// next velocity (for the friction), both without the walls' contact
/// forces, with their preloads; Σ N S_I / m_I (`w`), Σ N T_I / m_I (`wf`)
/// and Σ N² / m_I (`w_own`).
struct NodeSums {
    v: [f64; 2],
    vp: [f64; 2],
    w: f64,
    wf: f64,
    w_own: f64,
}

impl NodeInputs<'_> {
    /// The sums of the particle on `nodes` with weights `wt` and velocity
    /// `v_p`, over its nodes with mass.
    #[inline]
    fn sums(&self, nodes: &[u32], wt: &[[f64; 3]], v_p: [f64; 2]) -> NodeSums {
        let (mut v, mut w, mut wf, mut w_own) = ([0.0; 2], 0.0, 0.0, 0.0);
        let mut vp = v_p;
        let (gamma_dt, slip_dt) = (self.gamma_dt, self.slip_dt);
        for (&n, wk) in nodes.iter().zip(wt) {
            let node = &self.mv[n as usize];
            if node[0] > self.mass_eps {
                let mut f = self.force[n as usize];
                if let Some(pf) = self.pre_force.get(n as usize) {
                    f = [f[0] + pf[0], f[1] + pf[1]];
                }
                v[0] += wk[0] * (node[1] + gamma_dt * f[0] / node[0]);
                v[1] += wk[0] * (node[2] + gamma_dt * f[1] / node[0]);
                vp[0] += wk[0] * slip_dt * f[0] / node[0];
                vp[1] += wk[0] * slip_dt * f[1] / node[0];
                w += wk[0] * self.touch[n as usize][0] / node[0];
                wf += wk[0] * self.touch[n as usize][1] / node[0];
                w_own += wk[0] * wk[0] / node[0];
            }
        }
        NodeSums {
            v,
            vp,
            w,
            wf,
            w_own,
        }
    }
}

/// The contact's friction (N per unit thickness): the force that stops
/// the slip of the particle's next velocity `vp` along the wall (normal
/// `nrm`), −v_t / `ws`, at most μ `fnorm` (`coulomb_slip`, `mu` from
/// `Wall::coulomb_mu`). `ws` = `slip_dt` Σ N T_I / m_I: the particle
/// feels the force over `slip_dt` (NPC: Δt in v_p and (1 − γ)Δt more in
/// the next predictor), so that is the step it is sized for. Sized on the
/// corrected nodal velocity over γΔt instead, the stick loop's gain was
/// (2 − γ)/γ = 3 and a slip grew (the geostatic column's bottom row: from
/// 1e-16 to 1 m/s in 100 steps). And with the weights it acts with (T_I):
/// sized with the particle's (S_I) while it acts on the line, a stick
/// loop's gain was about 1.28, which left the held particles a steady slip
/// against their load and a stick-held slab crept under a block
/// (docs/methods.md, "Walls"). A point whose nodes carry no friction
/// weight (T is never negative beyond round-off) falls back on S.
#[inline]
fn friction(vp: [f64; 2], nrm: [f64; 2], ws: f64, fnorm: f64, mu: f64) -> [f64; 2] {
    let vpn = vp[0] * nrm[0] + vp[1] * nrm[1];
    let vt = [vp[0] - vpn * nrm[0], vp[1] - vpn * nrm[1]];
    let mut ft = [-vt[0] / ws, -vt[1] / ws];
    let mag = ft[0].hypot(ft[1]);
    if let Some(cap) = coulomb_slip(mag, fnorm, mu) {
        ft = [ft[0] * cap / mag, ft[1] * cap / mag];
    }
    ft
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cpu::wall_touch::wall_touch;
    use crate::model::Wall;
    use crate::model::walls::{CONTACT_FRICTION, CONTACT_SLIP, CONTACT_STICK};

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
}
