//! Energy diagnostics on the CPU: the sum of `Energy::of_particle` over all
//! particles. GPU twin: `shaders/energy.wgsl`.

use crate::model::Model;
use crate::model::energy::Energy;
use rayon::prelude::*;

/// Particles per partial sum. Fixed chunks summed in order make the total
/// the same from run to run (rayon's adaptive `reduce` groups the terms by
/// how work happened to be stolen, which changes the last bits).
const CHUNK: usize = 1024;

pub fn energy(model: &Model) -> Energy {
    let n = model.particles.len();
    let partial: Vec<Energy> = (0..n.div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| {
            (c * CHUNK..((c + 1) * CHUNK).min(n))
                .map(|i| Energy::of_particle(model, i))
                .fold(Energy::default(), |a, b| a + b)
        })
        .collect();
    partial.into_iter().fold(Energy::default(), |a, b| a + b)
}
