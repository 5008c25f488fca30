// Gather the probe particles' state into a small buffer for read-back at
// sample times: per probe [x, y, vx, vy, sxx, syy, sxy, 0]. Positions are
// relative to the grid's lower-left node. CPU twin: `probe_states` in
// src/backend.rs (which `CpuBackend::sample` calls).
#include "shared/common.wgsl"

@group(0) @binding({{B_X0}}) var<storage, read> x0: array<vec2<f32>>;
@group(0) @binding({{B_U}}) var<storage, read> u: array<vec2<f32>>;
@group(0) @binding({{B_V}}) var<storage, read> v: array<vec2<f32>>;
@group(0) @binding({{B_STRESS}}) var<storage, read> stress: array<f32>;
@group(0) @binding({{B_PROBE_IDX}}) var<storage, read> probe_idx: array<u32>;
@group(0) @binding({{B_PROBE_OUT}}) var<storage, read_write> probe_out: array<f32>;

// Floats per probe (src/gpu/layout.rs PROBE_STRIDE).
const PROBE_STRIDE: u32 = 8u;

// Workgroup size (src/gpu/layout.rs PROBES_WG, which the dispatch divides by).
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let k = gid.x;
    if k >= params.n_probes {
        return;
    }
    let p = probe_idx[k];
    let x = x0[p] + u[p];
    let o = PROBE_STRIDE * k;
    probe_out[o] = x.x;
    probe_out[o + 1u] = x.y;
    probe_out[o + 2u] = v[p].x;
    probe_out[o + 3u] = v[p].y;
    probe_out[o + 4u] = stress[3u * p];
    probe_out[o + 5u] = stress[3u * p + 1u];
    probe_out[o + 6u] = stress[3u * p + 2u];
    probe_out[o + 7u] = 0.0;
}
