//! The implicit step's node set when `solver.method = "gmm"` (implicit-MPM
//! paper Algorithm 2): the body's own node cloud (`gmm::Cloud`) in place
//! of the grid. What differs from implicit MPM is here, and only here:
//!
//! - shape functions: each particle gathers the nodes within the search
//!   radius (a cell list rebuilt each step) and evaluates the basis
//!   (`gmm::Basis`, LME or MLS) over them, into the same `ShapeCache` the
//!   grid's shapes fill, so the residual, Jacobian and solve
//!   (`assemble`) run unchanged;
//! - Newmark's predictor reads the nodes' own velocity and acceleration
//!   of the last converged step (like FEM; MPM maps them from the
//!   particles);
//! - walls act on the cloud's own nodes (`wall_pairs`): a node moves with
//!   the body, so its contact gap is its distance to the wall's line,
//!   g = (x + Δu − point)·n, the nodes lying in the body or on its
//!   outline (`Cloud::fit_to_outline`), so that a node meets the wall
//!   when the body's edge does, and a held node holds the body's edge;
//!   every wall, `stick` included, is a penalty
//!   contact of `contact` (a stick wall holds a closed contact, and lets
//!   it go when it opens, which is what lets a disk roll on it);
//! - after convergence the nodes move with the solution: x += Δu, the
//!   Newmark acceleration and velocity (eqs. 43–44) become their state.

use super::assemble::{Dofs, NO_DOF, Newmark};
use super::contact::{ContactPair, ContactState};
use crate::cpu::ShapeCache;
use crate::error::SceneError;
use crate::gmm::{Basis, Cloud};
use crate::model::fault::{Fault, FaultKind};
use crate::model::shape::ShapeFault;
use crate::model::walls::{CONTACT_STICK, Wall};
use crate::model::{GmmSettings, Model};
use rayon::prelude::*;

/// A particle's cloud may hold this many times the nodes of the undeformed
/// lattice's disk before the cache grows (it grows on demand anyway).
const STRIDE_SLACK: f64 = 2.0;

/// The radii, as multiples of the search radius, over which a particle
/// gathers its cloud, the next tried only when the basis finds no
/// solution on the last (the paper's variable radius for the column
/// collapse, §5.3): where the body stretches, the nodes that enclose a
/// particle can lie beyond the initial radius, and LME then has no λ
/// (its Hessian turns singular: the particle lies outside the hull of
/// the nodes it gathered). The cell list is built for the widest.
const RADIUS_GROWTH: [f64; 3] = [1.0, 1.5, 2.0];

/// Past the widest radius a particle adds the nodes nearest it,
/// `WIDEN_STEP` at a time in order of distance, out to `WIDEN_REACH`
/// times the search radius: the paper's "old connections plus the next
/// nodes closer to the material point" (§5.3), its guard against a cloud
/// that no longer encloses the particle. It always succeeds for LME where
/// the last step's cloud lies within reach: LME's weights are positive
/// and reproduce x, and the step moves the particle by Σ N_a Δu_a and
/// its nodes by Δu_a, so the particle ends strictly inside the hull of
/// the nodes it gathered last step, and any set holding those encloses
/// it.
const WIDEN_STEP: usize = 2;
const WIDEN_REACH: f64 = 4.0;

/// The cloud, its basis and each particle's LME multiplier.
pub struct GmmNodes {
    pub cloud: Cloud,
    basis: Basis,
    /// Search radius (m).
    radius: f64,
    /// Per particle: LME's λ of the last step (warm start; unused by MLS).
    lambda: Vec<[f64; 2]>,
    /// Per wall: how far (m) the body reached past its line at the start
    /// (its nodes' deepest gap, 0 if none did): contact is measured from
    /// there, so a body seeded against the wall starts unloaded, as the
    /// explicit walls' `Wall::offset`. 0 for a wall that appears later.
    wall_offset: Vec<f64>,
}

impl GmmNodes {
    pub fn new(model: &Model, s: &GmmSettings) -> Result<GmmNodes, SceneError> {
        let mut cloud = Cloud::from_model(model)?;
        cloud.fit_to_outline(&model.outline);
        let h = cloud.h;
        let wall_offset = model
            .walls
            .list
            .iter()
            .map(|w| {
                if w.appear_at > 0.0 {
                    return 0.0;
                }
                (0..cloud.len())
                    .map(|n| -raw_gap(&cloud, n, w))
                    .fold(0.0, f64::max)
            })
            .collect();
        Ok(GmmNodes {
            wall_offset,
            basis: Basis::new(s, h),
            radius: s.search_radius * h,
            lambda: vec![[0.0; 2]; model.particles.len()],
            cloud,
        })
    }

    /// What a checkpoint keeps of the cloud (`backend::CloudState`).
    pub fn state(&self) -> crate::backend::CloudState {
        let c = &self.cloud;
        crate::backend::CloudState {
            x: c.x.clone(),
            u: c.u.clone(),
            v: c.v.clone(),
            a: c.a.clone(),
            lambda: self.lambda.clone(),
        }
    }

    /// Takes a checkpoint's cloud over this one, which the same scene
    /// built from its initial particles (so its lattice origin,
    /// constraints and nodes fitted to the outline are the run's own);
    /// `Err` says what does not match.
    pub fn load(&mut self, s: &crate::backend::CloudState) -> Result<(), String> {
        let (n, p) = (self.cloud.len(), self.lambda.len());
        if s.x.len() != n || s.lambda.len() != p {
            return Err(format!(
                "holds a node cloud of {} nodes and {} particles; the scene makes {n} and {p}",
                s.x.len(),
                s.lambda.len()
            ));
        }
        let c = &mut self.cloud;
        c.x.clone_from(&s.x);
        c.u.clone_from(&s.u);
        c.v.clone_from(&s.v);
        c.a.clone_from(&s.a);
        self.lambda.clone_from(&s.lambda);
        Ok(())
    }

    /// "GMM-LME" or "GMM-MLS", for the backend's name.
    pub fn label(&self) -> &'static str {
        match self.basis {
            Basis::Lme(_) => "GMM-LME",
            Basis::Mls { .. } => "GMM-MLS",
        }
    }

    /// Slots per particle in the shape cache: the nodes of the lattice
    /// within the radius (π (r/h + √2/2)², every such node's unit cell lying
    /// in that disk) times `STRIDE_SLACK`.
    pub fn stride(&self) -> usize {
        let r = self.radius / self.cloud.h + std::f64::consts::FRAC_1_SQRT_2;
        (STRIDE_SLACK * std::f64::consts::PI * r * r).ceil() as usize
    }

    /// N and ∇N of every particle over its cloud, into `cache` (grown when
    /// a cloud outnumbers its slots).
    pub fn shape_eval(&mut self, x: &[[f64; 2]], cache: &mut ShapeCache) -> Result<(), Fault> {
        let widest = RADIUS_GROWTH[RADIUS_GROWTH.len() - 1];
        self.cloud.rebuild(widest * self.radius);
        let (cloud, basis, radius) = (&self.cloud, &self.basis, self.radius);
        loop {
            let stride = cache.stride;
            let (fault, need) = cache
                .nodes
                .par_chunks_mut(stride)
                .zip(cache.w.par_chunks_mut(stride))
                .zip(cache.count.par_iter_mut())
                .zip(self.lambda.par_iter_mut())
                .enumerate()
                .with_min_len(64)
                .map_init(
                    || (Vec::new(), Vec::new()),
                    |(list, near), (p, (((nodes, w), count), lam))| match particle_cloud(
                        cloud, basis, radius, x[p], list, near, nodes, w, lam,
                    ) {
                        Gathered::Kept(kept) => {
                            *count = kept as u16;
                            (None, 0)
                        }
                        Gathered::Failed(e) => (Some(Fault::at(p, FaultKind::Shape(e))), 0),
                        Gathered::NeedSlots(m) => (None, m),
                    },
                )
                .reduce(|| (None, 0), |a, b| (Fault::first(a.0, b.0), a.1.max(b.1)));
            if need > stride {
                *cache = ShapeCache::new(x.len(), need + need / 2);
                continue;
            }
            return fault.map_or(Ok(()), Err);
        }
    }

    /// The step's wall contacts: every unknown node within one node spacing
    /// of a wall's contact line (a node moves far less in a step; one that
    /// starts further off cannot reach the wall, and an open contact costs
    /// nothing), with its gap (m): its distance to the line less the
    /// wall's seeding offset. Every wall acts here, gates included only
    /// while they stand (`Wall::active_at` at the step's start `t`, s).
    pub fn wall_pairs(&self, model: &Model, dofs: &Dofs, t: f64) -> Vec<ContactPair> {
        let c = &self.cloud;
        let reach = c.h;
        let mut pairs = Vec::new();
        for n in 0..c.len() {
            if dofs.id[n] == NO_DOF {
                continue;
            }
            for (k, w) in model.walls.list.iter().enumerate() {
                if !w.active_at(t) {
                    continue;
                }
                let gap = raw_gap(c, n, w) + self.wall_offset[k];
                if gap <= reach {
                    pairs.push(ContactPair {
                        node: n as u32,
                        wall: k as u32,
                        gap,
                    });
                }
            }
        }
        pairs
    }

    /// The nodes take the converged step (Algorithm 2, step 3): position
    /// and displacement += Δu, acceleration from Newmark (eq. 44),
    /// velocity by the trapezoid of the accelerations (eq. 43); zero in a
    /// static analysis. A node that was no unknown this step (`dof[n]` is
    /// `NO_DOF`: no particle's cloud held it) is at rest: velocity and
    /// acceleration zero, moved only by a prescribed Δu. Newmark's update
    /// with Δu = 0 would give it a_new = −v/(βΔt) − (1/(2β) − 1) a, whose
    /// velocity flips sign every step while its acceleration grows by
    /// 4|v|/Δt per step, and a particle that gathered it again would start
    /// Newton from that acceleration.
    pub fn advance(&mut self, du: &[[f64; 2]], dof: &[u32], newmark: &Newmark) {
        let c = &mut self.cloud;
        let (gamma, dt) = (newmark.gamma, newmark.dt);
        for (n, dn) in du.iter().enumerate() {
            if dof[n] == NO_DOF {
                for (d, step) in dn.iter().enumerate() {
                    c.x[n][d] += step;
                    c.u[n][d] += step;
                }
                c.v[n] = [0.0; 2];
                c.a[n] = [0.0; 2];
                continue;
            }
            let a = newmark.accel(*dn, c.v[n], c.a[n]);
            for d in 0..2 {
                c.x[n][d] += dn[d];
                c.u[n][d] += dn[d];
                if newmark.is_static {
                    c.v[n][d] = 0.0;
                } else {
                    c.v[n][d] += dt * ((1.0 - gamma) * c.a[n][d] + gamma * a[d]);
                }
            }
            c.a[n] = a;
        }
    }

    /// A node in closed contact with a wall at the step's end (`state`
    /// not open) moves along the wall only: the normal components of its
    /// velocity and acceleration are set to zero (the contact's
    /// persistency, ġ = 0 while closed, imposed on the node's own state,
    /// as implicit dynamic contact does after each step; a node that
    /// lifts off opens its contact first). On a `stick` wall a stuck node
    /// moves with the wall, which is at rest: its tangential velocity and
    /// acceleration are set to zero too. Without it the trapezoidal rule
    /// keeps the velocity the node arrived with: Δu ≈ 0 under the stiff
    /// penalty gives v_new = 2 Δu/Δt − v ≈ −v, a sign flip every step
    /// that never decays, with an acceleration 4(Δu − Δt v)/Δt² − a that
    /// grows by about 4|v|/Δt a step, and the next predictor starts from
    /// both (docs/methods.md, GMM: the column collapse's stop at 0.304 s;
    /// the rolling disk's landing at 0.165 s, its strain energy jumping
    /// from 8 to 105 J). Removing only the approaching half instead
    /// rectifies that flip into a push off the wall: the sliding block
    /// then ran 0.725 % past Coulomb's motion instead of 0.014 %.
    pub fn persist_contact(&mut self, n: usize, wall: &Wall, state: ContactState) {
        if state == ContactState::Open {
            return;
        }
        let normal = wall.normal;
        let held = wall.contact == CONTACT_STICK && state == ContactState::Stick;
        let c = &mut self.cloud;
        for q in [&mut c.v[n], &mut c.a[n]] {
            let along = q[0] * normal[0] + q[1] * normal[1];
            *q = if held {
                [0.0; 2]
            } else {
                [q[0] - along * normal[0], q[1] - along * normal[1]]
            };
        }
    }
}

/// What `particle_cloud` found.
#[derive(Debug)]
enum Gathered {
    /// The basis over this many nodes (`nodes[..k]`, `w[..k]`).
    Kept(usize),
    /// No set it tried gave the basis a solution; the last one's fault.
    Failed(ShapeFault),
    /// A set it needed outnumbers the slots: this many.
    NeedSlots(usize),
}

/// One particle's cloud and basis at `x`: the nodes within each of
/// `RADIUS_GROWTH` times `radius` in turn, then the guard (`WIDEN_STEP`),
/// into `nodes` and `w` (their length is the slots); `lam` is LME's warm
/// start, reset to 0 past the first set. `list` and `near` are scratch.
#[allow(clippy::too_many_arguments)]
fn particle_cloud(
    cloud: &Cloud,
    basis: &Basis,
    radius: f64,
    x: [f64; 2],
    list: &mut Vec<u32>,
    near: &mut Vec<(f64, u32)>,
    nodes: &mut [u32],
    w: &mut [[f64; 3]],
    lam: &mut [f64; 2],
) -> Gathered {
    let stride = nodes.len();
    let mut fault = ShapeFault::LmeTooFewNodes { nodes: Some(0) };
    for (k, grow) in RADIUS_GROWTH.iter().enumerate() {
        cloud.gather(x, grow * radius, list);
        if list.len() > stride {
            return Gathered::NeedSlots(list.len());
        }
        nodes[..list.len()].copy_from_slice(list);
        if k > 0 {
            *lam = [0.0; 2];
        }
        match basis.eval(x, &cloud.x, nodes, list.len(), lam, w) {
            Ok(kept) => return Gathered::Kept(kept),
            Err(e) => fault = e,
        }
    }
    // The guard: the nearest nodes beyond the widest radius, a few at a time.
    cloud.nearest_within(x, WIDEN_REACH * radius, near);
    let mut m = list.len();
    while m < near.len() {
        m = (m + WIDEN_STEP).min(near.len());
        if m > stride {
            return Gathered::NeedSlots(m);
        }
        list.clear();
        list.extend(near[..m].iter().map(|&(_, n)| n));
        list.sort_unstable();
        nodes[..m].copy_from_slice(list);
        *lam = [0.0; 2];
        match basis.eval(x, &cloud.x, nodes, m, lam, w) {
            Ok(kept) => return Gathered::Kept(kept),
            Err(e) => fault = e,
        }
    }
    Gathered::Failed(fault)
}

/// Node `n`'s gap to wall `w`'s line (m): its distance on the material's
/// side (the cloud's nodes lie in the body or on its outline,
/// `Cloud::fit_to_outline`).
fn raw_gap(c: &Cloud, n: usize, w: &Wall) -> f64 {
    let x = c.x[n];
    (x[0] - w.point[0]) * w.normal[0] + (x[1] - w.point[1]) * w.normal[1]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::GmmSettings;
    use crate::scene::GmmBasis;

    /// A particle whose nodes within the widest radius all lie on one side
    /// of it (the body stretched the cloud that enclosed it): LME has no
    /// solution there, and the guard finds one with the nearest node
    /// beyond, which reproduces x.
    #[test]
    fn the_guard_encloses_a_particle_the_widest_radius_leaves_outside() {
        let h = 0.05;
        let s = GmmSettings {
            basis: GmmBasis::Lme,
            gamma: 1.8,
            search_radius: std::f64::consts::SQRT_2,
            dilation: 1.0,
        };
        let radius = s.search_radius * h;
        let widest = RADIUS_GROWTH[RADIUS_GROWTH.len() - 1] * radius;
        // A half-lattice left of the particle at the origin, and one node
        // to its right beyond the widest radius, within the guard's reach.
        let mut xn = Vec::new();
        for j in -6..=6 {
            for i in 1..=6 {
                xn.push([-(i as f64) * h, j as f64 * h]);
            }
        }
        let far = [1.2 * widest, 0.0];
        assert!(far[0] < WIDEN_REACH * radius);
        xn.push(far);
        let mut cloud = Cloud::from_points(h, xn);
        cloud.rebuild(widest);
        let basis = Basis::new(&s, h);
        let x = [0.0, 0.01];
        let slots = 200;
        let (mut nodes, mut w) = (vec![0u32; slots], vec![[0.0; 3]; slots]);
        let (mut list, mut near) = (Vec::new(), Vec::new());
        // Without the guard: the widest radius alone faults.
        cloud.gather(x, widest, &mut list);
        let n = list.len();
        nodes[..n].copy_from_slice(&list);
        assert!(
            basis
                .eval(x, &cloud.x, &mut nodes, n, &mut [0.0; 2], &mut w)
                .is_err()
        );
        let got = particle_cloud(
            &cloud,
            &basis,
            radius,
            x,
            &mut list,
            &mut near,
            &mut nodes,
            &mut w,
            &mut [0.0; 2],
        );
        let Gathered::Kept(k) = got else {
            panic!("the guard found no cloud: {got:?}")
        };
        assert!(nodes[..k].contains(&((cloud.len() - 1) as u32)));
        let (mut sum, mut rx) = (0.0, [0.0; 2]);
        for (a, wa) in nodes[..k].iter().zip(&w[..k]) {
            sum += wa[0];
            for (r, xa) in rx.iter_mut().zip(cloud.x[*a as usize]) {
                *r += wa[0] * xa;
            }
        }
        assert!((sum - 1.0).abs() < 1e-10, "partition of unity {sum}");
        assert!(
            (rx[0] - x[0]).abs() < 1e-9 * h && (rx[1] - x[1]).abs() < 1e-9 * h,
            "{rx:?}"
        );
    }
}
