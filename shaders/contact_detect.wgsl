// Stage `grid_update`, contact pairs only, second of `detect` (after
// `contact_grad`): one invocation per pair and grid node. Where both
// fields of the pair have mass, the normal from the pair's first body to
// its second (`contact_normal`, shared/contact.wgsl), then the gap: the
// least distance between the round domains (radius l_p = ½ sqrt(V_p)) of
// the two bodies' particles that reach the node, d(p, q) − l_p − l_q,
// over the particles binned near it (shared/bins.wgsl, by stencil anchor,
// binned in `shape_eval`). The pair is in contact at the node where the
// gap is at most CONTACT_GAP_SLACK times the smallest half-width; elsewhere
// its normal is zero. Writes [n_x, n_y, gap] per pair node
// (`contact_normal`; gap CONTACT_NO_GAP where there is no normal).
// CPU twin: `detect` in src/cpu/contact.rs.
#include "shared/common.wgsl"
#include "shared/shape_bindings.wgsl" LME_ACCESS=read
#include "shared/shape.wgsl"
#include "shared/bins.wgsl"
#include "shared/contact.wgsl"

@group(0) @binding({{B_X0}}) var<storage, read> x0: array<vec2<f32>>;
@group(0) @binding({{B_U}}) var<storage, read> u: array<vec2<f32>>;
@group(0) @binding({{B_MASS}}) var<storage, read> mass: array<f32>;
@group(0) @binding({{B_RHO}}) var<storage, read> rho: array<f32>;
@group(0) @binding({{B_NODE_ACC}}) var<storage, read> node_acc: array<f32>;
@group(0) @binding({{B_CELL_START}}) var<storage, read> cell_start: array<u32>;
@group(0) @binding({{B_CELL_ORDER}}) var<storage, read> cell_order: array<u32>;
@group(0) @binding({{B_CONTACT_PAIRS}}) var<storage, read> contact_pairs: array<ContactPair>;
@group(0) @binding({{B_CONTACT_GRAD}}) var<storage, read> contact_grad: array<f32>;
@group(0) @binding({{B_CONTACT_SLACK}}) var<storage, read> contact_slack: array<u32>;
@group(0) @binding({{B_CONTACT_NORMAL}}) var<storage, read_write> contact_normal_out: array<f32>;

fn grad_of(node: u32) -> vec3<f32> {
    return vec3<f32>(contact_grad[3u * node], contact_grad[3u * node + 1u], contact_grad[3u * node + 2u]);
}

// Particle p's position and half-width if it is of field f and reaches
// node (i, j) with a positive weight; w < 0 otherwise.
fn member(p: u32, f: u32, i: u32, j: u32) -> vec3<f32> {
    if field[p] != f {
        return vec3<f32>(-1.0);
    }
    let x = x0[p] + u[p];
    let w = shape_at(shape_ctx(p, x), i, j);
    if !w.ok || !(w.n > 0.0) {
        return vec3<f32>(-1.0);
    }
    return vec3<f32>(x, 0.5 * sqrt(mass[p] / rho[p]));
}

// The least d(p, q) − l_p − l_q over the particles of fields fa and fb
// that reach node (i, j).
fn node_gap(fa: u32, fb: u32, i: u32, j: u32) -> f32 {
    let cells = cells_reaching(i, j);
    var gap = CONTACT_NO_GAP;
    for (var cj = cells.lo.y; cj <= cells.hi.y; cj++) {
        let row = cj * (params.nx - 1u);
        let end = cell_start[row + cells.hi.x + 1u];
        for (var idx = cell_start[row + cells.lo.x]; idx < end; idx++) {
            let a = member(cell_order[idx], fa, i, j);
            if a.z < 0.0 {
                continue;
            }
            for (var cj2 = cells.lo.y; cj2 <= cells.hi.y; cj2++) {
                let row2 = cj2 * (params.nx - 1u);
                let end2 = cell_start[row2 + cells.hi.x + 1u];
                for (var idx2 = cell_start[row2 + cells.lo.x]; idx2 < end2; idx2++) {
                    let b = member(cell_order[idx2], fb, i, j);
                    if b.z < 0.0 {
                        continue;
                    }
                    gap = min(gap, distance(a.xy, b.xy) - a.z - b.z);
                }
            }
        }
    }
    return gap;
}

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let o = linear_index(gid, nwg);
    if sim.running == 0u || o >= N_PAIRS * params.n_nodes {
        return;
    }
    let k = o / params.n_nodes;
    let i = o % params.n_nodes;
    let fa = contact_pairs[k].fields.x;
    let fb = contact_pairs[k].fields.y;
    let a = fa * params.n_nodes + i;
    let b = fb * params.n_nodes + i;
    var n = vec2<f32>(0.0);
    var gap = CONTACT_NO_GAP;
    if node_acc[a * NODE_STRIDE] > params.mass_eps && node_acc[b * NODE_STRIDE] > params.mass_eps {
        n = contact_normal(grad_of(a), grad_of(b));
    }
    if any(n != vec2<f32>(0.0)) {
        gap = node_gap(fa, fb, i % params.nx, i / params.nx);
        // In contact where the domains meet.
        if gap > CONTACT_GAP_SLACK * bitcast<f32>(contact_slack[0]) {
            n = vec2<f32>(0.0);
        }
    }
    contact_normal_out[3u * o] = n.x;
    contact_normal_out[3u * o + 1u] = n.y;
    contact_normal_out[3u * o + 2u] = gap;
}
