//! CPU throughput: particle-steps per second of a whole NPC step for
//! linear, uGIMP and LME (γ = 2, 3, 4) at about 10k, 100k and 1M particles.
//! `cargo bench` prints a markdown table and writes target/bench/throughput.csv.
//! Set LME_MPM_BENCH_COUNTS=10000,100000 to choose counts and
//! LME_MPM_BENCH_SECONDS=2 for the time spent per point.

use lme_mpm::bench;
use lme_mpm::run::BackendChoice;

fn main() {
    let counts: Vec<usize> = std::env::var("LME_MPM_BENCH_COUNTS")
        .ok()
        .map(|s| s.split(',').filter_map(|c| c.trim().parse().ok()).collect())
        .unwrap_or_else(|| vec![10_000, 100_000, 1_000_000]);
    let seconds: f64 = std::env::var("LME_MPM_BENCH_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(2.0);
    println!("{}", bench::TABLE_HEADER);
    let points = bench::run(
        BackendChoice::Cpu,
        None,
        &bench::standard_cases(),
        &counts,
        seconds,
        |p| println!("{}", bench::table_row(p)),
    )
    .expect("benchmark runs");
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/bench");
    std::fs::create_dir_all(&dir).expect("create target/bench");
    std::fs::write(dir.join("throughput.csv"), bench::csv(&points)).expect("write csv");
}
