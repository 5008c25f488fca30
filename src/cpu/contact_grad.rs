//! Contact between bodies on the CPU (multi-field MPM, Bardenhagen et al.
//! 2000; the gap from the particles' domains, after Nairn's position
//! checks), in three passes: `contact_grad`, `contact_detect` (before
//! `predict`) and `contact_exchange` (after `predict`, and after `correct`
//! as forces). `model::contact` stacks one copy of the nodes per field,
//! and `offset_nodes` moves each particle's node indices into its body's
//! field after `shape_eval`, so every other stage runs unchanged.
//! `grad`: per field node the body's mass gradient Σ_p m_p ∇N_I and
//! volume Σ_p N_I V_p, which `contact_detect` takes its normals from.
//! GPU twin: `shaders/contact_grad.wgsl`.

use super::contact_detect::ContactState;
use super::stage_inputs::ShapeCache;
use crate::model::Contacts;

/// Moves particle p's node indices into its body's field (node i of field
/// f is `f · n_nodes + i`). Runs after `shape_eval`, which writes grid
/// nodes.
pub fn offset_nodes(cache: &mut ShapeCache, body: &[u32], c: &Contacts, n_nodes: usize) {
    let stride = cache.stride;
    for (p, &b) in body.iter().enumerate() {
        let off = c.field_of_body[b as usize] * n_nodes as u32;
        if off == 0 {
            continue;
        }
        let n = cache.count[p] as usize;
        for node in &mut cache.nodes[p * stride..p * stride + n] {
            *node += off;
        }
    }
}

/// The mass gradients and volumes per field node (`ContactState::grad`),
/// which `detect` reads.
pub fn grad(
    cache: &ShapeCache,
    mass: &[f64],
    rho: &[f64],
    body: &[u32],
    c: &Contacts,
    st: &mut ContactState,
) {
    st.grad.fill([0.0; 3]);
    for p in 0..body.len() {
        if c.field_of_body[body[p] as usize] == 0 {
            // Field 0 takes part only in merges, which need no normal.
            continue;
        }
        let (nodes, w) = cache.particle(p);
        for (&node, wk) in nodes.iter().zip(w) {
            let g = &mut st.grad[node as usize];
            g[0] += mass[p] * wk[1];
            g[1] += mass[p] * wk[2];
            g[2] += wk[0] * mass[p] / rho[p];
        }
    }
}
