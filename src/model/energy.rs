//! Energy diagnostics (not a step stage): kinetic and stored elastic energy,
//! and a bound on the work gravity can have done, for the runaway check and
//! `energy.csv`. The per-particle formula is here; the CPU reduction is
//! `cpu/energy.rs`, the GPU one `shaders/energy.wgsl`.

use crate::model::Model;

/// Energies per unit thickness (J/m).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Energy {
    pub kinetic: f64,
    pub strain: f64,
    /// Σ (m_p |g| + |F_p|) |x_p − x0_p|: no more work than this can gravity
    /// and the tractions and point loads (F_p at full value) have done.
    pub gravity_work_bound: f64,
}

impl Energy {
    /// Particle `i`'s share.
    pub fn of_particle(model: &Model, i: usize) -> Energy {
        let p = &model.particles;
        let g = model.gravity.map_or(0.0, |g| g.g[0].hypot(g.g[1]));
        let v = p.v[i];
        let d = [p.x[i][0] - p.x0[i][0], p.x[i][1] - p.x0[i][1]];
        Energy {
            kinetic: 0.5 * p.mass[i] * (v[0] * v[0] + v[1] * v[1]),
            strain: p.volume(i)
                * model.material_of(i).strain_energy_density(
                    &p.stress[i],
                    p.f.get(i).unwrap_or(&[1.0, 0.0, 0.0, 1.0]),
                    p.plastic.get(i).unwrap_or(&[0.0; 4]),
                ),
            gravity_work_bound: (p.mass[i] * g
                + model
                    .external
                    .as_ref()
                    .map_or(0.0, |e| e.force[i][0].hypot(e.force[i][1])))
                * d[0].hypot(d[1]),
        }
    }
}

impl std::ops::Add for Energy {
    type Output = Energy;
    fn add(self, b: Energy) -> Energy {
        Energy {
            kinetic: self.kinetic + b.kinetic,
            strain: self.strain + b.strain,
            gravity_work_bound: self.gravity_work_bound + b.gravity_work_bound,
        }
    }
}
