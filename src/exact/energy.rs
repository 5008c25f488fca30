//! Energy kept (`energy`): with no gravity, loads, prescribed velocities,
//! walls or manufactured field doing work, an elastic body's kinetic plus
//! strain energy stays what it was at the start. What the run loses (the
//! integrator's dissipation, and the particles that meet fixed nodes, as
//! the plate impact's wall) is the figure.

use crate::backend::Sample;
use serde::Serialize;

/// Figures for `summary.json`.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct EnergyErrors {
    /// Kinetic + strain energy at the first sample (J per m of thickness).
    pub energy_start: f64,
    /// Kinetic and strain energy at the last sample.
    pub kinetic: f64,
    pub strain: f64,
    /// (kinetic + strain) / energy_start.
    pub kept: f64,
}

pub fn score(samples: &[Sample]) -> EnergyErrors {
    let total = |s: &Sample| s.energy.kinetic + s.energy.strain;
    let start = samples.first().map_or(f64::NAN, total);
    let (kinetic, strain) = samples.last().map_or((f64::NAN, f64::NAN), |s| {
        (s.energy.kinetic, s.energy.strain)
    });
    EnergyErrors {
        energy_start: start,
        kinetic,
        strain,
        kept: (kinetic + strain) / start,
    }
}
