//! The CPU path allocates nothing per step: buffers are made when the
//! backend is built (and the scatter scratch on its first use). Counted with
//! a global allocator over whole steps of every shape and integrator, with
//! and without MLS.

mod common;

use lme_mpm::cpu::CpuBackend;
use lme_mpm::model::Model;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

const STEPS: usize = 500;

/// Allocations during `STEPS` steps of each configuration, in a pool of `threads`.
fn allocations(threads: usize) -> Vec<(String, usize)> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let mut out = Vec::new();
        for (case, sets) in [
            ("elastic_block.toml", &["solver.shape=lme"][..]),
            (
                "elastic_block.toml",
                &["solver.shape=linear", "solver.integrator=fe"],
            ),
            ("elastic_block.toml", &["solver.shape=ugimp"]),
            // B-spline, Neo-Hookean F, manufactured body force, MLS.
            (
                "aligned_vibration.toml",
                &[
                    "grid.h=0.125",
                    "solver.mls=true",
                    "solver.mls_scope=all",
                    "solver.shape=bspline2",
                ],
            ),
            // MLS as the force correction, with its strain-rate correction.
            (
                "aligned_vibration.toml",
                &[
                    "grid.h=0.125",
                    "solver.mls=true",
                    "solver.mls_scope=force",
                    "solver.shape=bspline2",
                    "solver.integrator=musl",
                ],
            ),
            ("aligned_vibration.toml", &["grid.h=0.125"]),
            // B-splines on walls with a geostatic preload: the preload's
            // weights at the wall's line (`wall_touch::LineWeights`).
            ("granular_collapse.toml", &["grid.h=0.1"]),
        ] {
            let scene = common::scene(case, sets);
            let mut b = CpuBackend::new(Model::new(&scene).unwrap());
            // Warm-up: the pool's threads start and the scatter scratch is sized.
            for _ in 0..3 {
                b.step().unwrap();
            }
            let before = ALLOCATIONS.load(Ordering::SeqCst);
            for _ in 0..STEPS {
                b.step().unwrap();
            }
            let n = ALLOCATIONS.load(Ordering::SeqCst) - before;
            out.push((format!("{case} {sets:?}"), n));
        }
        out
    })
}

/// Allocations allowed in `STEPS` steps. Our code makes none; rayon's
/// work-stealing deques can resize their buffers a few times when the
/// machine is loaded and jobs queue up differently (we saw 2 to 4 in 500
/// steps with another simulation running, 0 on an idle machine). A per-step
/// allocation would show as 500 or more.
const ALLOWED: usize = 10;

#[test]
fn steps_do_not_allocate() {
    // One thread, and two (the private-grid scatter path).
    for threads in [1, 2] {
        for (what, n) in allocations(threads) {
            assert!(
                n <= ALLOWED,
                "{what}: {n} allocations in {STEPS} steps on {threads} thread(s)"
            );
        }
    }
}
