//! Rigid walls: half-planes behind a line, with a contact law. A wall's
//! nodes are the grid nodes behind its line, (x_node − point)·n ≤ 0, tested
//! on the unperturbed lattice (as constraints are), so a perturbed grid has
//! the same wall nodes as the regular one. Both backends apply the
//! contact (`cpu::wall_touch` / `cpu::wall_contact` and their WGSL
//! twins) from this list, with each wall's penalty stiffness and offset
//! and the particles' preloads (`Walls::set_contact`). Coulomb's law of a
//! wall's contact (`Wall::coulomb_mu`, `coulomb_slip`) is here for both
//! steps: the explicit one's `cpu::wall_contact` (and its WGSL twin) and
//! the implicit one's `cpu::implicit::contact`.

use crate::error::SceneError;
use crate::model::{Grid, Particles};
use crate::scene::{Contact, Scene};

/// Contact law code shared with WGSL (`Wall::contact`, shaders/shared/types.wgsl).
pub const CONTACT_STICK: u32 = 0;
pub const CONTACT_SLIP: u32 = 1;
pub const CONTACT_FRICTION: u32 = 2;

/// The walls' penalty stiffness k relative to the stiffest material's
/// P-wave modulus M over the grid spacing h: k = WALL_PENALTY M / h (Pa/m).
/// Measured (docs/methods.md, "Walls" and "The penalty's stiffness,
/// again"): 0.1 left the suddenly loaded block bouncing on the wall (at
/// μ = 1.0 it slid at 0.17 m/s) and the disk on the grid-aligned floor 10 %
/// off; 0.01 put the inclined disk 5 % off; 0.03 left the stick disk on
/// the aligned floor at R/h 10 5.21 % short and the μ = 0.5 block 3.18 %
/// fast; 0.025 with `WALL_DAMPING` puts all 24 disks of the methods table
/// within issue 23's bounds (the largest 3.37 %) and the block at +2.90 %,
/// at rest at μ = 0.7 (0.008 m/s). A softer spring lets the body sink
/// further (ρ g H / k) and its landing last longer.
pub const WALL_PENALTY: f64 = 0.025;

/// Normal damping of the contact, as the fraction of the body's normal
/// velocity at a contact point that one step's damping force would stop
/// (F_d = −WALL_DAMPING v_n / w; `cpu::wall_contact`). Without
/// it the elastic block rings on the penalty spring, and at each release
/// gravity pulls it down the slope; 0.1 and more slows the rolling disk
/// (the force grows where the rim approaches the wall, ahead of the
/// contact: 6.4 % at R/h 10 against 4.5 %).
pub const WALL_DAMPING: f64 = 0.05;

/// A stick wall holds a contact point as friction with this μ: no slip
/// while the tangential force stays below 20 times the normal one.
/// Uncapped, points that barely touch the wall (no normal force) held
/// the disk's rim and it rolled 78 % short; 2, 5 and 20 give 4.4, 4.0 and
/// 3.9 % (inclined, R/h 10, linear), as friction with μ = 0.5 does.
pub const STICK_MU: f64 = 20.0;

/// One wall.
#[derive(Debug, Clone, PartialEq)]
pub struct Wall {
    pub name: String,
    /// A point of the wall line (m).
    pub point: [f64; 2],
    /// Unit normal pointing into the material's side.
    pub normal: [f64; 2],
    /// `CONTACT_*`.
    pub contact: u32,
    /// Coulomb μ (friction only; 0 otherwise).
    pub mu: f64,
    /// Nodes behind the line.
    pub nodes: Vec<u32>,
    /// Penalty stiffness k (Pa per m of penetration, i.e. N/m per m of
    /// wall length per m of penetration): `WALL_PENALTY` × the stiffest
    /// material's P-wave modulus / h (`Walls::set_stiffness`).
    pub stiffness: f64,
    /// How far (m) the particles' domains reached past the line at the
    /// start (the deepest): contact is measured from there, so a body
    /// seeded against the wall starts unloaded (`Walls::set_contact`).
    pub offset: f64,
    /// The wall acts for `appear_at` ≤ t < `remove_at` (s), t the step's
    /// start; 0 and +∞ for a wall that is always there.
    pub appear_at: f64,
    pub remove_at: f64,
}

impl Wall {
    /// Whether the wall acts in the step that starts at `t` (s).
    #[inline]
    pub fn active_at(&self, t: f64) -> bool {
        self.appear_at <= t && t < self.remove_at
    }

    /// Coulomb's μ of the wall's contact law: `STICK_MU` on a `stick`
    /// wall (it holds a contact as friction bounded so), the wall's own
    /// `mu` on a `friction` wall, 0 on a `slip` wall. WGSL twin
    /// `coulomb_mu` in shaders/shared/wall_coulomb.wgsl.
    #[inline]
    pub fn coulomb_mu(&self) -> f64 {
        match self.contact {
            CONTACT_STICK => STICK_MU,
            CONTACT_FRICTION => self.mu,
            _ => 0.0,
        }
    }
}

/// Coulomb's law at a wall's contact, |f_t| ≤ μ f_n: whether the
/// tangential `trial` (the magnitude of what would hold the contact
/// still: stick) exceeds μ times `normal` (the normal one, compression
/// positive, in the same units), and if so the bound μ `normal` that it
/// is capped at (slip); None while the contact holds. The explicit step
/// (`cpu::wall_contact`) asks it of forces (N), trial the force that
/// stops the slip; the implicit one (`cpu::implicit::contact::
/// natural_state`) of the gap's components (m; the penalty k of both
/// forces cancels), trial the tangential increment; its consistent start
/// (`cpu::implicit`'s `initial_acceleration`) of accelerations. WGSL twin
/// `coulomb_slip` in shaders/shared/wall_coulomb.wgsl.
#[inline]
pub fn coulomb_slip(trial: f64, normal: f64, mu: f64) -> Option<f64> {
    let cap = mu * normal;
    (trial > cap).then_some(cap)
}

/// The scene's walls, and per node the bit set of the walls it is behind
/// (bit k = wall k; empty when the scene has no walls).
#[derive(Debug, Clone, Default)]
pub struct Walls {
    pub list: Vec<Wall>,
    pub mask: Vec<u32>,
    /// Per particle and wall (index p × walls + k), the normal traction
    /// (Pa, compression positive) across the wall's line of a particle
    /// flush with the wall and compressed across it at the start (a
    /// geostatic body on its floor and against its side walls): the
    /// contact carries it from the start (`preload_force`). Empty when no
    /// particle starts so (every stress-free body): the scene pays
    /// nothing for it.
    pub preload: Vec<f64>,
    /// Per grid node, the factor a_I by which each preloaded contact also
    /// puts P_p N_Ip a_I on node I, fitted so that at the start the walls
    /// give each node the body's discrete reaction −(f_int + f_ext)_I
    /// (`model::preload_fit`); empty without preload, or where there is
    /// nothing to fit.
    pub pre_fit: Vec<[f64; 2]>,
}

impl Walls {
    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// Sets every wall's penalty stiffness from the largest P-wave
    /// modulus M = λ + 2μ (Pa) of the scene's materials and the spacing
    /// `h` (m), k = `WALL_PENALTY` M / h; the offset of each wall, how deep
    /// the deepest particle's domain reaches past its line at the start
    /// (`Wall::offset`); and the preload of the particles flush with that
    /// contact line and compressed across it (`Walls::preload`: their
    /// initial σ_nn, so a body that starts in equilibrium against the wall
    /// stays there). A wall that appears later (`appear_at` > 0) keeps
    /// offset 0 and no preload: the seeding says nothing of where the body
    /// will be when it appears.
    pub fn set_contact(&mut self, p_wave_modulus: f64, h: f64, particles: &Particles) {
        let n_walls = self.list.len();
        let mut preload = vec![0.0; particles.len() * n_walls];
        for (k, w) in self.list.iter_mut().enumerate() {
            w.stiffness = WALL_PENALTY * p_wave_modulus / h;
            w.offset = 0.0;
            // A gate that appears later meets the body where it is then,
            // not where it was seeded: its line is its contact line.
            if w.appear_at > 0.0 {
                continue;
            }
            let pens: Vec<(f64, f64)> = (0..particles.len())
                .map(|p| {
                    let lp = half_width(particles.mass[p], particles.rho[p]);
                    (wall_penetration(particles.x[p], lp, w), lp)
                })
                .collect();
            let deepest = pens.iter().map(|q| q.0).fold(0.0, f64::max);
            w.offset = deepest;
            // The particles flush with that line (to FLUSH_REL l_p) and in
            // compression across it carry their traction from the start.
            for (p, ((pen, lp), s)) in pens.iter().zip(&particles.stress).enumerate() {
                if *pen >= deepest - FLUSH_REL * lp {
                    preload[p * n_walls + k] = (-normal_stress(*s, w.normal)).max(0.0);
                }
            }
        }
        self.preload = if preload.iter().any(|&t| t > 0.0) {
            preload
        } else {
            Vec::new()
        };
    }

    /// The preload traction (Pa) of particle `p` against wall `k`
    /// (`Walls::preload`; 0 without one).
    #[inline]
    pub fn preload_of(&self, p: usize, k: usize) -> f64 {
        self.preload
            .get(p * self.list.len() + k)
            .copied()
            .unwrap_or(0.0)
    }

    /// Whether the preload's fit (`pre_fit`) acts in the step starting at
    /// `t` (s): there is one, and every wall stands that stood at the
    /// start. Its per-node factors hold the walls' shares together (at a
    /// corner the floor's contacts carry part of a gate's reaction), so a
    /// wall that goes takes the whole fit with it; the body is no longer
    /// at rest then, which is what the fit is for.
    #[inline]
    pub fn fit_at(&self, t: f64) -> bool {
        !self.pre_fit.is_empty()
            && self
                .list
                .iter()
                .all(|w| w.appear_at > 0.0 || t < w.remove_at)
    }

    /// Whether some wall appears or goes during the run (a gate).
    pub fn timed(&self) -> bool {
        self.list
            .iter()
            .any(|w| w.appear_at > 0.0 || w.remove_at.is_finite())
    }

    /// Walls of `scene` on `grid`. A wall with no node behind it is an
    /// error naming it (it would do nothing).
    pub fn new(scene: &Scene, grid: &Grid) -> Result<Walls, SceneError> {
        let specs = &scene.file.walls;
        if specs.is_empty() {
            return Ok(Walls::default());
        }
        let mut mask = vec![0u32; grid.n_nodes()];
        let mut list = Vec::new();
        // A node on the line counts as behind it; 1e-9 h absorbs the
        // round-off of a line through a node.
        let eps = 1e-9 * grid.h;
        for (k, (name, w)) in specs.iter().enumerate() {
            let len = w.normal[0].hypot(w.normal[1]);
            let n = [w.normal[0] / len, w.normal[1] / len];
            let mut nodes = Vec::new();
            for j in 0..grid.ny {
                for i in 0..grid.nx {
                    let p = grid.lattice_pos(i, j);
                    let d = (p[0] - w.point[0]) * n[0] + (p[1] - w.point[1]) * n[1];
                    if d <= eps {
                        let idx = grid.index(i, j);
                        mask[idx] |= 1 << k;
                        nodes.push(idx as u32);
                    }
                }
            }
            if nodes.is_empty() {
                return Err(SceneError::invalid(
                    format!("walls.{name}"),
                    format!(
                        "has no grid node behind it: the grid spans ({:.6}, {:.6}) to ({:.6}, {:.6}); \
                         move `point` to the material's boundary",
                        grid.min[0],
                        grid.min[1],
                        grid.max()[0],
                        grid.max()[1]
                    ),
                ));
            }
            let (contact, mu) = match w.contact {
                Contact::Stick => (CONTACT_STICK, 0.0),
                Contact::Slip => (CONTACT_SLIP, 0.0),
                Contact::Friction => (CONTACT_FRICTION, w.friction.unwrap_or(0.0)),
            };
            list.push(Wall {
                name: name.clone(),
                point: w.point,
                normal: n,
                contact,
                mu,
                nodes,
                stiffness: 0.0,
                offset: 0.0,
                appear_at: w.appear_at,
                remove_at: w.remove_at.unwrap_or(f64::INFINITY),
            });
        }
        Ok(Walls {
            list,
            mask,
            preload: Vec::new(),
            pre_fit: Vec::new(),
        })
    }
}

/// A particle is flush with a wall's contact line at the start when its
/// domain reaches within this fraction of its half-width of the deepest
/// one's (the seeding's rounding, ~1e-16 of a metre, is far below it;
/// the next layer of particles sits 2 l_p further).
pub const FLUSH_REL: f64 = 1e-6;

/// Normal stress n·σ·n (Pa, tension positive) of `s` = [σxx, σyy, σxy]
/// across a line of unit normal `n`.
#[inline]
pub fn normal_stress(s: [f64; 3], n: [f64; 2]) -> f64 {
    s[0] * n[0] * n[0] + 2.0 * s[2] * n[0] * n[1] + s[1] * n[1] * n[1]
}

/// The share of its preload traction τ0 that a particle's normal stress
/// may lose before the wall's preload follows it down: the traction is
/// min(τ0, −σ_nn / PRELOAD_HOLD), τ0 while −σ_nn ≥ 0.99 τ0, and it falls
/// to zero with the stress below that (so a body that unloads as it flows
/// still lets go). With min(τ0, −σ_nn) a body at rest sat on the kink:
/// each round-off fluctuation of σ_nn lowered the wall's force and none
/// raised it, and the geostatic column on B-splines (`cells` knots) grew
/// from round-off, its kinetic energy e-folding every 21 ms to about 1 J
/// at 1.6 s (bspline2; bspline3 at 3 s, tests/initial_states.rs). Any
/// value below 1 holds it (0.99, 0.9 and 0.5 give the same 2.3e-26 J at
/// 2.9 s). A particle that unloads is pushed by up to 1/PRELOAD_HOLD − 1
/// more than its stress: with 0.9 that excess (11 %) left the 1 % PIC
/// granular deposit at 0.64 J/m at 2 s against 0.13, with 0.99 (1 %) 0.17,
/// and the resting geostatic columns hold (σ_yy within 5.8e-3 ρgH of the
/// overburden over 3 s, tests/initial_states.rs).
pub const PRELOAD_HOLD: f64 = 0.99;

/// The normal force (N per unit thickness) with which a wall carries a
/// particle that started flush with it and compressed across it, with
/// preload traction `tau0` (Pa, `Walls::preload`): the traction on the
/// wall's line, the particle's normal stress now (capped by `tau0`, so a
/// body that unloads as it flows lets go) plus the weight of its material
/// between its centre and the line, at distance `depth` (m, `wall_depth`;
/// equilibrium under gravity: ∂σ_nn/∂n = ρ g·n), times the face length
/// 2 l_p. `stress` is the particle's stress now, `lp` its half-width (m),
/// `mass` (kg per unit thickness), `gravity` the full gravity (m/s²).
/// Zero for a particle without preload (every stress-free start). The
/// traction follows the stress down only past `PRELOAD_HOLD` (below).
#[inline]
pub fn preload_force(
    tau0: f64,
    stress: [f64; 3],
    normal: [f64; 2],
    lp: f64,
    mass: f64,
    gravity: [f64; 2],
    depth: f64,
) -> f64 {
    if tau0 <= 0.0 {
        return 0.0;
    }
    let traction = tau0.min((-normal_stress(stress, normal)).max(0.0) / PRELOAD_HOLD);
    let weight = (-(gravity[0] * normal[0] + gravity[1] * normal[1])).max(0.0);
    // ρ g_n depth 2 l_p, with ρ = m / (2 l_p)².
    2.0 * lp * traction + mass * weight * depth / (2.0 * lp)
}

/// The weight of a node at the wall's line, from the particle's [N, ∇N]
/// `wk` and the distance `d` (m, `wall_depth`) from its centre to the
/// line along the normal `n`: N − d n·∇N, first order in d (exact for
/// linear shapes while the line is in the particle's cell). They sum to
/// one, as N does.
#[inline]
pub fn face_weight(wk: &[f64; 3], n: [f64; 2], d: f64) -> f64 {
    wk[0] - d * (n[0] * wk[1] + n[1] * wk[2])
}

/// The contact's normal spring force (N per unit thickness) of particle
/// `p` (at `x`, mass `m` kg, density `rho` kg/m³, stress `stress` Pa) on
/// wall `k` before damping: the penalty k pen 2 l_p (pen from
/// `wall_penetration`, negative once the domain is clear of the contact
/// line) plus the particle's preload (`preload_force` under the full
/// `gravity`, zero unless it started flush and compressed against the
/// wall), and that preload. The particle is in contact while the sum is
/// positive. Shared by the CPU stages and `preload_fit`; WGSL twin
/// `contact_spring` in shaders/shared/wall_spring.wgsl.
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn contact_spring(
    walls: &Walls,
    p: usize,
    k: usize,
    x: [f64; 2],
    m: f64,
    rho: f64,
    stress: [f64; 3],
    gravity: [f64; 2],
) -> (f64, f64) {
    let w = &walls.list[k];
    let lp = half_width(m, rho);
    let pre = preload_force(
        walls.preload_of(p, k),
        stress,
        w.normal,
        lp,
        m,
        gravity,
        wall_depth(x, lp, w),
    );
    (
        w.stiffness * wall_penetration(x, lp, w) * 2.0 * lp + pre,
        pre,
    )
}

/// How far (m) the centre of a particle at `x` (half-width `lp`, m) is in
/// front of the wall's line, clamped to [0, l_p (|n_x| + |n_y|)]: the
/// distance along −n from the centre to where the wall's traction acts.
#[inline]
pub fn wall_depth(x: [f64; 2], lp: f64, w: &Wall) -> f64 {
    let d = (x[0] - w.point[0]) * w.normal[0] + (x[1] - w.point[1]) * w.normal[1];
    d.clamp(0.0, lp * (w.normal[0].abs() + w.normal[1].abs()))
}

/// Half-width l_p = ½ sqrt(m_p / ρ_p) (m) of a particle's square domain
/// (mass `m`, kg per unit thickness; density `rho`, kg/m³).
#[inline]
pub fn half_width(m: f64, rho: f64) -> f64 {
    0.5 * (m / rho).sqrt()
}

/// How far (m) the square domain (half-width `lp`, m) of a particle at
/// `x` (m) reaches past the wall's contact line, the wall line moved by
/// its offset: l_p (|n_x| + |n_y|) − (x − point)·n − offset. Positive:
/// the particle is in contact.
#[inline]
pub fn wall_penetration(x: [f64; 2], lp: f64, w: &Wall) -> f64 {
    let d = (x[0] - w.point[0]) * w.normal[0] + (x[1] - w.point[1]) * w.normal[1];
    lp * (w.normal[0].abs() + w.normal[1].abs()) - d - w.offset
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn preload_is_the_traction_on_the_line_held_and_capped_by_the_start() {
        // ρ = 1000 kg/m³ (m = 0.1 kg, l_p = 0.005 m), the centre 0.004 m
        // above a floor, g = 10 m/s²: the weight below the centre adds
        // ρ g d = 40 Pa to the normal stress, over a face of 0.01 m.
        let (lp, m, g, n) = (0.005, 0.1, [0.0, -10.0], [0.0, 1.0]);
        let f = |tau0: f64, syy: f64| preload_force(tau0, [0.0, syy, 0.0], n, lp, m, g, 0.004);
        // Unloaded past `PRELOAD_HOLD`: the stress over it.
        let h = PRELOAD_HOLD;
        assert!((f(1000.0, -800.0) - 0.01 * (800.0 / h + 40.0)).abs() < 1e-12);
        // Within `PRELOAD_HOLD` of τ0, and compressed beyond its start: τ0.
        assert!((f(1000.0, -995.0) - 0.01 * (1000.0 + 40.0)).abs() < 1e-12);
        assert!((f(1000.0, -1500.0) - 0.01 * (1000.0 + 40.0)).abs() < 1e-12);
        // Unloaded: only the weight; no preload at all without τ0.
        assert!((f(1000.0, 100.0) - 0.01 * 40.0).abs() < 1e-12);
        assert_eq!(f(0.0, -800.0), 0.0);
        // A side wall carries no weight.
        let side = preload_force(1000.0, [-800.0, 0.0, 0.0], [1.0, 0.0], lp, m, g, 0.004);
        assert!((side - 0.01 * 800.0 / h).abs() < 1e-12);
    }
}
