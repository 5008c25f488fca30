//! Particle-to-node scatter without races: the particles are split into one
//! contiguous range per worker thread, each range adds into its own copy of
//! the node array, and the copies are summed node by node. The split depends
//! only on the thread count, so results are repeatable on a given machine.
//! (The GPU twin uses atomics instead: `shaders/shared/atomics.wgsl`.)

use rayon::prelude::*;

/// Nodes per task in the reduction.
const REDUCE_CHUNK: usize = 4096;

/// Private per-thread node arrays, kept between steps (no allocation per step).
#[derive(Debug, Default)]
pub struct Scatter<const K: usize> {
    scratch: Vec<[f64; K]>,
}

impl<const K: usize> Scatter<K> {
    /// Adds `kernel(p, acc)` for every particle `p` in `0..n_particles` into
    /// `out` (which `clear_grid` zeroed); the kernel adds its contributions
    /// into `acc`, an array as long as `out`.
    pub fn run(
        &mut self,
        out: &mut [[f64; K]],
        n_particles: usize,
        kernel: impl Fn(usize, &mut [[f64; K]]) + Sync,
    ) {
        let n_nodes = out.len();
        let threads = rayon::current_num_threads().clamp(1, n_particles.max(1));
        if threads == 1 {
            (0..n_particles).for_each(|p| kernel(p, out));
            return;
        }
        if self.scratch.len() != threads * n_nodes {
            self.scratch = vec![[0.0; K]; threads * n_nodes];
        }
        let per = n_particles.div_ceil(threads);
        self.scratch
            .par_chunks_mut(n_nodes)
            .enumerate()
            .for_each(|(t, acc)| {
                acc.fill([0.0; K]);
                let end = ((t + 1) * per).min(n_particles);
                (t * per..end).for_each(|p| kernel(p, acc));
            });
        self.reduce_into(out, threads);
    }
}

impl<const K: usize> Scatter<K> {
    /// Adds the first `copies` private node arrays into `out`, node by node
    /// in thread order (the same sums every run).
    fn reduce_into(&self, out: &mut [[f64; K]], copies: usize) {
        let n_nodes = out.len();
        let scratch = &self.scratch;
        out.par_chunks_mut(REDUCE_CHUNK)
            .enumerate()
            .for_each(|(c, chunk)| {
                let base = c * REDUCE_CHUNK;
                for (k, o) in chunk.iter_mut().enumerate() {
                    let mut sum = *o;
                    for t in 0..copies {
                        let v = &scratch[t * n_nodes + base + k];
                        for d in 0..K {
                            sum[d] += v[d];
                        }
                    }
                    *o = sum;
                }
            });
    }

    /// Particles per worker range for `n_particles` (the split `run` uses).
    pub fn range_len(n_particles: usize) -> usize {
        let threads = rayon::current_num_threads().clamp(1, n_particles.max(1));
        n_particles.div_ceil(threads).max(1)
    }

    /// Like `run`, for a kernel that also updates per-particle state: `ranges`
    /// yields, for each worker range of `range_len(n_particles)` particles in
    /// order, the caller's mutable chunks of its particle arrays (e.g.
    /// `stress.par_chunks_mut(len)`), and `kernel(first particle, chunks,
    /// acc)` runs the range. Returns the kernels' results folded by `fold`.
    pub fn run_ranges<C: Send, R: Send>(
        &mut self,
        out: &mut [[f64; K]],
        n_particles: usize,
        ranges: impl IndexedParallelIterator<Item = C>,
        kernel: impl Fn(usize, C, &mut [[f64; K]]) -> R + Sync,
        fold: impl Fn(R, R) -> R + Sync + Send,
        none: impl Fn() -> R + Sync + Send,
    ) -> R {
        if n_particles == 0 {
            return none();
        }
        let (r, used) = self.accumulate(out.len(), n_particles, ranges, kernel, fold, none);
        self.reduce_into(out, used);
        r
    }

    /// The first half of `run_ranges`: each worker range adds into its
    /// own copy of `n_nodes` nodes, left in the scatter; returns the
    /// kernels' folded result and how many copies hold sums, for
    /// `reduce_map` once the caller knows how to finish them.
    pub fn accumulate<C: Send, R: Send>(
        &mut self,
        n_nodes: usize,
        n_particles: usize,
        ranges: impl IndexedParallelIterator<Item = C>,
        kernel: impl Fn(usize, C, &mut [[f64; K]]) -> R + Sync,
        fold: impl Fn(R, R) -> R + Sync + Send,
        none: impl Fn() -> R + Sync + Send,
    ) -> (R, usize) {
        let threads = rayon::current_num_threads().clamp(1, n_particles.max(1));
        let per = Self::range_len(n_particles);
        let used = n_particles.div_ceil(per).max(1);
        if self.scratch.len() != threads * n_nodes {
            self.scratch = vec![[0.0; K]; threads * n_nodes];
        }
        let r = self
            .scratch
            .par_chunks_mut(n_nodes)
            .take(used)
            .zip(ranges)
            .enumerate()
            .map(|(t, (acc, c))| {
                acc.fill([0.0; K]);
                crate::cpu::isa::vector(
                    #[inline(always)]
                    || kernel(t * per, c, acc),
                )
            })
            .reduce(&none, &fold);
        (r, used)
    }

    /// Writes `finish(Σ copies)` into each node of `out` (the sums of the
    /// first `copies` node arrays `accumulate` left, node by node in
    /// thread order: the sums `run_ranges` adds).
    pub fn reduce_map<const M: usize>(
        &self,
        out: &mut [[f64; M]],
        copies: usize,
        finish: impl Fn([f64; K]) -> [f64; M] + Sync,
    ) {
        let n_nodes = out.len();
        let scratch = &self.scratch;
        out.par_chunks_mut(REDUCE_CHUNK)
            .enumerate()
            .for_each(|(c, chunk)| {
                let base = c * REDUCE_CHUNK;
                for (k, o) in chunk.iter_mut().enumerate() {
                    let mut sum = [0.0; K];
                    for t in 0..copies {
                        let v = &scratch[t * n_nodes + base + k];
                        for d in 0..K {
                            sum[d] += v[d];
                        }
                    }
                    *o = finish(sum);
                }
            });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scatter_sums_every_contribution_once() {
        let mut s = Scatter::<2>::default();
        let mut out = vec![[0.0; 2]; 10];
        s.run(&mut out, 1000, |p, acc| {
            acc[p % 10][0] += 1.0;
            acc[(p * 7) % 10][1] += p as f64;
        });
        for (i, o) in out.iter().enumerate() {
            assert_eq!(o[0], 100.0);
            let expect: f64 = (0..1000)
                .filter(|p| (p * 7) % 10 == i)
                .map(|p| p as f64)
                .sum();
            assert_eq!(o[1], expect);
        }
    }
}
