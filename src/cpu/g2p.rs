//! Stage `g2p`: move the particles with the nodal solution (paper eqs. 22–23
//! for FE, Algorithm 1 step 8 for NPC), then check each particle is still
//! finite and inside the grid.
//! FE and MUSL:  v_p += Δt Σ N f/m;  x_p += Δt Σ N v_I (v_I after the
//!      momentum update; B-spline paper eqs. 29–30).
//! NPC: a_p = Σ N f/m;  v_p += Δt a_p;  x_p += Δt Σ N v_I + ½ Δt² a_p, with
//!      v_I the corrected or the predicted nodal velocity (`NpcPosition`).
//! With `solver.pic_fraction` α > 0 the new particle velocity is the blend
//! (1 − α) v_FLIP + α v_PIC, v_FLIP the update above and v_PIC = Σ N v_I
//! with v_I the nodal velocity after the momentum update (the corrected
//! one for NPC); positions are untouched (docs/methods.md, "PIC blend").
//! A particle that reaches a node where a contact pair of its body is in
//! contact takes at least `CONTACT_PIC_FRACTION` of PIC.
//! GPU twin: `shaders/g2p.wgsl`.

use super::stage_inputs::{ParticleWeights, Stencil, Weights, with_weights};
use crate::model::contact::CONTACT_PIC_FRACTION;
use crate::model::fault::{Fault, FaultKind};
use crate::model::shape::ShapeFault;
use crate::model::{Grid, Integrator, inside};
use crate::scene::NpcPosition;
use rayon::prelude::*;

#[derive(Debug, Clone, Copy)]
pub struct G2pParams {
    pub dt: f64,
    pub integrator: Integrator,
    /// Distance (m) a particle must keep from the grid's edge.
    pub edge_margin: f64,
    /// Share α of PIC in the velocity update, in [0, 1]; 0 = FLIP.
    pub pic_fraction: f64,
}

/// Contact pairs: per field node, whether some pair of the field is in
/// contact there (`ContactState::touched`), and per particle the
/// momentum change the blend makes (`ContactState::pic_dp`, with the
/// particles' masses): a particle
/// reaching such a node takes `CONTACT_PIC_FRACTION` if the scene's share
/// is smaller.
pub type Touched<'a> = Option<(&'a [bool], &'a [f64], &'a mut [[f64; 2]])>;

/// One particle's update from its nodes and weights (`g2p`'s body, also
/// run by `g2p_p2g`).
pub struct Update<'a> {
    /// `nodal`'s per node.
    pub nodal: &'a [[f64; 4]],
    /// `Grid::bounds` at `prm.edge_margin`: where a particle must stay.
    pub bounds: [[f64; 2]; 2],
    pub prm: G2pParams,
    /// Contact pairs: `Touched`'s flags per field node and the particles'
    /// masses; None and empty without.
    pub touched: Option<&'a [bool]>,
    pub mass: &'a [f64],
}

impl Update<'_> {
    /// Moves particle `p` (`dp`: the interface blend's momentum change,
    /// with contact pairs).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub fn particle(
        &self,
        p: usize,
        st: &impl Stencil,
        x: &mut [f64; 2],
        v: &mut [f64; 2],
        a: Option<&mut [f64; 2]>,
        dp: Option<&mut [f64; 2]>,
    ) -> Option<Fault> {
        let (nodal, prm, touched, mass) = (self.nodal, self.prm, self.touched, self.mass);
        let dt = prm.dt;
        // Σ N f/m and Σ N v_I (nodes without mass hold zeros).
        let (mut acc, mut vel) = ([0.0; 2], [0.0; 2]);
        st.each(|node, wk| {
            let n = &nodal[node as usize];
            vel[0] += wk[0] * n[0];
            vel[1] += wk[0] * n[1];
            acc[0] += wk[0] * n[2];
            acc[1] += wk[0] * n[3];
        });
        let alpha = match touched {
            Some(t) if touches(st, t) => prm.pic_fraction.max(CONTACT_PIC_FRACTION),
            _ => prm.pic_fraction,
        };
        if let Some(dp) = dp {
            *dp = [0.0; 2];
            if alpha > prm.pic_fraction {
                // The interface's share over the scene's: its momentum
                // change, which `contact_conserve::conserve` gives back.
                let flip = [v[0] + dt * acc[0], v[1] + dt * acc[1]];
                let scene = [
                    (1.0 - prm.pic_fraction) * flip[0] + prm.pic_fraction * vel[0],
                    (1.0 - prm.pic_fraction) * flip[1] + prm.pic_fraction * vel[1],
                ];
                let new = [
                    (1.0 - alpha) * flip[0] + alpha * vel[0],
                    (1.0 - alpha) * flip[1] + alpha * vel[1],
                ];
                *dp = [mass[p] * (new[0] - scene[0]), mass[p] * (new[1] - scene[1])];
            }
        }
        if alpha > 0.0 {
            // Blend of the FLIP update and Σ N v_I (the same v_I as
            // the positions' before NPC's own changes to `vel`).
            let a = alpha;
            v[0] = (1.0 - a) * (v[0] + dt * acc[0]) + a * vel[0];
            v[1] = (1.0 - a) * (v[1] + dt * acc[1]) + a * vel[1];
        } else {
            v[0] += dt * acc[0];
            v[1] += dt * acc[1];
        }
        match prm.integrator {
            // MUSL moves as FE does (B-spline paper eqs. 29–30);
            // `cpu::implicit` steps implicit models, so that arm is unused.
            Integrator::Fe | Integrator::Musl | Integrator::Implicit(_) => {
                x[0] += dt * vel[0];
                x[1] += dt * vel[1];
            }
            Integrator::Npc { gamma, position } => {
                if position != NpcPosition::Corrected {
                    // v_pred = v_corr − γ Δt f/m, interpolated.
                    vel[0] -= gamma * dt * acc[0];
                    vel[1] -= gamma * dt * acc[1];
                }
                let half_dt2 = if position == NpcPosition::Newmark {
                    0.0
                } else {
                    0.5 * dt * dt
                };
                x[0] += dt * vel[0] + half_dt2 * acc[0];
                x[1] += dt * vel[1] + half_dt2 * acc[1];
                if let Some(a) = a {
                    *a = acc;
                }
            }
        }
        if !(x[0].is_finite() && x[1].is_finite() && v[0].is_finite() && v[1].is_finite()) {
            return Some(Fault::at(
                p,
                FaultKind::NonFinite {
                    field: "position or velocity",
                },
            ));
        }
        if !inside(self.bounds, *x) {
            return Some(Fault::at(p, FaultKind::Shape(ShapeFault::OutsideGrid)));
        }
        None
    }
}

impl Update<'_> {
    /// `particle` with its weights evaluated into `slots`.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn with_weights<W: ParticleWeights>(
        &self,
        weights: &W,
        slots: &mut W::Scratch,
        p: usize,
        x: &mut [f64; 2],
        v: &mut [f64; 2],
        a: Option<&mut [f64; 2]>,
        dp: Option<&mut [f64; 2]>,
    ) -> Option<Fault> {
        match weights.get::<false>(p, *x, slots) {
            Ok(st) => self.particle(p, &st, x, v, a, dp),
            Err(e) => Some(Fault::at(p, FaultKind::Shape(e))),
        }
    }
}

/// Whether a node of the stencil with a weight is one where a contact
/// pair is in contact (`t`).
fn touches(st: &impl Stencil, t: &[bool]) -> bool {
    let mut hit = false;
    st.each(|node, wk| hit |= wk[0] > 0.0 && t[node as usize]);
    hit
}

/// Per node the velocity and acceleration g2p interpolates,
/// [v_x, v_y, f_x/m, f_y/m], zero on nodes without mass: one division per
/// node rather than one per particle and node.
pub fn nodal(mv: &[[f64; 3]], force: &[[f64; 2]], mass_eps: f64, out: &mut [[f64; 4]]) {
    out.par_iter_mut()
        .zip(mv.par_iter().zip(force))
        .with_min_len(4096)
        .for_each(|(o, (n, f))| {
            *o = if n[0] > mass_eps {
                [n[1], n[2], f[0] / n[0], f[1] / n[0]]
            } else {
                [0.0; 4]
            };
        });
}

/// `weights` not stored are evaluated at each particle's position before
/// it moves (where this step's shape evaluation was). `nodal` is `nodal`'s.
#[allow(clippy::too_many_arguments)]
pub fn g2p(
    weights: Weights<'_>,
    nodal: &[[f64; 4]],
    grid: &Grid,
    prm: G2pParams,
    touched: Touched,
    x: &mut [[f64; 2]],
    v: &mut [[f64; 2]],
    a: &mut [[f64; 2]],
) -> Result<(), Fault> {
    with_weights!(weights, |w| g2p_with(w, nodal, grid, prm, touched, x, v, a))
}

#[allow(clippy::too_many_arguments)]
fn g2p_with<W: ParticleWeights>(
    weights: &W,
    nodal: &[[f64; 4]],
    grid: &Grid,
    prm: G2pParams,
    touched: Touched,
    x: &mut [[f64; 2]],
    v: &mut [[f64; 2]],
    a: &mut [[f64; 2]],
) -> Result<(), Fault> {
    let (touched, mass, pic_dp): (_, &[f64], &mut [[f64; 2]]) = match touched {
        Some((t, m, dp)) => (Some(t), m, dp),
        None => (None, &[], &mut []),
    };
    let update = Update {
        nodal,
        bounds: grid.bounds(prm.edge_margin),
        prm,
        touched,
        mass,
    };
    let fault = match (a.is_empty(), pic_dp.is_empty()) {
        (true, true) => (x.par_iter_mut(), v.par_iter_mut())
            .into_par_iter()
            .enumerate()
            .with_min_len(256)
            .map_init(W::Scratch::default, |sl, (p, (x, v))| {
                crate::cpu::isa::vector(
                    #[inline(always)]
                    || update.with_weights(weights, sl, p, x, v, None, None),
                )
            })
            .reduce(|| None, Fault::first),
        (false, true) => (x.par_iter_mut(), v.par_iter_mut(), a.par_iter_mut())
            .into_par_iter()
            .enumerate()
            .with_min_len(256)
            .map_init(W::Scratch::default, |sl, (p, (x, v, a))| {
                crate::cpu::isa::vector(
                    #[inline(always)]
                    || update.with_weights(weights, sl, p, x, v, Some(a), None),
                )
            })
            .reduce(|| None, Fault::first),
        (true, false) => (x.par_iter_mut(), v.par_iter_mut(), pic_dp.par_iter_mut())
            .into_par_iter()
            .enumerate()
            .with_min_len(256)
            .map_init(W::Scratch::default, |sl, (p, (x, v, d))| {
                crate::cpu::isa::vector(
                    #[inline(always)]
                    || update.with_weights(weights, sl, p, x, v, None, Some(d)),
                )
            })
            .reduce(|| None, Fault::first),
        (false, false) => (
            x.par_iter_mut(),
            v.par_iter_mut(),
            a.par_iter_mut(),
            pic_dp.par_iter_mut(),
        )
            .into_par_iter()
            .enumerate()
            .with_min_len(256)
            .map_init(W::Scratch::default, |sl, (p, (x, v, a, d))| {
                crate::cpu::isa::vector(
                    #[inline(always)]
                    || update.with_weights(weights, sl, p, x, v, Some(a), Some(d)),
                )
            })
            .reduce(|| None, Fault::first),
    };
    fault.map_or(Ok(()), Err)
}
