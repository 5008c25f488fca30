//! Stage `clear_grid`: zero the nodal mass, momentum and force accumulators
//! before the scatters add into them. GPU twin: `shaders/clear_grid.wgsl`.

use rayon::prelude::*;

pub fn clear_grid(mv: &mut [[f64; 3]], force: &mut [[f64; 2]]) {
    mv.par_iter_mut()
        .with_min_len(4096)
        .for_each(|m| *m = [0.0; 3]);
    force
        .par_iter_mut()
        .with_min_len(4096)
        .for_each(|f| *f = [0.0; 2]);
}
