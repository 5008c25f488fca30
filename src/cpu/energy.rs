//! Energy diagnostics on the CPU: the sum of `Energy::of_particle` over all
//! particles. GPU twin: `shaders/energy.wgsl`.

use crate::model::Model;
use crate::model::energy::Energy;
use rayon::prelude::*;

pub fn energy(model: &Model) -> Energy {
    (0..model.particles.len())
        .into_par_iter()
        .with_min_len(1024)
        .map(|i| Energy::of_particle(model, i))
        .reduce(Energy::default, |a, b| a + b)
}
