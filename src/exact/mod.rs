//! Exact solutions the benchmarks are scored against, built from the scene
//! (geometry, material, loads) so a changed scene is scored correctly.

pub mod bodies;
pub mod cantilever;
pub mod collapse;
pub mod column;
pub mod contact;
pub mod critical_state;
pub mod dyka;
pub mod energy;
pub mod footing;
pub mod mandel;
pub mod mms;
pub mod rolling;
pub mod sliding;
pub mod terzaghi;

use crate::backend::Sample;
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
    ContactSliding(contact::ContactSlidingErrors),
    ContactRolling(contact::ContactRollingErrors),
    DiskImpact(contact::DiskImpactErrors),
    Footing(footing::FootingErrors),
    CriticalState(critical_state::CriticalStateErrors),
    ColumnCollapse(collapse::ColumnCollapseErrors),
    GranularCollapse(collapse::GranularCollapseErrors),
    Energy(energy::EnergyErrors),
    Terzaghi(terzaghi::TerzaghiErrors),
    Mandel(mandel::MandelErrors),
}

/// Scores the particle state at time `t` against the scene's exact
/// solution or reference; `samples` (the run's, in time order) for those
/// read over time (the footing's peak, the energy at the start).
pub fn score(
    kind: ExactKind,
    scene: &Scene,
    model: &Model,
    particles: &Particles,
    t: f64,
    samples: &[Sample],
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
        ExactKind::ContactSliding => {
            Errors::ContactSliding(contact::score_sliding(scene, particles, t))
        }
        ExactKind::ContactRolling => {
            Errors::ContactRolling(contact::score_rolling(scene, particles, t))
        }
        ExactKind::DiskImpact => Errors::DiskImpact(contact::score_impact(scene, particles)),
        ExactKind::PrandtlFooting => {
            Errors::Footing(footing::Footing::from_scene(scene, model).score(samples))
        }
        ExactKind::CriticalState => Errors::CriticalState(critical_state::score(scene, particles)),
        ExactKind::ColumnCollapse => {
            Errors::ColumnCollapse(collapse::score_column(scene, particles))
        }
        ExactKind::GranularCollapse => {
            Errors::GranularCollapse(collapse::score_granular(scene, particles))
        }
        ExactKind::Energy => Errors::Energy(energy::score(samples)),
        ExactKind::Terzaghi => {
            let layer = terzaghi::Terzaghi::from_scene(scene);
            Errors::Terzaghi(layer.score(particles, t))
        }
        ExactKind::Mandel => Errors::Mandel(mandel::Mandel::from_scene(scene).score(particles, t)),
    }
}
