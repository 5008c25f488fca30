//! Pass `pore_flow` (saturated soil, stage `stress`, after the effective
//! stress): the pore pressure's update from the fluid's mass balance
//! (`model::pore`), (n / K_w) ṗ = −∇·v − ∇·w, w = −κ (∇p − ρ_w b), in its
//! weak form on the grid with a lumped capacity:
//!   C_I ṗ_I = −Σ_p V_p N_I tr L_p + Σ_p V_p ∇N_I · w_p,  C_I = Σ_p V_p N_I S_p,
//! S = n / K_w, κ = k / γ_w, w_p from the nodal pressure
//! p_I = Σ V N p / Σ V N (saturated particles only), ∇p_p = Σ ∇N_I p_I.
//! Drained nodes hold their pressure (`[drainage]`), except the ghosts
//! beyond a half-plane's face row, which take the antisymmetric image of
//! their mirror (`Drain::ghosts`); every other boundary is impermeable (no
//! flux term). Each particle then takes Δp_p =
//! Σ N_I Δp_I. With `solver.pore_volumetric = "particle"` the −tr L term
//! is the particle's own, −Δt tr L_p / S_p, instead of the nodes':
//! equal-order u–p, whose pressure oscillates from particle to particle
//! (docs/methods.md, "Saturated soil"). No GPU twin yet: the GPU refuses
//! saturated scenes.

use super::scatter::Scatter;
use super::stage_inputs::{ParticleWeights, Stencil, Weights};
use crate::model::pore::{Fluid, Pore};

/// The pass's work space, kept between steps.
#[derive(Debug, Default)]
pub struct PoreFlow {
    /// Per node: Σ V N, Σ V N p, Σ V N S (the capacity), Σ V N tr L.
    sums: Vec<[f64; 4]>,
    /// Per node: Σ V ∇N · w.
    flux: Vec<[f64; 1]>,
    /// Per node: the pressure p_I, then its change Δp_I.
    p: Vec<f64>,
    /// Per node: the pressure a drained node holds.
    drained: Vec<Option<f64>>,
    /// Drained nodes beyond a half-plane's face row, with their mirror
    /// node and the face's pressure (`Drain::ghosts`).
    ghosts: Vec<(usize, usize, f64)>,
    sums_scatter: Scatter<4>,
    flux_scatter: Scatter<1>,
}

/// What the pass reads of the particles and the grid.
pub struct PoreInputs<'a> {
    pub x: &'a [[f64; 2]],
    /// Nodal [m, v_x, v_y] after the predictor (the stress's velocities).
    pub mv: &'a [[f64; 3]],
    pub mass: &'a [f64],
    pub rho: &'a [f64],
    /// Each particle's material's fluid (None: dry).
    pub fluid: &'a (dyn Fn(usize) -> Option<Fluid> + Sync),
    /// The strain-rate correction the stress took (the cell average), or empty.
    pub dl: &'a [[f64; 4]],
    /// Body force per unit mass (m/s²): the scene's gravity now.
    pub g: [f64; 2],
    pub dt: f64,
}

impl PoreFlow {
    pub fn new(pore: &Pore, n_nodes: usize) -> Self {
        let mut drained = vec![None; n_nodes];
        for d in &pore.drains {
            for &n in &d.nodes {
                drained[n as usize] = Some(d.pressure);
            }
        }
        let ghosts = pore
            .drains
            .iter()
            .flat_map(|d| {
                d.ghosts
                    .iter()
                    .map(|&(g, m)| (g as usize, m as usize, d.pressure))
            })
            .collect();
        PoreFlow {
            ghosts,
            sums: vec![[0.0; 4]; n_nodes],
            flux: vec![[0.0; 1]; n_nodes],
            p: vec![0.0; n_nodes],
            drained,
            ..Default::default()
        }
    }

    /// Advances every saturated particle's pore pressure `pore` by Δt.
    /// The weights are those the stress just used (their faults were its).
    pub fn update(
        &mut self,
        weights: Weights<'_>,
        inp: &PoreInputs<'_>,
        nodal_volumetric: bool,
        pore: &mut [f64],
    ) {
        let n = inp.x.len();
        let w = &weights;
        // 1. Σ V N, Σ V N p, Σ V N S, Σ V N tr L at the nodes.
        self.sums.iter_mut().for_each(|s| *s = [0.0; 4]);
        let p_now: &[f64] = pore;
        self.sums_scatter.run(&mut self.sums, n, |i, acc| {
            let Some(f) = (inp.fluid)(i) else { return };
            let mut slots = Default::default();
            let Ok(st) = w.get::<true>(i, inp.x[i], &mut slots) else {
                return;
            };
            let vol = inp.mass[i] / inp.rho[i];
            let tr = trace_l(&st, inp.mv, inp.dl.get(i));
            let (s, p) = (f.storage(), p_now[i]);
            st.each(|node, wk| {
                let vn = vol * wk[0];
                let a = &mut acc[node as usize];
                a[0] += vn;
                a[1] += vn * p;
                a[2] += vn * s;
                a[3] += vn * tr;
            });
        });
        // 2. The nodal pressure; drained nodes hold theirs.
        for ((pn, s), d) in self.p.iter_mut().zip(&self.sums).zip(&self.drained) {
            *pn = match d {
                Some(held) => *held,
                None if s[0] > 0.0 => s[1] / s[0],
                None => 0.0,
            };
        }
        // A ghost beyond a drained face: the antisymmetric image of its
        // mirror (which has soil), so the face row interpolates p_D.
        for &(g, m, pd) in &self.ghosts {
            if self.sums[m][0] > 0.0 {
                self.p[g] = 2.0 * pd - self.p[m];
            }
        }
        // 3. Σ V ∇N · w, w = −κ (∇p − ρ_w b).
        self.flux.iter_mut().for_each(|f| *f = [0.0]);
        let p_nodes = &self.p;
        self.flux_scatter.run(&mut self.flux, n, |i, acc| {
            let Some(f) = (inp.fluid)(i) else { return };
            if f.k == 0.0 {
                return;
            }
            let mut slots = Default::default();
            let Ok(st) = w.get::<true>(i, inp.x[i], &mut slots) else {
                return;
            };
            let mut grad = [0.0; 2];
            st.each(|node, wk| {
                let p = p_nodes[node as usize];
                grad[0] += wk[1] * p;
                grad[1] += wk[2] * p;
            });
            let kappa = f.mobility();
            let flux = [
                -kappa * (grad[0] - f.rho_w * inp.g[0]),
                -kappa * (grad[1] - f.rho_w * inp.g[1]),
            ];
            let vol = inp.mass[i] / inp.rho[i];
            st.each(|node, wk| {
                acc[node as usize][0] += vol * (wk[1] * flux[0] + wk[2] * flux[1]);
            });
        });
        // 4. Δp_I: the rate over the capacity; none at a drained node,
        //    whose pressure is given (it enters through the gradient).
        for (k, dp) in self.p.iter_mut().enumerate() {
            let s = &self.sums[k];
            *dp = match self.drained[k] {
                Some(_) => 0.0,
                None if s[2] > 0.0 => {
                    let vol = if nodal_volumetric { s[3] } else { 0.0 };
                    inp.dt * (self.flux[k][0] - vol) / s[2]
                }
                None => 0.0,
            };
        }
        for &(g, m, _) in &self.ghosts {
            if self.sums[m][0] > 0.0 {
                self.p[g] = -self.p[m];
            }
        }
        // 5. Each saturated particle takes its share.
        let dp_nodes = &self.p;
        use rayon::prelude::*;
        pore.par_iter_mut()
            .enumerate()
            .with_min_len(256)
            .for_each_init(Default::default, |slots, (i, p)| {
                let Some(f) = (inp.fluid)(i) else { return };
                let Ok(st) = w.get::<true>(i, inp.x[i], slots) else {
                    return;
                };
                let mut dp = 0.0;
                st.each(|node, wk| dp += wk[0] * dp_nodes[node as usize]);
                if !nodal_volumetric {
                    dp -= inp.dt * trace_l(&st, inp.mv, inp.dl.get(i)) / f.storage();
                }
                *p += dp;
            });
    }
}

/// tr L = Σ v_I · ∇N_I at a particle, plus the trace of the correction the
/// stress took (`dl`, the cell average).
fn trace_l(st: &impl Stencil, mv: &[[f64; 3]], dl: Option<&[f64; 4]>) -> f64 {
    let mut tr = 0.0;
    st.each(|node, wk| {
        let v = &mv[node as usize];
        tr += v[1] * wk[1] + v[2] * wk[2];
    });
    tr + dl.map_or(0.0, |d| d[0] + d[3])
}
