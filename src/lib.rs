//! lme-mpm: a 2D Material Point Method with Local Max-Ent (LME) shape
//! functions and the Newmark predictor-corrector (NPC) of Molinos et al.,
//! beside linear (Q4) and uGIMP shape functions and Forward Euler, with a
//! CPU reference path (f64, rayon) whose stages have WGSL twins.
//!
//! A run: `scene::Scene::load` → `model::Model::new` → a `backend::Backend`
//! (`cpu::CpuBackend`) → `solver::drive` → `output`. The step itself is the
//! ordered stage list `solver::STEP`.

pub mod backend;
pub mod bench;
pub mod cases;
pub mod chart;
pub mod cpu;
pub mod docgen;
pub mod error;
pub mod exact;
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
pub mod study;

pub use error::{Error, Result, SceneError};
