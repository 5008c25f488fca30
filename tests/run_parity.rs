//! Whole-run parity: Dyka's bar (1 mm cells), the elastic block, the
//! manufactured vibration, a two-material impact and a Mohr–Coulomb slump
//! run on the CPU (f64)
//! and the GPU (f32). Probe and energy histories and final fields must
//! agree within the tolerances below, and the GPU's error against the exact
//! solution (where there is one) must be within 10% of the CPU's.

use crate::common;

use lme_mpm::backend::{Backend, Sample};
use lme_mpm::cpu::CpuBackend;
use lme_mpm::exact::Errors;
use lme_mpm::gpu::GpuBackend;
use lme_mpm::model::{Model, Particles};
use lme_mpm::scene::{Override, Scene};
use lme_mpm::simulation::Simulation;
use lme_mpm::solver::{Recorder, RunStatus, Schedule};

// Sampled energies, as history RMS difference over the largest CPU value of
// each of kinetic, strain and gravity-work bound: 10 times the worst
// measured on llvmpipe (float and compare-exchange atomics), rounded up.
/// Dyka: worst 2.0e-4 (FE, strain; NPC 1.3e-4).
const DYKA_ENERGY_TOL: f64 = 2e-3;
/// Block: worst 1.5e-5 (uGIMP, kinetic).
const BLOCK_ENERGY_TOL: f64 = 2e-4;
/// Manufactured vibration: worst 9.5e-4 (no MLS, strain: f32 Neo-Hookean
/// energy of a 10% stretch).
const MMS_ENERGY_TOL: f64 = 1e-2;
/// Two-material impact: worst 2.3e-6 (LME, strain).
const TWO_MATERIAL_ENERGY_TOL: f64 = 3e-5;
/// Two-material impact, the target probe's vx history and the final
/// velocity fields over the striker's speed, the final stresses over the
/// largest: worst 2.2e-6 (LME, history), 1.8e-6, 1.8e-6. 10 times, rounded up.
const TWO_MATERIAL_TOL: f64 = 3e-5;

/// Block on a frictional incline pushed by a traction and a point load:
/// worst measured 1.1e-4 (LME FE, reaction history; final velocities
/// 1.5e-5, stresses 5.7e-5; Q4 NPC 1.4e-6 to 3.3e-6). 9 times, rounded.
const BOUNDARIES_TOL: f64 = 1e-3;

/// Mohr–Coulomb / Drucker–Prager slump: toe probe vx history, final
/// velocity, stress and ε̄p fields and the energies, each over its largest
/// CPU value: worst 7.0e-6 (LME, final velocity; linear 8.0e-7), 10 times,
/// rounded up.
const SLUMP_TOL: f64 = 7e-5;

/// Cam-clay biaxial, 1605 steps: final stress 3.6e-6 of its largest, p_c
/// 7.2e-5 and v 2.7e-4 of their change over the run (the f32 return stops
/// at 1e-5 on ln p_c, not round-off, each step); 1e-3 is 3.7 times the worst.
const CAM_CLAY_TOL: f64 = 1e-3;

struct Outcome {
    samples: Vec<Sample>,
    particles: Particles,
    errors: Option<Errors>,
    steps: u64,
}

/// `backend` driven through the one `Simulation` every caller uses.
fn run_on(backend: Box<dyn Backend>, scene: &Scene) -> Outcome {
    let mut sim = Simulation::with_backend(scene, backend);
    let mut rec = Recorder::default();
    let schedule = Schedule {
        vtk_interval: None,
        ..sim.schedule()
    };
    let status = sim.drive_with(schedule, &mut rec).unwrap();
    let name = sim.backend_ref().name();
    assert_eq!(status, RunStatus::Completed, "{name}");
    let errors = sim.score().unwrap();
    let backend = sim.backend();
    Outcome {
        samples: rec.samples,
        particles: backend.particles().unwrap().clone(),
        errors,
        steps: backend.steps(),
    }
}

fn both(case: &str, sets: &[&str], force_cas: bool) -> Option<(Outcome, Outcome)> {
    let scene = common::scene(case, sets);
    both_of(case, &scene, force_cas)
}

fn both_of(
    label: &str,
    scene: &lme_mpm::scene::Scene,
    force_cas: bool,
) -> Option<(Outcome, Outcome)> {
    let ctx = common::gpu::open(label, force_cas)?;
    let model = Model::new(scene).unwrap();
    let cpu = run_on(Box::new(CpuBackend::new(model.clone())), scene);
    let gpu = run_on(Box::new(GpuBackend::new(ctx, model).unwrap()), scene);
    assert!(
        cpu.samples.len() >= 3,
        "{label}: {} samples",
        cpu.samples.len()
    );
    Some((cpu, gpu))
}

/// The sampled energies (kinetic, strain, gravity-work bound: they drive
/// the runaway check and energy.csv) compared as history RMS differences
/// relative to the largest CPU value of each, against `tol`. A quantity the
/// CPU has at zero throughout (no gravity) must be zero on the GPU too.
fn check_energy(label: &str, cpu: &Outcome, gpu: &Outcome, tol: f64) {
    type Part = (&'static str, fn(&Sample) -> f64);
    let parts: [Part; 3] = [
        ("kinetic", |s| s.energy.kinetic),
        ("strain", |s| s.energy.strain),
        ("gravity work bound", |s| s.energy.gravity_work_bound),
    ];
    for (name, f) in parts {
        let (rms, scale) = history_rms(&cpu.samples, &gpu.samples, f);
        if scale == 0.0 {
            assert_eq!(rms, 0.0, "{label}: {name} energy zero on the CPU only");
            continue;
        }
        println!(
            "  {label}: {name} energy history RMS diff / max = {:.2e}",
            rms / scale
        );
        assert!(
            rms / scale < tol,
            "{label}: {name} energy differs: {:.3e} of its largest value > {tol:.1e}",
            rms / scale
        );
    }
}

/// RMS of f(GPU sample) − f(CPU sample) over the samples both paths took
/// at the same step, and the largest |f| on the CPU. A sample is taken at
/// the first step end at or after its stop time; with CFL steps the GPU's
/// f32 Δt drifts its time from the CPU's (3e-6 s after 2300 steps of the
/// elastic block), so a stop that falls inside that drift is sampled one
/// step apart (twice in the block's 400 samples on llvmpipe). Such pairs
/// (times differing by more than 1 % of the sample interval; a step is
/// 4–14 % of it in these scenes, the drift at most 0.2 %, in the gate's
/// granular flow) say nothing about parity and are left out; at most one
/// in 20 may be.
fn history_rms(cpu: &[Sample], gpu: &[Sample], f: impl Fn(&Sample) -> f64) -> (f64, f64) {
    let n = cpu.len().min(gpu.len());
    let gap = |k: usize| if k == 0 { 0.0 } else { cpu[k].t - cpu[k - 1].t };
    let same: Vec<usize> = (0..n)
        .filter(|&k| (cpu[k].t - gpu[k].t).abs() <= 0.01 * gap(k) + 1e-12)
        .collect();
    assert!(
        (n - same.len()) * 20 <= n,
        "{} of {n} samples taken a step apart",
        n - same.len()
    );
    let rms = (same
        .iter()
        .map(|&k| (f(&cpu[k]) - f(&gpu[k])).powi(2))
        .sum::<f64>()
        / same.len() as f64)
        .sqrt();
    let scale = cpu.iter().map(|s| f(s).abs()).fold(0.0, f64::max);
    (rms, scale)
}

fn field_rms(a: &[f64], b: &[f64]) -> f64 {
    (a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>() / a.len() as f64).sqrt()
}

/// Dyka: at 1 mm cells the fronts are a few cells wide and every sample
/// is taken within one step of the same time on both backends. f32 shifts
/// a front by a fraction of a step at most; we measure RMS differences of
/// 2.4e-4 (Q4) to 2.5e-3 (LME FE: its ripple amplifies round-off) of the
/// impact speed over the free-end history, and at most 8.7e-4 (velocity)
/// and 8.9e-4 (stress) in the final fields, both LME FE. Bound: 1% of the
/// impact speed (stress: of Z v0), 4 times the worst history, 11 times the
/// worst final field; headroom is not large here, so it stays.
const DYKA_TOL: f64 = 0.01;

#[test]
fn dyka_bar_gpu_matches_cpu() {
    dyka_parity(&[
        (&["solver.shape=lme"][..], false),
        (&["solver.shape=lme", "solver.integrator=fe"][..], false),
        (&["solver.shape=linear"][..], true),
    ]);
}

/// The predicted position reading with LME (about 16 s on 2 cores; the
/// suite holds the reading by `two_material_impact_gpu_matches_cpu`'s
/// bspline2 run):
///   cargo test --release --test suite -- --ignored run_parity::dyka_bar_gpu_matches_cpu_with_predicted_positions
#[test]
#[ignore]
fn dyka_bar_gpu_matches_cpu_with_predicted_positions() {
    dyka_parity(&[(
        &["solver.shape=lme", "solver.npc_position=predicted"][..],
        false,
    )]);
}

fn dyka_parity(configs: &[(&[&str], bool)]) {
    for &(sets, cas) in configs {
        let Some((cpu, gpu)) = both("dyka_bar.toml", sets, cas) else {
            return;
        };
        let (Some(Errors::Dyka(ec)), Some(Errors::Dyka(eg))) = (&cpu.errors, &gpu.errors) else {
            unreachable!()
        };
        println!(
            "{sets:?} cas={cas}: steps cpu {} gpu {}; RMS error cpu {:.4} gpu {:.4}",
            cpu.steps, gpu.steps, ec.rms_velocity, eg.rms_velocity
        );
        let v0 = 5.0;
        let (h_rms, _) = history_rms(&cpu.samples, &gpu.samples, |s| s.probes[0].v[0]);
        let vc: Vec<f64> = cpu.particles.v.iter().map(|v| v[0]).collect();
        let vg: Vec<f64> = gpu.particles.v.iter().map(|v| v[0]).collect();
        let f_rms = field_rms(&vc, &vg);
        let sc: Vec<f64> = cpu.particles.stress.iter().map(|s| s[0]).collect();
        let sg: Vec<f64> = gpu.particles.stress.iter().map(|s| s[0]).collect();
        let z = (200e9f64 * 7833.0).sqrt();
        let s_rms = field_rms(&sc, &sg) / (z * v0);
        println!(
            "  free-end velocity history RMS diff / v0 = {:.2e}; final velocity RMS diff / v0 = {:.2e}; final stress RMS diff / (Z v0) = {:.2e}",
            h_rms / v0,
            f_rms / v0,
            s_rms
        );
        assert!(
            h_rms / v0 < DYKA_TOL,
            "probe history differs: {}",
            h_rms / v0
        );
        assert!(
            f_rms / v0 < DYKA_TOL,
            "final velocities differ: {}",
            f_rms / v0
        );
        assert!(s_rms < DYKA_TOL, "final stresses differ: {s_rms}");
        check_energy(&format!("{sets:?}"), &cpu, &gpu, DYKA_ENERGY_TOL);
        assert!(
            (eg.rms_velocity - ec.rms_velocity).abs() < 0.1 * ec.rms_velocity,
            "GPU error {} vs CPU {}",
            eg.rms_velocity,
            ec.rms_velocity
        );
    }
}

/// Block: quasi-static after the ramp. We measure top-probe settlement
/// histories differing by at most 5.1e-6 of the settlement and final σ_yy
/// fields by at most 6.6e-6 of ρ0 g H (both LME, `LME_MPM_FORCE_CAS=1`;
/// 4.9e-6 and 5.9e-6 with float atomics). Bounds: 10 times those, rounded
/// up (the earlier 1% left 1500 times).
const BLOCK_HISTORY_TOL: f64 = 6e-5;
const BLOCK_STRESS_TOL: f64 = 7e-5;

#[test]
fn elastic_block_gpu_matches_cpu() {
    for sets in [
        &["solver.shape=lme"][..],
        &["solver.shape=ugimp"],
        &["solver.shape=linear"],
    ] {
        let Some((cpu, gpu)) = both("elastic_block.toml", sets, false) else {
            return;
        };
        let (Some(Errors::Column(ec)), Some(Errors::Column(eg))) = (&cpu.errors, &gpu.errors)
        else {
            unreachable!()
        };
        let y0 = cpu.samples[0].probes[0].x[1];
        let (h_rms, settle) = history_rms(&cpu.samples, &gpu.samples, |s| y0 - s.probes[0].x[1]);
        let syc: Vec<f64> = cpu.particles.stress.iter().map(|s| s[1]).collect();
        let syg: Vec<f64> = gpu.particles.stress.iter().map(|s| s[1]).collect();
        let scale = 6000.0 * 9.81 * 10.0;
        let s_rms = field_rms(&syc, &syg) / scale;
        println!(
            "{sets:?}: settlement history RMS diff / settlement = {:.2e}; final sigma_yy RMS diff / (rho g H) = {:.2e}; settlement error cpu {:.4} gpu {:.4}",
            h_rms / settle,
            s_rms,
            ec.settlement_rel_error,
            eg.settlement_rel_error
        );
        assert!(
            h_rms / settle < BLOCK_HISTORY_TOL,
            "settlement history differs: {:.3e}",
            h_rms / settle
        );
        check_energy(&format!("{sets:?}"), &cpu, &gpu, BLOCK_ENERGY_TOL);
        assert!(
            s_rms < BLOCK_STRESS_TOL,
            "final sigma_yy differs: {s_rms:.3e}"
        );
        // The GPU's error against the exact column within 10% of the CPU's,
        // or within 1e-4 of it: errors of a few 1e-4 are at f32's reach
        // (the settlement histories differ by 3e-5 of the settlement), and
        // on an NVIDIA H100 the LME run's 3.4e-4 came out 3.9e-4.
        let close = |g: f64, c: f64| (g - c).abs() <= 0.1 * c + 1e-4;
        assert!(
            close(eg.settlement_rel_error, ec.settlement_rel_error),
            "settlement error gpu {} cpu {}",
            eg.settlement_rel_error,
            ec.settlement_rel_error
        );
        assert!(close(
            eg.sigma_yy_bottom_rel_error,
            ec.sigma_yy_bottom_rel_error
        ));
        assert!(close(eg.sigma_yy_rms_relative, ec.sigma_yy_rms_relative));
    }
}

/// The manufactured vibration, bspline2, 8 cells a side, an eighth of a
/// period (250 steps of the fixed Δt; a quarter period, 500 steps, made
/// this the suite's second slowest test): the GPU runs the body force and,
/// with MLS, the Gauss point passes in f32, with NPC and with the paper's
/// update (MUSL, the MLS remap; bspline3 MUSL without MLS; MUSL with
/// `solver.mls_scope = "force"`). Over the quarter period we measured
/// final velocity fields within 9.7e-6 of the velocity amplitude Aω
/// (6.1e-6 with MLS, NPC and MUSL; 8.8e-6 bspline3 MUSL; 7.4e-6 force
/// mode); bound `MMS_VELOCITY_TOL`, 10 times that, rounded up (was 1e-3).
/// RMS errors against the exact field within 1% of the CPU's.
const MMS_VELOCITY_TOL: f64 = 1e-4;

#[test]
fn manufactured_vibration_gpu_matches_cpu() {
    for sets in [
        &[
            "grid.h=0.125",
            "solver.t_end=0.0025",
            "solver.shape=bspline2",
            "solver.mls=false",
        ][..],
        &[
            "grid.h=0.125",
            "solver.t_end=0.0025",
            "solver.shape=bspline2",
            "solver.mls=true",
            "solver.mls_scope=all",
        ],
        // The paper's update: MUSL with the MLS remap.
        &[
            "grid.h=0.125",
            "solver.t_end=0.0025",
            "solver.shape=bspline2",
            "solver.mls=true",
            "solver.mls_scope=all",
            "solver.integrator=musl",
        ],
        // MUSL with MLS as the internal force's correction only (issue 28).
        &[
            "grid.h=0.125",
            "solver.t_end=0.0025",
            "solver.shape=bspline2",
            "solver.mls=true",
            "solver.mls_scope=force",
            "solver.integrator=musl",
        ],
        &[
            "grid.h=0.125",
            "solver.t_end=0.0025",
            "solver.shape=bspline3",
            "solver.mls=false",
            "solver.integrator=musl",
        ],
    ] {
        let Some((cpu, gpu)) = both("aligned_vibration.toml", sets, false) else {
            return;
        };
        let (Some(Errors::Mms(ec)), Some(Errors::Mms(eg))) = (&cpu.errors, &gpu.errors) else {
            unreachable!()
        };
        let amp = 0.1 * 100.0 * std::f64::consts::PI;
        let vc: Vec<f64> = cpu.particles.v.iter().flatten().copied().collect();
        let vg: Vec<f64> = gpu.particles.v.iter().flatten().copied().collect();
        let f_rms = field_rms(&vc, &vg) / amp;
        println!(
            "{sets:?}: steps cpu {} gpu {}; final velocity RMS diff / (A w) = {f_rms:.2e}; \
             RMS errors cpu {ec:?} gpu {eg:?}",
            cpu.steps, gpu.steps
        );
        assert_eq!(cpu.steps, gpu.steps);
        assert!(f_rms < MMS_VELOCITY_TOL, "final velocities differ: {f_rms}");
        check_energy(&format!("{sets:?}"), &cpu, &gpu, MMS_ENERGY_TOL);
        let close = |g: f64, c: f64| (g - c).abs() <= 0.01 * c;
        assert!(close(eg.rms_displacement, ec.rms_displacement));
        assert!(close(eg.rms_velocity, ec.rms_velocity));
        assert!(close(eg.rms_stress, ec.rms_stress));
    }
}

/// Two materials in one scene: a linear-elastic striker against a
/// Neo-Hookean block at a wall, under gravity (tests/scenes/two_materials.toml).
#[test]
fn two_material_impact_gpu_matches_cpu() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/scenes/two_materials.toml");
    for sets in [
        &[][..],
        &["solver.integrator=fe"],
        &["solver.shape=bspline2", "solver.npc_position=predicted"],
        &["solver.shape=lme"],
    ] {
        let o: Vec<Override> = sets.iter().map(|s| Override::parse(s).unwrap()).collect();
        let scene = Scene::load(&path, &o).unwrap();
        let Some((cpu, gpu)) = both_of("two_materials", &scene, false) else {
            return;
        };
        let v0 = 2.0;
        let (hv, _) = history_rms(&cpu.samples, &gpu.samples, |s| s.probes[1].v[0]);
        let vc: Vec<f64> = cpu.particles.v.iter().flatten().copied().collect();
        let vg: Vec<f64> = gpu.particles.v.iter().flatten().copied().collect();
        let f_rms = field_rms(&vc, &vg);
        let sc: Vec<f64> = cpu.particles.stress.iter().flatten().copied().collect();
        let sg: Vec<f64> = gpu.particles.stress.iter().flatten().copied().collect();
        let s_max = sc.iter().map(|x| x.abs()).fold(0.0, f64::max);
        let s_rms = field_rms(&sc, &sg) / s_max;
        println!(
            "{sets:?}: steps cpu {} gpu {}; target probe vx history RMS diff / v0 = {:.2e}; \
             final velocity RMS diff / v0 = {:.2e}; final stress RMS diff / max = {s_rms:.2e}",
            cpu.steps,
            gpu.steps,
            hv / v0,
            f_rms / v0
        );
        assert!(
            hv / v0 < TWO_MATERIAL_TOL,
            "probe history differs: {}",
            hv / v0
        );
        assert!(
            f_rms / v0 < TWO_MATERIAL_TOL,
            "final velocities differ: {}",
            f_rms / v0
        );
        assert!(s_rms < TWO_MATERIAL_TOL, "final stresses differ: {s_rms}");
        check_energy(&format!("{sets:?}"), &cpu, &gpu, TWO_MATERIAL_ENERGY_TOL);
    }
}

/// A block on a frictional 30° wall pushed along it by a ramped traction
/// and a point load under gravity (tests/scenes/incline_traction.toml),
/// 0.2 s: final velocities over the
/// largest CPU speed, final stresses over the largest, and the reaction
/// histories of every constraint and wall over the largest reaction.
/// Measured worst figures are in the constant's comment.
#[test]
fn boundaries_gpu_matches_cpu() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/scenes/incline_traction.toml");
    for sets in [&[][..], &["solver.shape=lme", "solver.integrator=fe"][..]] {
        let o: Vec<Override> = sets.iter().map(|s| Override::parse(s).unwrap()).collect();
        let scene = Scene::load(&path, &o).unwrap();
        let Some((cpu, gpu)) = both_of("incline_traction", &scene, false) else {
            return;
        };
        let vc: Vec<f64> = cpu.particles.v.iter().flatten().copied().collect();
        let vg: Vec<f64> = gpu.particles.v.iter().flatten().copied().collect();
        let v_max = vc.iter().map(|x| x.abs()).fold(0.0, f64::max);
        let v_rms = field_rms(&vc, &vg) / v_max;
        let sc: Vec<f64> = cpu.particles.stress.iter().flatten().copied().collect();
        let sg: Vec<f64> = gpu.particles.stress.iter().flatten().copied().collect();
        let s_max = sc.iter().map(|x| x.abs()).fold(0.0, f64::max);
        let s_rms = field_rms(&sc, &sg) / s_max;
        let n_r = cpu.samples[0].reactions.len();
        let mut r_rms: f64 = 0.0;
        for k in 0..n_r {
            for c in 0..2 {
                let (rms, scale) = history_rms(&cpu.samples, &gpu.samples, |s| s.reactions[k][c]);
                if scale > 0.0 {
                    r_rms = r_rms.max(rms / scale);
                }
            }
        }
        println!(
            "{sets:?}: steps cpu {} gpu {}; final velocity RMS diff / max {v_rms:.2e}, \
             final stress {s_rms:.2e}, worst reaction history {r_rms:.2e}",
            cpu.steps, gpu.steps
        );
        assert!(v_rms < BOUNDARIES_TOL, "final velocities differ: {v_rms}");
        assert!(s_rms < BOUNDARIES_TOL, "final stresses differ: {s_rms}");
        assert!(r_rms < BOUNDARIES_TOL, "reaction histories differ: {r_rms}");
    }
}

/// A weak Mohr–Coulomb block slumping under gravity
/// (tests/scenes/soil_slump.toml): most particles yield, on both backends,
/// and the plastic state follows (140 of 144 particles yield, ε̄p up to
/// 0.16).
#[test]
fn plastic_slump_gpu_matches_cpu() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/scenes/soil_slump.toml");
    for sets in [
        &[][..],
        &["materials.soil.model=drucker_prager"],
        &["solver.shape=lme"],
    ] {
        let o: Vec<Override> = sets.iter().map(|s| Override::parse(s).unwrap()).collect();
        let scene = Scene::load(&path, &o).unwrap();
        let Some((cpu, gpu)) = both_of("soil_slump", &scene, false) else {
            return;
        };
        let (cp, gp) = (&cpu.particles, &gpu.particles);
        let yielded = |p: &Particles| p.plastic.iter().filter(|q| q[1] > 0.0).count();
        let (yc, yg) = (yielded(cp), yielded(gp));
        // The largest velocity on the CPU path sets the scale of velocities.
        let v_max = cpu
            .samples
            .iter()
            .flat_map(|s| s.probes.iter().map(|p| p.v[0].hypot(p.v[1])))
            .fold(0.0, f64::max);
        let (hv, _) = history_rms(&cpu.samples, &gpu.samples, |s| s.probes[1].v[0]);
        let vc: Vec<f64> = cp.v.iter().flatten().copied().collect();
        let vg: Vec<f64> = gp.v.iter().flatten().copied().collect();
        let sc: Vec<f64> = cp.stress.iter().flatten().copied().collect();
        let sg: Vec<f64> = gp.stress.iter().flatten().copied().collect();
        let s_max = sc.iter().map(|x| x.abs()).fold(0.0, f64::max);
        let ec: Vec<f64> = cp.plastic.iter().map(|q| q[1]).collect();
        let eg: Vec<f64> = gp.plastic.iter().map(|q| q[1]).collect();
        let e_max = ec.iter().copied().fold(0.0, f64::max);
        let (hv, f_rms, s_rms, e_rms) = (
            hv / v_max,
            field_rms(&vc, &vg) / v_max,
            field_rms(&sc, &sg) / s_max,
            field_rms(&ec, &eg) / e_max,
        );
        println!(
            "{sets:?}: steps cpu {} gpu {}; yielded cpu {yc} gpu {yg} of {}; max ε̄p {e_max:.3e}; \
             toe vx history {hv:.2e}, final v {f_rms:.2e}, stress {s_rms:.2e}, ε̄p {e_rms:.2e}",
            cpu.steps,
            gpu.steps,
            cp.len()
        );
        // Plasticity must have happened, or the comparison says nothing.
        assert!(
            yc * 4 >= cp.len() && e_max > 1e-3,
            "{sets:?}: {yc} yielded, ε̄p ≤ {e_max}"
        );
        assert!(
            yc.abs_diff(yg) * 50 <= cp.len(),
            "{sets:?}: yielded {yc} vs {yg}"
        );
        for (what, err) in [
            ("toe vx history", hv),
            ("velocity", f_rms),
            ("stress", s_rms),
            ("ε̄p", e_rms),
        ] {
            assert!(err < SLUMP_TOL, "{sets:?}: {what} differs by {err:.2e}");
        }
        check_energy(&format!("{sets:?}"), &cpu, &gpu, SLUMP_TOL);
    }
}

/// The cohesive column collapse (cases/column_collapse.toml: Mohr–Coulomb,
/// a slip wall and a stick floor together) on a coarse grid (h = 0.1 m)
/// for 0.4 s, linear and LME: run-out, height and the mean equivalent
/// plastic strain agree between the backends. Localised plastic flow makes
/// particle-by-particle fields diverge sooner than these bulk figures.
#[test]
fn column_collapse_gpu_matches_cpu() {
    // Run-out and height differences in cells: measured on 2026-11-23 the
    // same run-out bin and heights within 1 mm (0.01 cell); 10 times that.
    const GEOMETRY_TOL_CELLS: f64 = 0.1;
    // Mean ε̄p, relative: measured ≤ 1e-4 (the node rule for walls, and
    // the contact-point walls since the friction stops each particle's
    // own slip, 2026-11-25: linear 1e-4, LME < 1e-4; sized on the nodal
    // velocity it had let the stick floor's slip chatter, 3.5e-3 and
    // 1.3e-2); 10 times that.
    const PLASTIC_TOL: f64 = 1e-3;
    let h = 0.1;
    for shape in ["linear", "lme"] {
        let o: Vec<Override> = [
            format!("grid.h={h}"),
            format!("solver.shape={shape}"),
            "solver.t_end=0.4".to_string(),
        ]
        .iter()
        .map(|s| Override::parse(s).unwrap())
        .collect();
        let scene = Scene::from_str(
            lme_mpm::cases::COLUMN_COLLAPSE,
            "column_collapse",
            "column_collapse",
            &o,
        )
        .unwrap();
        let Some((cpu, gpu)) = both_of("column_collapse", &scene, false) else {
            return;
        };
        use lme_mpm::study::column::{height, run_out};
        let (cp, gp) = (&cpu.particles, &gpu.particles);
        let mean_eps = |p: &Particles| p.plastic.iter().map(|q| q[1]).sum::<f64>() / p.len() as f64;
        let d_run = (run_out(cp, h) - run_out(gp, h)).abs() / h;
        let d_height = (height(cp, h) - height(gp, h)).abs() / h;
        let (ec, eg) = (mean_eps(cp), mean_eps(gp));
        let d_eps = (ec - eg).abs() / ec;
        println!(
            "{shape}: run-out cpu {:.3} gpu {:.3} m, height cpu {:.3} gpu {:.3} m, mean ε̄p cpu {ec:.4e} gpu {eg:.4e}",
            run_out(cp, h),
            run_out(gp, h),
            height(cp, h),
            height(gp, h)
        );
        assert!(ec > 1e-3, "{shape}: the column must yield (mean ε̄p {ec})");
        assert!(
            d_run < GEOMETRY_TOL_CELLS,
            "{shape}: run-out differs by {d_run} cells"
        );
        assert!(
            d_height < GEOMETRY_TOL_CELLS,
            "{shape}: height differs by {d_height} cells"
        );
        assert!(d_eps < PLASTIC_TOL, "{shape}: mean ε̄p differs by {d_eps}");
    }
}

/// A geostatic column released by a gate at 0.1 s
/// (tests/scenes/gate_release.toml, h = 0.1 m, 0.4 s), linear NPC, linear
/// FE with the PIC blend and local damping, and B-splines MUSL with both:
/// run-out and height agree; the gate holds the column, then exerts
/// nothing, on both backends. Its reaction history is compared sample by
/// sample for linear NPC, where the held column is exactly at rest
/// (measured 1.0e-7 of its largest value); with FE a step's reaction
/// jumps between values 4 % apart as wall nodes enter and leave contact,
/// so one sample differs by that much between f32 and f64 (measured RMS
/// 1.1e-2), which says nothing about the gate.
#[test]
fn gate_release_gpu_matches_cpu() {
    // Run-out and height differences in cells, as for the column collapse:
    // measured the same run-out bin and heights within 1 mm; 10 times that.
    const GEOMETRY_TOL_CELLS: f64 = 0.1;
    // The gate's reaction history (linear NPC), RMS difference over its
    // largest value: measured 1.0e-7; as BOUNDARIES_TOL.
    const GATE_TOL: f64 = BOUNDARIES_TOL;
    let h = 0.1;
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/scenes/gate_release.toml");
    for sets in [
        &[][..],
        &[
            "solver.integrator=fe",
            "solver.pic_fraction=0.05",
            "solver.local_damping=0.1",
        ][..],
        &[
            "solver.shape=bspline2",
            "solver.integrator=musl",
            "solver.pic_fraction=0.05",
            "solver.local_damping=0.1",
        ][..],
    ] {
        let o: Vec<Override> = sets.iter().map(|s| Override::parse(s).unwrap()).collect();
        let scene = Scene::load(&path, &o).unwrap();
        let Some((cpu, gpu)) = both_of("gate_release", &scene, false) else {
            return;
        };
        use lme_mpm::study::column::{height, run_out};
        let (cp, gp) = (&cpu.particles, &gpu.particles);
        let d_run = (run_out(cp, h) - run_out(gp, h)).abs() / h;
        let d_height = (height(cp, h) - height(gp, h)).abs() / h;
        let names = Model::new(&scene).unwrap().reaction_names();
        let gate = names.iter().position(|n| n == "gate").unwrap();
        let (rms, scale) = history_rms(&cpu.samples, &gpu.samples, |s| s.reactions[gate][0]);
        let after = |o: &Outcome| {
            o.samples
                .iter()
                .filter(|s| s.t > 0.1 + 1e-3)
                .map(|s| s.reactions[gate][0].abs())
                .fold(0.0, f64::max)
        };
        println!(
            "{sets:?}: run-out cpu {:.3} gpu {:.3} m, height cpu {:.3} gpu {:.3} m; gate reaction \
             history RMS diff / max {:.2e} (max {scale:.1} N/m; after removal cpu {} gpu {})",
            run_out(cp, h),
            run_out(gp, h),
            height(cp, h),
            height(gp, h),
            rms / scale,
            after(&cpu),
            after(&gpu)
        );
        assert!(scale > 0.0, "{sets:?}: the gate never held the column");
        assert_eq!(after(&cpu), 0.0, "{sets:?}: CPU gate acts after removal");
        assert_eq!(after(&gpu), 0.0, "{sets:?}: GPU gate acts after removal");
        assert!(
            run_out(cp, h) > 0.4 + 0.5 * h,
            "{sets:?}: the column did not flow past the gate"
        );
        let held = |o: &Outcome| o.samples.iter().any(|s| s.reactions[gate][0] < 0.0);
        assert!(held(&gpu), "{sets:?}: the GPU gate never held the column");
        if sets.is_empty() {
            assert!(rms / scale < GATE_TOL, "{sets:?}: gate reactions differ");
        }
        assert!(
            d_run < GEOMETRY_TOL_CELLS,
            "{sets:?}: run-out differs by {d_run} cells"
        );
        assert!(
            d_height < GEOMETRY_TOL_CELLS,
            "{sets:?}: height differs by {d_height} cells"
        );
    }
}

/// Modified Cam-clay: the biaxial case (cases/clay_biaxial.toml) for 1 s
/// (1 % axial strain, most particles on the ellipse) on both backends: the
/// final stresses, preconsolidation pressures and specific volumes agree.
#[test]
fn cam_clay_biaxial_gpu_matches_cpu() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/clay_biaxial.toml");
    let o: Vec<Override> = ["solver.t_end=1.0", "output.vtk_interval=1e9"]
        .iter()
        .map(|s| Override::parse(s).unwrap())
        .collect();
    let scene = Scene::load(&path, &o).unwrap();
    let Some((cpu, gpu)) = both_of("clay_biaxial", &scene, false) else {
        return;
    };
    let (cp, gp) = (&cpu.particles, &gpu.particles);
    let on_ellipse = cp.plastic.iter().filter(|q| q[3] != 0.0).count();
    let sc: Vec<f64> = cp.stress.iter().flatten().copied().collect();
    let sg: Vec<f64> = gp.stress.iter().flatten().copied().collect();
    let s_max = sc.iter().map(|x| x.abs()).fold(0.0, f64::max);
    let col = |p: &Particles, k: usize| -> Vec<f64> { p.plastic.iter().map(|q| q[k]).collect() };
    // p_c and v relative to their own change over the run.
    let change = |p: &Particles, k: usize, v0: f64| {
        p.plastic
            .iter()
            .map(|q| (q[k] - v0).abs())
            .fold(0.0, f64::max)
    };
    let pc0 = 1.0e5;
    let v0 = cp.plastic.iter().map(|q| q[2]).fold(0.0, f64::max);
    let (s_rms, pc_rms, v_rms) = (
        field_rms(&sc, &sg) / s_max,
        field_rms(&col(cp, 1), &col(gp, 1)) / change(cp, 1, pc0),
        field_rms(&col(cp, 2), &col(gp, 2)) / change(cp, 2, v0).max(1e-12),
    );
    println!(
        "clay_biaxial: steps cpu {} gpu {}; {on_ellipse} of {} on the ellipse; stress {s_rms:.2e}, p_c change {pc_rms:.2e}, v {v_rms:.2e}",
        cpu.steps,
        gpu.steps,
        cp.len()
    );
    assert!(on_ellipse * 2 >= cp.len(), "{on_ellipse} on the ellipse");
    for (what, err) in [
        ("stress", s_rms),
        ("p_c change", pc_rms),
        ("v change", v_rms),
    ] {
        assert!(err < CAM_CLAY_TOL, "{what} differs by {err:.2e}");
    }
}

/// Contact pairs (issue 24), the block sliding on the slab (μ = 0.2, to
/// 0.1 s: the ramp's first half, the block settling on the slab and
/// starting to slide): final velocity and stress fields and the pair's
/// reaction history (over its largest CPU value, |R|), and the energies.
/// Worst measured 2.8e-4 (gravity-work bound; fields 1.9e-5, 1.3e-4,
/// reaction 5.5e-5), 10 times rounded up. Run at h = 0.1 (half the
/// case's: parity needs no resolution, and llvmpipe's time is per step):
/// fields 1.7e-5, 4.0e-4, reaction 3.2e-4 (2026-11-28).
const CONTACT_BLOCK_TOL: f64 = 3e-3;
/// The two disks head-on (the whole collision, frictionless): contact at
/// a node is a yes/no decision (gap ≤ slack, approaching) that f32
/// round-off flips a step early or late on one side, so the GPU loses the
/// collision's mirror symmetry (v_y ±5e-4 m/s after it, 0 on the CPU) and
/// the fields differ by 1e-2 (velocity) to 4e-2 (stress) of their largest.
/// What the collision does is compared: each disk's mean velocity after
/// it over the impact speed (1 m/s; measured 1.1e-3: −0.90787 against
/// −0.90895 m/s), the pair's reaction history over its largest |R|
/// (4.9e-3) and the energies (kinetic 1.6e-3); 10 times the worst,
/// rounded up. Run at h = 0.05 (twice the case's, 4 cells a radius; half
/// the steps): this run kept the symmetry to 2e-8 m/s (2026-11-28).
const CONTACT_DISKS_TOL: f64 = 5e-2;

/// Mass-weighted mean velocity of each body.
fn body_means(p: &Particles) -> Vec<[f64; 2]> {
    let n = p.body.iter().max().map_or(0, |b| *b as usize + 1);
    lme_mpm::study::contact::body_motion(p, n)
        .iter()
        .map(|m| m.v)
        .collect()
}

#[test]
fn contact_pairs_gpu_matches_cpu() {
    for (case, sets, disks) in [
        (
            "contact_block.toml",
            &["solver.t_end=0.1", "grid.h=0.1"][..],
            false,
        ),
        (
            "contact_disks.toml",
            &["bodies.right.disks=[[0.75, 0.5, 0.2]]", "grid.h=0.05"][..],
            true,
        ),
    ] {
        let Some((cpu, gpu)) = both(case, sets, false) else {
            return;
        };
        let rel_rms =
            |c: &[f64], g: &[f64]| field_rms(c, g) / c.iter().map(|x| x.abs()).fold(0.0, f64::max);
        let vc: Vec<f64> = cpu.particles.v.iter().flatten().copied().collect();
        let vg: Vec<f64> = gpu.particles.v.iter().flatten().copied().collect();
        let sc: Vec<f64> = cpu.particles.stress.iter().flatten().copied().collect();
        let sg: Vec<f64> = gpu.particles.stress.iter().flatten().copied().collect();
        let (v_rms, s_rms) = (rel_rms(&vc, &vg), rel_rms(&sc, &sg));
        // The pair's reaction: the last one (after the walls').
        let k = cpu.samples[0].reactions.len() - 1;
        let r_max = cpu
            .samples
            .iter()
            .map(|s| s.reactions[k][0].hypot(s.reactions[k][1]))
            .fold(0.0, f64::max);
        assert!(r_max > 0.0, "{case}: the pair never touched");
        let r_rms = (0..2)
            .map(|c| history_rms(&cpu.samples, &gpu.samples, |s| s.reactions[k][c]).0)
            .fold(0.0, f64::max)
            / r_max;
        let (bc, bg) = (body_means(&cpu.particles), body_means(&gpu.particles));
        let body = bc
            .iter()
            .zip(&bg)
            .map(|(c, g)| (c[0] - g[0]).abs().max((c[1] - g[1]).abs()))
            .fold(0.0, f64::max);
        println!(
            "{case}: steps cpu {} gpu {}; final velocity RMS diff / max {v_rms:.2e}, \
             final stress {s_rms:.2e}, pair reaction history {r_rms:.2e}, bodies' mean \
             velocities {body:.2e} m/s (cpu {bc:?}, gpu {bg:?})",
            cpu.steps, gpu.steps
        );
        let tol = if disks {
            CONTACT_DISKS_TOL
        } else {
            assert!(
                v_rms < CONTACT_BLOCK_TOL,
                "{case}: final velocities differ: {v_rms}"
            );
            assert!(
                s_rms < CONTACT_BLOCK_TOL,
                "{case}: final stresses differ: {s_rms}"
            );
            CONTACT_BLOCK_TOL
        };
        assert!(body < tol, "{case}: bodies' mean velocities differ: {body}");
        assert!(r_rms < tol, "{case}: reaction histories differ: {r_rms}");
        check_energy(case, &cpu, &gpu, tol);
    }
}

/// The strip footing on a Tresca soil (`cases/footing.toml`, the smooth
/// pair, the cell-averaged volumetric strain rate) at h = 0.1 m to 0.3 s
/// (865 steps; 582 particles yield under the footing): the pair's
/// vertical reaction history (the load-settlement curve) over its
/// largest, measured 7.5e-7 on llvmpipe (2026-11-28), 10 times rounded up.
const FOOTING_REACTION_TOL: f64 = 1e-5;
/// Its final stress field over its largest: measured 5.4e-3, where the
/// same run with each particle's own strain rate differs by 3.9e-3 (f32
/// against f64 returns to the Tresca surface beside the footing's corners,
/// whose stress singularity puts the largest values there); 10 times,
/// rounded up.
const FOOTING_STRESS_TOL: f64 = 6e-2;

#[test]
fn footing_gpu_matches_cpu() {
    let Some((cpu, gpu)) = both(
        "footing.toml",
        &[
            "grid.h=0.1",
            "solver.t_end=0.3",
            "output.sample_interval=0.01",
        ],
        false,
    ) else {
        return;
    };
    // The pair's reaction: the last one (after the constraints').
    let k = cpu.samples[0].reactions.len() - 1;
    let r_max = cpu
        .samples
        .iter()
        .map(|s| s.reactions[k][1].abs())
        .fold(0.0, f64::max);
    assert!(r_max > 0.0, "the footing never pressed");
    let r_rms = history_rms(&cpu.samples, &gpu.samples, |s| s.reactions[k][1]).0 / r_max;
    let sc: Vec<f64> = cpu.particles.stress.iter().flatten().copied().collect();
    let sg: Vec<f64> = gpu.particles.stress.iter().flatten().copied().collect();
    let s_rms = field_rms(&sc, &sg) / sc.iter().map(|x| x.abs()).fold(0.0, f64::max);
    let plastic = cpu.particles.plastic.iter().filter(|q| q[1] > 0.0).count();
    println!(
        "footing: steps cpu {} gpu {}; reaction history RMS diff / max {r_rms:.2e} (max {r_max:.0} \
         N/m), final stress {s_rms:.2e}; {plastic} particles yielded on the CPU",
        cpu.steps, gpu.steps
    );
    assert!(plastic > 0, "no particle yielded: the run is elastic");
    assert!(
        r_rms < FOOTING_REACTION_TOL,
        "reaction histories differ: {r_rms}"
    );
    assert!(s_rms < FOOTING_STRESS_TOL, "final stresses differ: {s_rms}");
}

/// Constraint points (issue 23): the elastic block (h = 1 m) on a base
/// two cells inside the grid, so bspline2 and bspline3 hold it at its
/// edge by points (the projection after each grid update), NPC over the
/// gravity ramp's first half (10 s, 2885 steps). Settlement history over
/// the settlement, the base's reaction history over its largest, final
/// σ_yy over ρ g H. Measured on llvmpipe: bspline2 2.2e-5, 1.8e-5, 1.9e-6
/// (bspline3 4.1e-6, 2.6e-6, 1.3e-6); 10 times the worst, rounded up.
const POINTS_TOL: f64 = 3e-4;
/// Its energies: worst 1.0e-4 (bspline2, kinetic: the block still swings
/// mid-ramp); 10 times, rounded up.
const POINTS_ENERGY_TOL: f64 = 1e-3;

#[test]
fn constraint_points_gpu_matches_cpu() {
    for shape in ["bspline2", "bspline3"] {
        let shape_set = format!("solver.shape={shape}");
        let sets = [
            shape_set.as_str(),
            "grid.h=1.0",
            "grid.min=[-2.0, -2.0]",
            "grid.max=[12.0, 12.0]",
            "solver.t_end=10.0",
        ];
        let scene = common::scene("elastic_block.toml", &sets);
        let points = Model::new(&scene).unwrap().constraints.points.len();
        assert!(points > 0, "{shape}: no constraint points");
        let Some((cpu, gpu)) = both_of(shape, &scene, false) else {
            return;
        };
        let y0 = cpu.samples[0].probes[0].x[1];
        let (h_rms, settle) = history_rms(&cpu.samples, &gpu.samples, |s| y0 - s.probes[0].x[1]);
        let (r_rms, r_max) = history_rms(&cpu.samples, &gpu.samples, |s| s.reactions[0][1]);
        let syc: Vec<f64> = cpu.particles.stress.iter().map(|s| s[1]).collect();
        let syg: Vec<f64> = gpu.particles.stress.iter().map(|s| s[1]).collect();
        let s_rms = field_rms(&syc, &syg) / (6000.0 * 9.81 * 10.0);
        println!(
            "{shape} ({points} points, {} steps): settlement history RMS diff / settlement = \
             {:.2e}; base reaction history RMS diff / max = {:.2e}; final sigma_yy RMS diff / \
             (rho g H) = {s_rms:.2e}",
            cpu.steps,
            h_rms / settle,
            r_rms / r_max
        );
        assert!(h_rms / settle < POINTS_TOL, "{shape}: settlement history");
        assert!(r_rms / r_max < POINTS_TOL, "{shape}: base reaction history");
        assert!(s_rms < POINTS_TOL, "{shape}: final sigma_yy");
        check_energy(shape, &cpu, &gpu, POINTS_ENERGY_TOL);
    }
}

/// The device's clock against the CPU's over a long fixed-Δt run: 10 000
/// steps of 1e-4 s, stopped every 0.05 s as samples stop it (the f64 sum
/// falls short of 18 of the 20 stops by round-off). At each stop
/// both paths have taken the same number of steps and reached the same
/// time. A compensated f32 sum of the time cannot promise this on every
/// driver (llvmpipe reassociated it into a plain f32 sum, which drifts by
/// 3e-8 s a step near t = 1 s, 3e-4 of Δt; on an NVIDIA H100 the
/// manufactured vibration took 251 steps where the CPU took 250); the
/// integer clock (`gpu::layout::Clock`) does.
#[test]
fn long_fixed_step_runs_keep_the_cpus_clock() {
    let scene = common::scene(
        "elastic_block.toml",
        &["solver.dt=1e-4", "solver.t_end=1.0"],
    );
    let Some(ctx) = common::gpu::open("long fixed-step clock", false) else {
        return;
    };
    let model = Model::new(&scene).unwrap();
    let mut cpu = CpuBackend::new(model.clone());
    let mut gpu = GpuBackend::new(ctx, model).unwrap();
    let stop = std::sync::atomic::AtomicBool::new(false);
    let mut worst_t = 0.0f64;
    for k in 1..=20 {
        let target = 0.05 * k as f64;
        cpu.advance(target, &stop).unwrap();
        gpu.advance(target, &stop).unwrap();
        assert_eq!(
            cpu.steps(),
            gpu.steps(),
            "steps to t = {target}: cpu {} gpu {}",
            cpu.steps(),
            gpu.steps()
        );
        worst_t = worst_t.max((cpu.time() - gpu.time()).abs());
    }
    println!(
        "20 stops, {} steps on both paths; largest time difference {worst_t:.2e} s",
        cpu.steps()
    );
    assert_eq!(cpu.steps(), 10_000);
    assert!(worst_t < 1e-12, "time differs by {worst_t:.3e} s");
}

/// Issue 51: a platen whose region moves with its velocity
/// (cases/clay_biaxial.toml pressed at 0.2 m/s for 1.5 s: 0.275 m, its
/// nodes shifted down two spacings by the end) presses alike on both
/// backends: on both the sample's top within a cell of the platen and
/// within 1e-2 h of each other (measured 1.7140 m on both), the platen's
/// reaction history over its largest and the final positions over h.
/// Measured on llvmpipe (2026-12-01): 1.9e-2 and 4.2e-2 h, more than the
/// 1 s clay parity above: pressed this fast the clay runs dynamic, and
/// whether the rest comes from the f32 time at which a row joins the
/// platen or from the dynamics is not separated yet; bounds 2.5 times
/// the measured.
const PLATEN_REACTION_TOL: f64 = 5e-2;
const PLATEN_POSITION_TOL: f64 = 0.1;

#[test]
fn moving_platen_gpu_matches_cpu() {
    let (t_end, v, ramp) = (1.5, 0.2, 0.25);
    let Some((cpu, gpu)) = both(
        "clay_biaxial.toml",
        &[
            "constraints.platen.velocity=[0.0, -0.2]",
            "constraints.platen.ramp_time=0.25",
            "solver.t_end=1.5",
            "output.sample_interval=0.05",
        ],
        false,
    ) else {
        return;
    };
    let platen = 2;
    let r_max = cpu
        .samples
        .iter()
        .map(|s| s.reactions[platen][1].abs())
        .fold(0.0, f64::max);
    assert!(r_max > 0.0, "the platen never pressed");
    let r_rms = history_rms(&cpu.samples, &gpu.samples, |s| s.reactions[platen][1]).0 / r_max;
    let h = 0.125;
    let xc: Vec<f64> = cpu.particles.x.iter().flatten().copied().collect();
    let xg: Vec<f64> = gpu.particles.x.iter().flatten().copied().collect();
    let x_rms = field_rms(&xc, &xg) / h;
    let face = 2.0 - v * (t_end - 0.5 * ramp);
    let top = |p: &Particles| p.x.iter().map(|x| x[1]).fold(f64::NEG_INFINITY, f64::max);
    let (tc, tg) = (top(&cpu.particles), top(&gpu.particles));
    println!(
        "moving platen: steps cpu {} gpu {}; reaction history RMS diff / max {r_rms:.2e} (max \
         {r_max:.0} N/m); positions {x_rms:.2e} h; top cpu {tc:.4} gpu {tg:.4}, platen at {face:.4} m",
        cpu.steps, gpu.steps
    );
    assert!((tc - tg).abs() < 1e-2 * h, "tops differ: {tc} {tg}");
    for (b, t) in [("cpu", tc), ("gpu", tg)] {
        assert!(
            (t - face).abs() < h,
            "{b}: top {t} m, the platen at {face} m"
        );
    }
    assert!(
        r_rms < PLATEN_REACTION_TOL,
        "reaction histories differ: {r_rms}"
    );
    assert!(x_rms < PLATEN_POSITION_TOL, "positions differ: {x_rms} h");
}
