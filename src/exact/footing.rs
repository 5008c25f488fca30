//! A rigid strip footing pressed into a Tresca soil (`prandtl_footing`):
//! the scene's one contact pair holds the footing (its first body) on the
//! soil (its second, a Mohr–Coulomb material with φ = 0 and cohesion c).
//! Prandtl's limit pressure, for a smooth and a rough footing alike, is
//! q = (2 + π) c = 5.14 c. q is the pair's reaction along the face's normal
//! (reactions.csv, the pair's column) over the footing's width B (its extent
//! along the face); settlement is the footing's initial speed into the
//! soil times t (a footing dense enough to keep its speed, as the case's).

use super::bodies;
use crate::backend::Sample;
use crate::scene::Scene;
use serde::Serialize;

/// Prandtl's bearing capacity factor N_c = 2 + π.
pub const PRANDTL: f64 = 2.0 + std::f64::consts::PI;

#[derive(Debug, Clone, PartialEq)]
pub struct Footing {
    /// Width B along the face (m).
    pub width: f64,
    /// The soil's cohesion c (Pa).
    pub cohesion: f64,
    /// The face's unit normal, from the soil into the footing.
    pub normal: [f64; 2],
    /// Index of the pair's reaction in a sample's `reactions`.
    pub reaction: usize,
    /// The footing's initial velocity into the soil (m/s).
    pub speed: f64,
}

/// Figures for `summary.json`.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct FootingErrors {
    /// Largest q/c over the samples.
    pub q_peak_over_c: f64,
    /// The settlement where it was reached (m).
    pub settlement_at_peak: f64,
    /// q/c at the last sample.
    pub q_end_over_c: f64,
    /// 2 + π.
    pub q_exact_over_c: f64,
    /// (peak − (2 + π)) / (2 + π), signed.
    pub q_rel_error: f64,
}

impl Footing {
    pub fn from_scene(scene: &Scene, model: &crate::model::Model) -> Footing {
        let pair = bodies::pair(scene);
        let n = bodies::pair_normal(scene);
        let bb = crate::scene::seed::body_bbox(pair.body[0]);
        let width = if n[0] == 0.0 {
            bb[2] - bb[0]
        } else {
            bb[3] - bb[1]
        };
        let soil = &scene.file.materials[&pair.body[1].material];
        let v = pair.body[0].velocity;
        Footing {
            width,
            cohesion: soil.get("cohesion").unwrap_or(0.0),
            normal: n,
            reaction: model
                .reaction_names()
                .iter()
                .position(|r| r == pair.name)
                .expect("a pair has a reaction"),
            speed: -(v[0] * n[0] + v[1] * n[1]),
        }
    }

    /// q/c of a sample: the pair's reaction along the normal over B c.
    pub fn q_over_c(&self, s: &Sample) -> f64 {
        let r = s.reactions.get(self.reaction).copied().unwrap_or([0.0; 2]);
        (r[0] * self.normal[0] + r[1] * self.normal[1]) / (self.width * self.cohesion)
    }

    /// The settlement at time `t` (m): the footing's initial speed into
    /// the soil times t (the case's footing is dense enough to keep it).
    pub fn settlement(&self, t: f64) -> f64 {
        self.speed * t
    }

    pub fn score(&self, samples: &[Sample]) -> FootingErrors {
        let (mut peak, mut at) = (f64::NEG_INFINITY, 0.0);
        for s in samples {
            let q = self.q_over_c(s);
            if q > peak {
                (peak, at) = (q, self.settlement(s.t));
            }
        }
        let end = samples.last().map_or(f64::NAN, |s| self.q_over_c(s));
        if samples.is_empty() {
            peak = f64::NAN;
        }
        FootingErrors {
            q_peak_over_c: peak,
            settlement_at_peak: at,
            q_end_over_c: end,
            q_exact_over_c: PRANDTL,
            q_rel_error: (peak - PRANDTL) / PRANDTL,
        }
    }
}
