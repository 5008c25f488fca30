//! Helpers shared by the integration tests: run a case file on the CPU path
//! in memory (no output files) and score it.

#![allow(dead_code)]

use lme_mpm::backend::Backend;
use lme_mpm::cpu::CpuBackend;
use lme_mpm::exact::{self, Errors};
use lme_mpm::model::Model;
use lme_mpm::scene::{Override, Scene};
use lme_mpm::solver::{self, Recorder, RunStatus, Schedule};
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
    pub backend: CpuBackend,
    pub recorder: Recorder,
    pub errors: Option<Errors>,
}

/// Runs `name` with overrides on the CPU path and scores it.
pub fn run(name: &str, sets: &[&str]) -> Run {
    let scene = scene(name, sets);
    let model = Model::new(&scene).unwrap();
    let mut backend = CpuBackend::new(model);
    let mut recorder = Recorder::default();
    let schedule = Schedule {
        sample_interval: scene.sample_interval,
        vtk_interval: None,
        ..Default::default()
    };
    let status = solver::drive(&mut backend, schedule, &mut recorder).unwrap();
    let t = backend.time();
    let errors = scene
        .file
        .exact
        .map(|k| exact::score(k, &scene, &backend.model, &backend.model.particles, t));
    Run {
        status,
        backend,
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
