//! Stage `forces`: scatter internal and external nodal forces,
//! f_I = Σ_p (−V_p σ_p ∇N_I + N_I m_p b) (paper eq. 14; V_p = m_p / ρ_p);
//! in saturated soil σ_p is the total stress σ' − p I (`model::pore`).
//! GPU twin: `shaders/forces.wgsl`.

use super::scatter::Scatter;
use super::stage_inputs::{BodyForce, ParticleWeights, Stencil, Weights, with_weights};
use crate::model::fault::{Fault, FaultKind};
use crate::model::node_force;
use rayon::prelude::*;

/// `body` gives particle p's body force per unit mass at this step (m/s²):
/// gravity, plus a manufactured solution's source term when there is one.
/// `x` is where `weights` are evaluated when not stored. `pore` is the
/// particles' pore pressure (Pa, compression positive; empty when dry):
/// `stress` is then the effective stress.
#[allow(clippy::too_many_arguments)]
pub fn forces(
    weights: Weights<'_>,
    x: &[[f64; 2]],
    stress: &[[f64; 3]],
    pore: &[f64],
    mass: &[f64],
    rho: &[f64],
    body: &BodyForce<'_>,
    force: &mut [[f64; 2]],
    scatter: &mut Scatter<2>,
) -> Result<(), Fault> {
    with_weights!(weights, |w| forces_with(
        w, x, stress, pore, mass, rho, body, force, scatter
    ))
}

#[allow(clippy::too_many_arguments)]
fn forces_with<W: ParticleWeights>(
    weights: &W,
    x: &[[f64; 2]],
    stress: &[[f64; 3]],
    pore: &[f64],
    mass: &[f64],
    rho: &[f64],
    body: &BodyForce<'_>,
    force: &mut [[f64; 2]],
    scatter: &mut Scatter<2>,
) -> Result<(), Fault> {
    let n = mass.len();
    let len = Scatter::<2>::range_len(n);
    let fault = scatter.run_ranges(
        force,
        n,
        (0..n.div_ceil(len)).into_par_iter(),
        #[inline(always)]
        |first, _, acc| {
            let mut slots = W::Scratch::default();
            let mut fault = None;
            for p in first..(first + len).min(n) {
                let vol = mass[p] / rho[p];
                let mut s = stress[p];
                if let Some(pw) = pore.get(p) {
                    s[0] -= pw;
                    s[1] -= pw;
                }
                let g = body.at(p);
                let (bx, by) = (mass[p] * g[0], mass[p] * g[1]);
                match weights.get::<true>(p, x[p], &mut slots) {
                    Ok(st) => add_particle_forces(&st, vol, s, [bx, by], acc),
                    Err(e) => Fault::note(&mut fault, Some(Fault::at(p, FaultKind::Shape(e)))),
                }
            }
            fault
        },
        Fault::first,
        || None,
    );
    fault.map_or(Ok(()), Err)
}

/// Adds a particle's −V_p σ_p ∇N + N m_p b to its nodes in `acc` (`mb` is
/// m_p b). Shared with the fused `stress::stress_forces`.
#[inline(always)]
pub fn add_particle_forces(
    st: &impl Stencil,
    vol: f64,
    s: [f64; 3],
    mb: [f64; 2],
    acc: &mut [[f64; 2]],
) {
    st.each(|node, wk| {
        let acc = &mut acc[node as usize];
        let f = node_force(vol, s, &wk, mb);
        acc[0] += f[0];
        acc[1] += f[1];
    });
}
