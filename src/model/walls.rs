//! Rigid walls: half-planes behind a line, with a contact law. A wall's
//! nodes are the grid nodes behind its line, (x_node − point)·n ≤ 0, tested
//! on the unperturbed lattice (as constraints are), so a perturbed grid has
//! the same wall nodes as the regular one. Both backends apply the rules
//! (`cpu::grid_update::wall_velocity` and its WGSL twin) from this list.

use crate::error::SceneError;
use crate::model::Grid;
use crate::scene::{Contact, Scene};

/// Contact law code shared with WGSL (`Wall::contact`, shaders/shared/types.wgsl).
pub const CONTACT_STICK: u32 = 0;
pub const CONTACT_SLIP: u32 = 1;
pub const CONTACT_FRICTION: u32 = 2;

/// One wall.
#[derive(Debug, Clone, PartialEq)]
pub struct Wall {
    pub name: String,
    /// A point of the wall line (m).
    pub point: [f64; 2],
    /// Unit normal pointing into the material's side.
    pub normal: [f64; 2],
    /// `CONTACT_*`.
    pub contact: u32,
    /// Coulomb μ (friction only; 0 otherwise).
    pub mu: f64,
    /// Nodes behind the line.
    pub nodes: Vec<u32>,
    /// The wall acts for `appear_at` ≤ t < `remove_at` (s), t the step's
    /// start; 0 and +∞ for a wall that is always there.
    pub appear_at: f64,
    pub remove_at: f64,
}

impl Wall {
    /// Whether the wall acts in the step that starts at `t` (s).
    #[inline]
    pub fn active_at(&self, t: f64) -> bool {
        self.appear_at <= t && t < self.remove_at
    }
}

/// The scene's walls, and per node the bit set of the walls it is behind
/// (bit k = wall k; empty when the scene has no walls).
#[derive(Debug, Clone, Default)]
pub struct Walls {
    pub list: Vec<Wall>,
    pub mask: Vec<u32>,
}

impl Walls {
    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// Whether some wall appears or goes during the run (a gate).
    pub fn timed(&self) -> bool {
        self.list
            .iter()
            .any(|w| w.appear_at > 0.0 || w.remove_at.is_finite())
    }

    /// Walls of `scene` on `grid`. A wall with no node behind it is an
    /// error naming it (it would do nothing).
    pub fn new(scene: &Scene, grid: &Grid) -> Result<Walls, SceneError> {
        let specs = &scene.file.walls;
        if specs.is_empty() {
            return Ok(Walls::default());
        }
        let mut mask = vec![0u32; grid.n_nodes()];
        let mut list = Vec::new();
        // A node on the line counts as behind it; 1e-9 h absorbs the
        // round-off of a line through a node.
        let eps = 1e-9 * grid.h;
        for (k, (name, w)) in specs.iter().enumerate() {
            let len = w.normal[0].hypot(w.normal[1]);
            let n = [w.normal[0] / len, w.normal[1] / len];
            let mut nodes = Vec::new();
            for j in 0..grid.ny {
                for i in 0..grid.nx {
                    let p = grid.lattice_pos(i, j);
                    let d = (p[0] - w.point[0]) * n[0] + (p[1] - w.point[1]) * n[1];
                    if d <= eps {
                        let idx = grid.index(i, j);
                        mask[idx] |= 1 << k;
                        nodes.push(idx as u32);
                    }
                }
            }
            if nodes.is_empty() {
                return Err(SceneError::invalid(
                    format!("walls.{name}"),
                    format!(
                        "has no grid node behind it: the grid spans ({:.6}, {:.6}) to ({:.6}, {:.6}); \
                         move `point` to the material's boundary",
                        grid.min[0],
                        grid.min[1],
                        grid.max()[0],
                        grid.max()[1]
                    ),
                ));
            }
            let (contact, mu) = match w.contact {
                Contact::Stick => (CONTACT_STICK, 0.0),
                Contact::Slip => (CONTACT_SLIP, 0.0),
                Contact::Friction => (CONTACT_FRICTION, w.friction.unwrap_or(0.0)),
            };
            list.push(Wall {
                name: name.clone(),
                point: w.point,
                normal: n,
                contact,
                mu,
                nodes,
                appear_at: w.appear_at,
                remove_at: w.remove_at.unwrap_or(f64::INFINITY),
            });
        }
        Ok(Walls { list, mask })
    }
}
