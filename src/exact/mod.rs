//! Exact solutions the benchmarks are scored against, built from the scene
//! (geometry, material, loads) so a changed scene is scored correctly.

pub mod cantilever;
pub mod column;
pub mod dyka;
pub mod mms;
pub mod rolling;
pub mod sliding;

use crate::model::{Model, Particles};
use crate::scene::{ExactKind, Scene};
use serde::Serialize;

/// Error figures written to `summary.json` under `"errors"`.
#[derive(Debug, Clone, Serialize, PartialEq)]
#[serde(untagged)]
pub enum Errors {
    Dyka(dyka::DykaErrors),
    Column(column::ColumnErrors),
    Mms(mms::MmsErrors),
    Sliding(sliding::SlidingErrors),
    Rolling(rolling::RollingErrors),
    Cantilever(cantilever::CantileverErrors),
}

/// Scores the particle state at time `t` against the scene's exact solution.
pub fn score(
    kind: ExactKind,
    scene: &Scene,
    model: &Model,
    particles: &Particles,
    t: f64,
) -> Errors {
    match kind {
        ExactKind::DykaBar => Errors::Dyka(dyka::DykaBar::from_scene(scene).score(particles, t)),
        ExactKind::ElasticColumn => {
            Errors::Column(column::ElasticColumn::from_scene(scene, model).score(particles, t))
        }
        ExactKind::SlidingBlock => {
            Errors::Sliding(sliding::SlidingBlock::from_scene(scene).score(particles, t))
        }
        ExactKind::AlignedVibration => Errors::Mms(mms::score(
            &mms::AlignedVibration::from_scene(scene).expect("validated: a manufactured scene"),
            particles,
            t,
        )),
        ExactKind::RollingDisk => {
            Errors::Rolling(rolling::RollingDisk::from_scene(scene).score(particles, t))
        }
        ExactKind::Cantilever => {
            Errors::Cantilever(cantilever::Cantilever::from_scene(scene).score(particles))
        }
    }
}
