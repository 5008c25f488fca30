//! What each particle's material makes of its state in the outputs: σzz of
//! plane strain (`Constitutive::stress_zz`) and the state columns the
//! material names (`Constitutive::STATE_COLUMNS`), per body. A scene's
//! state columns are every distinct column of its materials, in registry
//! order; a particle whose material has no such column holds 0 there
//! (docs/outputs.md, "Plastic state").

use crate::model::material::{Material, StateColumn, state_columns};
use crate::model::{Model, Particles};

/// The materials of a model's bodies, as the outputs read their state.
#[derive(Debug, Clone, Default)]
pub struct StateLayout {
    /// Per body: its material.
    body: Vec<Material>,
    /// The scene's state columns, each with its slot of `PlasticState` per
    /// body (`None`: the body's material has no such column).
    columns: Vec<(StateColumn, Vec<Option<usize>>)>,
}

impl StateLayout {
    pub fn of(model: &Model) -> StateLayout {
        let body: Vec<Material> = model
            .body_material
            .iter()
            .map(|&m| model.materials[m as usize].clone())
            .collect();
        let present: Vec<StateColumn> = model
            .materials
            .iter()
            .flat_map(|m| m.entry().state_columns)
            .copied()
            .collect();
        let columns = state_columns()
            .into_iter()
            .filter(|c| present.contains(c))
            .map(|c| {
                let slots = body
                    .iter()
                    .map(|m| {
                        let own = m.entry().state_columns;
                        own.iter().position(|d| *d == c).map(|k| k + 1)
                    })
                    .collect();
                (c, slots)
            })
            .collect();
        StateLayout { body, columns }
    }

    /// σzz of particle `i` (Pa), as its material makes it; 0 for a particle
    /// of a body this does not know.
    pub fn szz(&self, p: &Particles, i: usize) -> f64 {
        match self.body.get(p.body[i] as usize) {
            Some(m) => m.stress_zz(&p.stress[i], p.f.get(i), p.rho[i], p.plastic.get(i)),
            None => 0.0,
        }
    }

    /// The scene's state columns, in the order the outputs write them.
    pub fn columns(&self) -> impl Iterator<Item = &StateColumn> {
        self.columns.iter().map(|c| &c.0)
    }

    /// Column `c`'s value (in `columns` order) of particle `i`: 0 where its
    /// material has no such column.
    pub fn value(&self, c: usize, p: &Particles, i: usize) -> f64 {
        match self.columns[c].1.get(p.body[i] as usize) {
            Some(Some(k)) => p.plastic[i][*k],
            _ => 0.0,
        }
    }
}
