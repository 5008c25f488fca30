//! Per-stage (CPU) and per-pass (GPU) time per particle-step on the bench
//! scene, for docs/performance.md. Not part of `cargo test`.
//! LME_MPM_PROFILE_CASES=linear,bspline2,lme-g3, LME_MPM_PROFILE_COUNT=100000,
//! LME_MPM_PROFILE_STEPS=5, LME_MPM_PROFILE_BACKEND=cpu|gpu|both.
//! Columns: wall ns per particle-step, its share, and (GPU) the process's
//! CPU time per particle-step, steadier than the wall time on a shared
//! machine when the adapter is a software one.

use lme_mpm::bench;

fn main() {
    let env = |k: &str, d: &str| std::env::var(k).unwrap_or_else(|_| d.to_string());
    let cases = env("LME_MPM_PROFILE_CASES", "linear,bspline2,lme-g3");
    let count: usize = env("LME_MPM_PROFILE_COUNT", "100000")
        .parse()
        .expect("a count");
    let steps: u64 = env("LME_MPM_PROFILE_STEPS", "5")
        .parse()
        .expect("a step count");
    let backend = env("LME_MPM_PROFILE_BACKEND", "both");
    let all: Vec<bench::Case> = bench::standard_cases()
        .into_iter()
        .chain(bench::extra_cases())
        .collect();
    for name in cases.split(',') {
        let case = all
            .iter()
            .find(|c| c.label == name)
            .unwrap_or_else(|| panic!("unknown case {name}"));
        let report = |what: &str, r: Vec<bench::StageTime>| {
            let total: f64 = r.iter().map(|s| s.ns_per_particle_step).sum();
            let cpu: f64 = r.iter().map(|s| s.cpu_ns_per_particle_step).sum();
            println!(
                "\n{what} {name} {count}: {total:.1} ns/particle-step (process CPU time {cpu:.1})"
            );
            for s in r {
                println!(
                    "| {:<12} | {:>7.1} | {:>4.0}% | {:>7.1} |",
                    s.name,
                    s.ns_per_particle_step,
                    100.0 * s.ns_per_particle_step / total,
                    s.cpu_ns_per_particle_step
                );
            }
        };
        if backend != "gpu" {
            report(
                "cpu",
                bench::profile_cpu(count, case, steps).expect("cpu profile"),
            );
        }
        if backend != "cpu" {
            report(
                "gpu",
                bench::profile_gpu(None, count, case, steps).expect("gpu profile"),
            );
        }
    }
}
