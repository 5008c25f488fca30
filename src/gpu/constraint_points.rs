//! The constraint points' tables for `shaders/constraint_points.wgsl`,
//! built once at upload from `model::Constraints` (the points do not move,
//! so their weights N_a(x_b) are fixed): one u32 buffer (`Buf::PointTable`)
//! of five tables one after the other, and the size of the per-lane
//! scratch (`Buf::PointWork`). Scenes without points have none of this.
//!
//! Layout of `PointTable` (u32; f32 weights as their bits), offsets in
//! `PointCounts`:
//! - per point: [group, fixed bits, first, start]: its row of the points'
//!   system S = C M⁻¹ Cᵀ holds columns `first..=point`, stored from
//!   `start` in the lane's envelope (every point that shares a node with
//!   it, whichever nodes have mass: a superset of the CPU's envelope,
//!   whose extra entries stay zero);
//! - per point, `slots` local node indices (`u32::MAX`: none), then
//!   `slots` weights;
//! - per held node (every node some point weighs on, ascending): [grid
//!   node, its fixed bits, first entry, entries] into the list;
//! - the list: per held node, [point, weight] for every point it weighs
//!   on, in point order (S's lower triangle is assembled node by node from
//!   it, as the CPU's `by_node`);
//! - per grid node, a bit per group whose points freed it (the group's box
//!   of `constraint_boxes` less these).

use crate::model::Model;

/// Counts and offsets of a scene's point tables (`Variant::points`, and
/// the WGSL values `POINT_*`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PointCounts {
    pub n_points: u32,
    /// Most nodes one point weighs on.
    pub slots: u32,
    /// Nodes some point weighs on.
    pub n_held: u32,
    /// Entries of the node → point list.
    pub n_list: u32,
    /// Entries of S's envelope.
    pub env: u32,
    /// Copies of the nodes (contact pairs' fields): lanes are 2 per field.
    pub n_fields: u32,
}

impl PointCounts {
    pub fn slots_at(&self) -> u32 {
        4 * self.n_points
    }
    pub fn weights_at(&self) -> u32 {
        self.slots_at() + self.slots * self.n_points
    }
    pub fn held_at(&self) -> u32 {
        self.weights_at() + self.slots * self.n_points
    }
    pub fn list_at(&self) -> u32 {
        self.held_at() + 4 * self.n_held
    }
    pub fn freed_at(&self) -> u32 {
        self.list_at() + 2 * self.n_list
    }
    /// f32s of one lane's scratch: the envelope, then per point whether it
    /// is held, r (the residual, then the solve's step), λ and C v, then
    /// per held node Δv.
    pub fn work_stride(&self) -> u32 {
        self.env + 4 * self.n_points + self.n_held
    }
    /// Lanes: one per field and component.
    pub fn lanes(&self) -> u32 {
        2 * self.n_fields
    }
}

/// The tables of `model`'s points, or None without points.
pub fn tables(model: &Model) -> Option<(PointCounts, Vec<u32>)> {
    let c = &model.constraints;
    if c.points.is_empty() {
        return None;
    }
    let mut held: Vec<u32> = c.points.iter().flat_map(|p| p.nodes.clone()).collect();
    held.sort_unstable();
    held.dedup();
    let local = |a: u32| held.binary_search(&a).expect("a point's node is held") as u32;
    // Per held node, its points in order.
    let mut lists: Vec<Vec<(u32, f32)>> = vec![Vec::new(); held.len()];
    for (i, p) in c.points.iter().enumerate() {
        for (&a, &w) in p.nodes.iter().zip(&p.n) {
            lists[local(a) as usize].push((i as u32, w as f32));
        }
    }
    let n = c.points.len();
    let mut first: Vec<u32> = (0..n as u32).collect();
    for list in &lists {
        let lo = list[0].0;
        for &(i, _) in list {
            first[i as usize] = first[i as usize].min(lo);
        }
    }
    let slots = c.points.iter().map(|p| p.nodes.len()).max().unwrap_or(0);
    let n_list: usize = lists.iter().map(Vec::len).sum();
    let mut env = 0u32;
    let mut out = Vec::new();
    for (i, p) in c.points.iter().enumerate() {
        out.extend([p.group, p.fix as u32, first[i], env]);
        env += i as u32 + 1 - first[i];
    }
    for p in &c.points {
        out.extend(p.nodes.iter().map(|&a| local(a)));
        out.extend(std::iter::repeat_n(u32::MAX, slots - p.nodes.len()));
    }
    for p in &c.points {
        out.extend(p.n.iter().map(|&w| (w as f32).to_bits()));
        out.extend(std::iter::repeat_n(0, slots - p.nodes.len()));
    }
    let mut at = 0u32;
    for (k, &a) in held.iter().enumerate() {
        let len = lists[k].len() as u32;
        out.extend([a, c.fix[a as usize] as u32, at, len]);
        at += len;
    }
    for list in &lists {
        for &(i, w) in list {
            out.extend([i, w.to_bits()]);
        }
    }
    let mut freed = vec![0u32; model.grid.n_nodes()];
    for (g, nodes) in c.freed.iter().enumerate() {
        for &a in nodes {
            freed[a as usize] |= 1 << g;
        }
    }
    out.extend(freed);
    let counts = PointCounts {
        n_points: n as u32,
        slots: slots as u32,
        n_held: held.len() as u32,
        n_list: n_list as u32,
        env,
        n_fields: model.n_fields() as u32,
    };
    debug_assert_eq!(
        out.len(),
        (counts.freed_at() as usize) + model.grid.n_nodes()
    );
    Some((counts, out))
}
