//! Helpers shared by the integration tests: run a case file on the CPU path
//! in memory (no output files) as a `Simulation`, and score it.

#![allow(dead_code)]

pub mod disk;

use lme_mpm::exact::Errors;
use lme_mpm::scene::{Override, Scene};
use lme_mpm::simulation::{BackendSpec, Simulation};
use lme_mpm::solver::{Recorder, RunStatus, Schedule};
use std::path::PathBuf;

pub fn case(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("cases")
        .join(name)
}

pub fn scene(name: &str, sets: &[&str]) -> Scene {
    let o: Vec<Override> = sets.iter().map(|s| Override::parse(s).unwrap()).collect();
    Scene::load(&case(name), &o).unwrap_or_else(|e| panic!("{name} {sets:?}: {e}"))
}

pub struct Run {
    pub status: RunStatus,
    pub sim: Simulation,
    pub recorder: Recorder,
    pub errors: Option<Errors>,
}

/// Runs `name` with overrides on the CPU path and scores it.
pub fn run(name: &str, sets: &[&str]) -> Run {
    let scene = scene(name, sets);
    let mut sim = Simulation::new(&scene, &BackendSpec::cpu()).unwrap();
    let mut recorder = Recorder::default();
    let schedule = Schedule {
        vtk_interval: None,
        ..sim.schedule()
    };
    let status = sim.drive_with(schedule, &mut recorder).unwrap();
    let errors = sim.score().unwrap();
    Run {
        status,
        sim,
        recorder,
        errors,
    }
}

pub fn dyka_rms(r: &Run) -> f64 {
    match &r.errors {
        Some(Errors::Dyka(e)) => e.rms_velocity,
        other => panic!("not a Dyka score: {other:?}"),
    }
}

pub fn column(r: &Run) -> lme_mpm::exact::column::ColumnErrors {
    match &r.errors {
        Some(Errors::Column(e)) => e.clone(),
        other => panic!("not a column score: {other:?}"),
    }
}

pub mod gpu;
