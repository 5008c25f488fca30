//! Stage `stress`: velocity gradient from the (predicted) nodal velocities,
//! L = Σ_I v_I ⊗ ∇N_I, then the material's update over Δt (paper Algorithm 1,
//! steps 4–5; update stress first): linear elastic adds D : Δε with
//! Δε = Δt sym(L); Neo-Hookean updates F ← (I + Δt L) F and evaluates σ(F);
//! Mohr–Coulomb and Drucker–Prager take a Jaumann trial and return it to
//! the yield surface, updating the plastic state (σzz, plastic strains).
//! The density follows the volume ratio the material returns.
//! GPU twin: `shaders/stress.wgsl`.

use super::forces::add_particle_forces;
use super::scatter::Scatter;
use super::stage_inputs::{
    BATCH, BodyForce, ParticleWeights, Stencil, Weights, optional, optional_chunks, with_weights,
};
use crate::model::fault::{Fault, FaultKind};
use crate::model::material::{Material, PlasticState};
use rayon::prelude::*;

/// The state a particle may carry beyond its stress: F, the plastic state.
/// Empty vectors (fields the scene does not use) give `None` per particle.
type Extra<'a> = (Option<&'a mut [f64; 4]>, Option<&'a mut PlasticState>);

#[allow(clippy::too_many_arguments)]
pub fn stress(
    weights: Weights<'_>,
    x: &[[f64; 2]],
    mv: &[[f64; 3]],
    dt: f64,
    body: &[u32],
    materials: &[Material],
    body_material: &[u32],
    stress: &mut [[f64; 3]],
    rho: &mut [f64],
    f: &mut [[f64; 4]],
    plastic: &mut [PlasticState],
    dl: &[[f64; 4]],
) -> Result<(), Fault> {
    let n = stress.len();
    let fault = with_weights!(weights, |weights| (
        stress.par_iter_mut(),
        rho.par_iter_mut(),
        optional(f, n),
        optional(plastic, n),
    )
        .into_par_iter()
        .enumerate()
        .with_min_len(256)
        .map_init(Default::default, |slots, (p, (s, r, f, q))| {
            crate::cpu::isa::vector(
                #[inline(always)]
                || {
                    let st = match weights.get::<true>(p, x[p], slots) {
                        Ok(st) => st,
                        Err(e) => return Some(Fault::at(p, FaultKind::Shape(e))),
                    };
                    update_particle(
                        &st,
                        mv,
                        dt,
                        &materials[body_material[body[p] as usize] as usize],
                        p,
                        s,
                        r,
                        (f, q),
                        dl.get(p),
                    )
                },
            )
        })
        .reduce(|| None, Fault::first));
    fault.map_or(Ok(()), Err)
}

/// Particle p's velocity gradient and material update (the whole stage for
/// one particle), from its nodes and weights.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn update_particle(
    st: &impl Stencil,
    mv: &[[f64; 3]],
    dt: f64,
    material: &Material,
    p: usize,
    s: &mut [f64; 3],
    r: &mut f64,
    extra: Extra<'_>,
    dl: Option<&[f64; 4]>,
) -> Option<Fault> {
    // Velocity gradient L_ij = Σ v_i ∂N/∂x_j.
    let mut l = [0.0; 4];
    st.each(|node, wk| {
        let v = &mv[node as usize];
        l[0] += v[1] * wk[1];
        l[1] += v[1] * wk[2];
        l[2] += v[2] * wk[1];
        l[3] += v[2] * wk[2];
    });
    // `solver.mls_scope = "force"`: the transpose of the force's bracket
    // (`Mls::strain_correction`), so that the stress does the forces' work.
    if let Some(d) = dl {
        for (a, b) in l.iter_mut().zip(d) {
            *a += b;
        }
    }
    // Fields the scene does not keep are stand-ins the models ignore.
    let (mut id, mut q0) = ([1.0, 0.0, 0.0, 1.0], [0.0; 4]);
    let f = extra.0.unwrap_or(&mut id);
    let q = extra.1.unwrap_or(&mut q0);
    match material.update(l, dt, s, f, q) {
        Err(kind) => Some(Fault::at(p, kind)),
        Ok(j) => {
            *r /= j;
            if !(s[0].is_finite() && s[1].is_finite() && s[2].is_finite()) {
                return Some(Fault::at(p, FaultKind::NonFinite { field: "stress" }));
            }
            None
        }
    }
}

/// Stages `stress` then `forces` in one pass over the particles (what a
/// whole step runs without MLS; twin of stress.wgsl built with FORCES): each
/// particle's update, then its forces from the stress just computed, with
/// the weights read (or evaluated) once. The same sums as the two stages,
/// in the same order per node and thread, so the same result.
#[allow(clippy::too_many_arguments)]
pub fn stress_forces(
    weights: Weights<'_>,
    x: &[[f64; 2]],
    mv: &[[f64; 3]],
    dt: f64,
    body: &[u32],
    materials: &[Material],
    body_material: &[u32],
    mass: &[f64],
    body_force: &BodyForce<'_>,
    stress: &mut [[f64; 3]],
    rho: &mut [f64],
    f: &mut [[f64; 4]],
    plastic: &mut [PlasticState],
    force: &mut [[f64; 2]],
    scatter: &mut Scatter<2>,
) -> Result<(), Fault> {
    let inputs = StressInputs {
        x,
        mv,
        dt,
        body,
        materials,
        body_material,
        mass,
        body_force,
    };
    with_weights!(weights, |w| stress_forces_with(
        w, &inputs, stress, rho, f, plastic, force, scatter
    ))
}

/// What `stress_forces` reads besides the weights.
struct StressInputs<'a> {
    x: &'a [[f64; 2]],
    mv: &'a [[f64; 3]],
    dt: f64,
    body: &'a [u32],
    materials: &'a [Material],
    body_material: &'a [u32],
    mass: &'a [f64],
    body_force: &'a BodyForce<'a>,
}

impl StressInputs<'_> {
    /// Particle p's update, then its forces from the stress just
    /// computed, from the weights `prepare` left in lane `j` of `batch`.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn particle<W: ParticleWeights>(
        &self,
        weights: &W,
        p: usize,
        s: &mut [f64; 3],
        r: &mut f64,
        extra: Extra<'_>,
        batch: &W::Batch,
        j: usize,
        acc: &mut [[f64; 2]],
    ) -> Option<Fault> {
        let inp = self;
        let material = &inp.materials[inp.body_material[inp.body[p] as usize] as usize];
        let st = match weights.view(p, batch, j) {
            Ok(st) => st,
            Err(e) => return Some(Fault::at(p, FaultKind::Shape(e))),
        };
        if let Some(fault) = update_particle(&st, inp.mv, inp.dt, material, p, s, r, extra, None) {
            return Some(fault);
        }
        let g = inp.body_force.at(p);
        let m = inp.mass[p];
        add_particle_forces(&st, m / *r, *s, [m * g[0], m * g[1]], acc);
        None
    }
}

#[allow(clippy::too_many_arguments)]
fn stress_forces_with<W: ParticleWeights>(
    weights: &W,
    inp: &StressInputs<'_>,
    stress: &mut [[f64; 3]],
    rho: &mut [f64],
    f: &mut [[f64; 4]],
    plastic: &mut [PlasticState],
    force: &mut [[f64; 2]],
    scatter: &mut Scatter<2>,
) -> Result<(), Fault> {
    let n = inp.mass.len();
    let len = Scatter::<2>::range_len(n);
    let ranges = (
        stress.par_chunks_mut(len),
        rho.par_chunks_mut(len),
        optional_chunks(f, n, len),
        optional_chunks(plastic, n, len),
    )
        .into_par_iter();
    let fault = scatter.run_ranges(
        force,
        n,
        ranges,
        #[inline(always)]
        |first, (s, r, mut f, mut q), acc| {
            let mut fault = None;
            let mut batch = W::Batch::default();
            for (b, (s, r)) in s.chunks_mut(BATCH).zip(r.chunks_mut(BATCH)).enumerate() {
                let k0 = b * BATCH;
                let at = first + k0;
                weights.prepare::<true>(at, &inp.x[at..at + s.len()], &mut batch);
                for (j, (s, r)) in s.iter_mut().zip(r).enumerate() {
                    let k = k0 + j;
                    let extra = (
                        f.as_deref_mut().map(|f| &mut f[k]),
                        q.as_deref_mut().map(|q| &mut q[k]),
                    );
                    let f = inp.particle(weights, first + k, s, r, extra, &batch, j, acc);
                    Fault::note(&mut fault, f);
                }
            }
            fault
        },
        Fault::first,
        || None,
    );
    fault.map_or(Ok(()), Err)
}
