//! A 4M-particle LME scene runs a few steps on whatever adapter exists (the
//! software adapter in CI): buffers split per field stay under the binding
//! limit (llvmpipe: 128 MiB), memory stays under the SPEC's 200 bytes per
//! particle, and the steps complete without a fault. An elastoplastic LME
//! scene (Mohr–Coulomb: σzz and plastic strains per particle) stays under
//! the same bound.

use crate::common;

use lme_mpm::backend::Backend;
use lme_mpm::bench;
use lme_mpm::gpu::GpuBackend;
use lme_mpm::model::Model;

/// SPEC target for elastic LME runs.
const MAX_BYTES_PER_PARTICLE: f64 = 200.0;

#[test]
fn four_million_lme_particles_step_on_the_gpu() {
    let Some(ctx) = common::gpu::open("four_million_lme_particles_step_on_the_gpu", false) else {
        return;
    };
    let limit = ctx.limits.max_storage_buffer_binding_size;
    let case = bench::Case::new("lme-g3", &["solver.shape=lme", "solver.lme_gamma=3"]);
    let scene = bench::scene(4_000_000, &case).unwrap();
    let model = Model::new(&scene).unwrap();
    let n = model.particles.len();
    assert!(n >= 4_000_000, "{n} particles");
    let mut gpu = GpuBackend::new(ctx, model).unwrap();
    let bpp = gpu.bytes_per_particle();
    println!(
        "{n} particles, {bpp:.1} bytes per particle, binding limit {} MiB",
        limit >> 20
    );
    assert!(bpp <= MAX_BYTES_PER_PARTICLE, "{bpp} bytes per particle");
    let t0 = std::time::Instant::now();
    gpu.advance_steps(3).unwrap_or_else(|h| panic!("{h:?}"));
    println!("3 steps in {:.1} s", t0.elapsed().as_secs_f64());
    assert_eq!(gpu.steps(), 3);
    let s = gpu.sample().unwrap();
    assert!(s.energy.kinetic.is_finite() && s.energy.kinetic > 0.0);
    let p = gpu.particles().unwrap();
    assert!(p.v.iter().all(|v| v[0].is_finite() && v[1].is_finite()));
}

/// Mohr–Coulomb adds one vec4<f32> per particle (σzz, ε̄p, εp_v, return):
/// 16 bytes over the elastic scene. 1M particles (the grid's share is
/// that of the 4M run within a byte); the buffers alone are made.
#[test]
fn elastoplastic_lme_stays_under_the_memory_bound() {
    let Some(ctx) = common::gpu::open("elastoplastic_lme_stays_under_the_memory_bound", false)
    else {
        return;
    };
    let elastic = bench::Case::new("lme-g3", &["solver.shape=lme", "solver.lme_gamma=3"]);
    let plastic = bench::Case::new(
        "lme-g3-mc",
        &[
            "solver.shape=lme",
            "solver.lme_gamma=3",
            "materials.m.model=mohr_coulomb",
            "materials.m.cohesion=1e3",
            "materials.m.friction_angle=30",
        ],
    );
    let bpp = |case: &bench::Case| {
        let model = Model::new(&bench::scene(1_000_000, case).unwrap()).unwrap();
        (
            model.particles.plastic.is_empty(),
            lme_mpm::gpu::buffers::Buffers::new(
                &ctx,
                &model,
                &lme_mpm::gpu::params(&model),
                &Default::default(),
            )
            .unwrap()
            .bytes() as f64
                / model.particles.len() as f64,
        )
    };
    let (no_state, e) = bpp(&elastic);
    let (no_plastic, p) = bpp(&plastic);
    println!("LME elastic {e:.1}, Mohr–Coulomb {p:.1} bytes per particle");
    assert!(no_state && !no_plastic);
    assert!(
        (p - e - 16.0).abs() < 0.5,
        "the plastic state costs {} bytes",
        p - e
    );
    assert!(p <= MAX_BYTES_PER_PARTICLE, "{p} bytes per particle");
}
