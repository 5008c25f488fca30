// Stage `grid_update`, contact pairs only, second of `detect` (after
// `contact_grad`): one invocation per pair and grid node. Where both
// fields of the pair have mass, the normal from the pair's first body to
// its second (`contact_normal`, shared/contact.wgsl), then the gap: the
// least distance between the round domains (radius l_p = ½ sqrt(V_p)) of
// the two bodies' particles that reach the node, d(p, q) − l_p − l_q,
// over the particles binned near it (shared/bins.wgsl, by stencil anchor,
// binned in `shape_eval`). The pair is in contact at the node where the
// gap is at most CONTACT_GAP_SLACK times the smallest half-width, and
// there the normal becomes the logistic regression's (`lr_normal`: the
// line that separates the two bodies' particles reaching the node);
// elsewhere the normal is zero. Writes [n_x, n_y, gap] per pair node
// (`contact_normal`; gap CONTACT_NO_GAP where there is no normal).
// CPU twin: `detect` in src/cpu/contact_detect.rs.
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

// Particle p's position, volume and side (1 for field fa, 0 for fb) if it
// is of one of them and reaches node (i, j); volume < 0 otherwise.
fn lr_member(p: u32, fa: u32, fb: u32, i: u32, j: u32) -> vec4<f32> {
    let f = field[p];
    if f != fa && f != fb {
        return vec4<f32>(-1.0);
    }
    let x = x0[p] + u[p];
    let w = shape_at(shape_ctx(p, x), i, j);
    if !w.ok || !(w.n > 0.0) {
        return vec4<f32>(-1.0);
    }
    return vec4<f32>(x, mass[p] / rho[p], select(0.0, 1.0, f == fa));
}

// Logistic weights at z for label y (1 or 0), without cancellation:
// (σ(z) − y, σ(z) (1 − σ(z))). CPU twin: `logistic`.
fn logistic(z: f32, y: f32) -> vec2<f32> {
    let e = exp(-abs(z));
    var s = e / (1.0 + e);
    var one_minus_s = 1.0 / (1.0 + e);
    if z >= 0.0 {
        s = 1.0 / (1.0 + e);
        one_minus_s = e / (1.0 + e);
    }
    return vec2<f32>(select(s, -one_minus_s, y > 0.5), e / ((1.0 + e) * (1.0 + e)));
}

// det of the 3 × 3 matrix with columns c0, c1, c2.
fn det3(c0: vec3<f32>, c1: vec3<f32>, c2: vec3<f32>) -> f32 {
    return dot(c0, cross(c1, c2));
}

// The logistic-regression normal (Nairn et al. 2018) over the particles of
// fields fa and fb that reach node (i, j), from n0. CPU twin: `lr_normal`
// in src/cpu/contact_detect.rs (the same steps: mean position and half-width,
// LR_ITERATIONS Newton steps with the ridge LR_RIDGE from 0, each |Δφ|
// capped at LR_MAX_STEP, Cramer's rule; n0 where it separates nothing,
// and where the fit lies within 3° of n0: LR_FLAT_COS).
fn lr_normal(fa: u32, fb: u32, i: u32, j: u32, n0: vec2<f32>) -> vec2<f32> {
    let cells = cells_reaching(i, j);
    var c = vec2<f32>(0.0);
    var vol = 0.0;
    var l = 0.0;
    for (var cj = cells.lo.y; cj <= cells.hi.y; cj++) {
        let row = cj * (params.nx - 1u);
        let end = cell_start[row + cells.hi.x + 1u];
        for (var idx = cell_start[row + cells.lo.x]; idx < end; idx++) {
            let m = lr_member(cell_order[idx], fa, fb, i, j);
            if m.z < 0.0 {
                continue;
            }
            c += m.z * m.xy;
            vol += m.z;
            l += m.z * 0.5 * sqrt(m.z);
        }
    }
    if !(vol > 0.0) {
        return n0;
    }
    c /= vol;
    l /= vol;
    var th = vec3<f32>(0.0);
    for (var it = 0u; it < LR_ITERATIONS; it++) {
        var g = vec3<f32>(LR_RIDGE * th.xy, 0.0);
        var h0 = vec3<f32>(LR_RIDGE, 0.0, 0.0);
        var h1 = vec3<f32>(0.0, LR_RIDGE, 0.0);
        var h2 = vec3<f32>(0.0);
        for (var cj = cells.lo.y; cj <= cells.hi.y; cj++) {
            let row = cj * (params.nx - 1u);
            let end = cell_start[row + cells.hi.x + 1u];
            for (var idx = cell_start[row + cells.lo.x]; idx < end; idx++) {
                let m = lr_member(cell_order[idx], fa, fb, i, j);
                if m.z < 0.0 {
                    continue;
                }
                let w = m.z / vol;
                let d = vec3<f32>((m.xy - c) / l, 1.0);
                let r = logistic(dot(th, d), m.w);
                g += w * r.x * d;
                h0 += w * r.y * d.x * d;
                h1 += w * r.y * d.y * d;
                h2 += w * r.y * d.z * d;
            }
        }
        // Cramer's rule on the symmetric system [h0 h1 h2] s = g.
        let det = det3(h0, h1, h2);
        if !(abs(det) > 0.0) {
            break;
        }
        let step = vec3<f32>(det3(g, h1, h2), det3(h0, g, h2), det3(h0, h1, g)) / det;
        let len = length(step.xy);
        th -= select(1.0, LR_MAX_STEP / len, len > LR_MAX_STEP) * step;
    }
    let len = length(th.xy);
    if len >= LR_MIN_SCALE && len < 3.4e38 {
        let n = -th.xy / len;
        // Within 3° of the gradient normal: a flat face's gradient is exact.
        if dot(n, n0) >= LR_FLAT_COS {
            return n0;
        }
        return n;
    }
    return n0;
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
        } else {
            n = lr_normal(fa, fb, i % params.nx, i / params.nx, n);
        }
    }
    contact_normal_out[3u * o] = n.x;
    contact_normal_out[3u * o + 1u] = n.y;
    contact_normal_out[3u * o + 2u] = gap;
}
