//! lme-mpm: a 2D Material Point Method with Local Max-Ent (LME) shape
//! functions and the Newmark predictor-corrector (NPC) of Molinos et al.,
//! beside linear (Q4), uGIMP and B-spline (quadratic, cubic, optionally with
//! MLS reconstruction) shape functions and Forward Euler, with a CPU
//! reference path (f64, rayon) whose stages have WGSL twins (wgpu).
//!
//! Layers, bottom up (`tests/layers.rs` keeps them pointing one way):
//! `limits`, `scene` (the file, validated) → `model` (grid, particles,
//! shape functions, materials, loads, energy, the time-step rule) →
//! `step` (the step plan: stages, fusion, GPU passes) → `backend` (the
//! contract) → `cpu`, `gpu` (the two backends, never importing each
//! other) → `solver` (the driver)
//! → `simulation` (scene + backend + drive + score: one run) → `exact`
//! (scoring), `output`, `run`, `study`, `bench` (the commands).
//!
//! A run: `scene::Scene::load` → `simulation::Simulation::new` (builds the
//! `model::Model`, opens a `backend::Backend`) → `Simulation::drive` (the
//! stages of `step::StepPlan`, sampled by an `solver::Observer`) →
//! `Simulation::score` → `output`.

pub mod backend;
pub mod bench;
pub mod cases;
pub mod chart;
pub mod cpu;
pub mod docgen;
pub mod error;
pub mod exact;
pub mod gmm;
pub mod gpu;
pub mod limits;
pub mod model;
pub mod output;
pub mod preflight;
pub mod rng;
pub mod run;
pub mod scene;
pub mod simulation;
pub mod solver;
pub mod step;
pub mod study;
pub mod sweep;

pub use error::{Error, Result, SceneError};
