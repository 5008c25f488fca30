//! Energy diagnostics (not a step stage): kinetic and stored elastic energy,
//! and a bound on the work gravity can have done, for the runaway check and
//! `energy.csv`. GPU twin: `shaders/energy.wgsl`.

use crate::model::Model;
use rayon::prelude::*;

/// Energies per unit thickness (J/m).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Energy {
    pub kinetic: f64,
    pub strain: f64,
    /// Σ m_p |g| |x_p − x0_p|: no more work than this can gravity have done.
    pub gravity_work_bound: f64,
}

pub fn energy(model: &Model) -> Energy {
    let p = &model.particles;
    let g = model.gravity.map_or(0.0, |g| g.g[0].hypot(g.g[1]));
    (0..p.len())
        .into_par_iter()
        .with_min_len(1024)
        .map(|i| {
            let v = p.v[i];
            let d = [p.x[i][0] - p.x0[i][0], p.x[i][1] - p.x0[i][1]];
            Energy {
                kinetic: 0.5 * p.mass[i] * (v[0] * v[0] + v[1] * v[1]),
                strain: p.volume(i)
                    * model.material_of(i).strain_energy_density(
                        &p.stress[i],
                        p.f.get(i).unwrap_or(&[1.0, 0.0, 0.0, 1.0]),
                    ),
                gravity_work_bound: p.mass[i] * g * d[0].hypot(d[1]),
            }
        })
        .reduce(Energy::default, |a, b| Energy {
            kinetic: a.kinetic + b.kinetic,
            strain: a.strain + b.strain,
            gravity_work_bound: a.gravity_work_bound + b.gravity_work_bound,
        })
}
