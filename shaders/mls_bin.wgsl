// Stage `p2g` with MLS, pass 2 of 5: count the particles per grid cell and
// mark the integration cells that hold one; MUSL: keep each particle's
// position at the step's start in `x_start`. CPU twin: `Mls::bin`.
#include "shared/common.wgsl"
#include "shared/mls.wgsl"

@group(0) @binding({{B_X0}}) var<storage, read> x0: array<vec2<f32>>;
@group(0) @binding({{B_U}}) var<storage, read> u: array<vec2<f32>>;
@group(0) @binding({{B_MLS_COUNT}}) var<storage, read_write> mls_count: array<atomic<u32>>;
@group(0) @binding({{B_MLS_CELL}}) var<storage, read_write> mls_cell: array<u32>;
@group(0) @binding({{B_MLS_OCC}}) var<storage, read_write> mls_occ: array<atomic<u32>>;
#if MUSL
@group(0) @binding({{B_X_START}}) var<storage, read_write> x_start: array<vec2<f32>>;
#endif

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let p = linear_index(gid, nwg);
    if sim.running == 0u || p >= params.n_particles {
        return;
    }
#if MUSL
    // The step's start positions, for the remap and the stress after g2p.
    x_start[p] = x0[p] + u[p];
#endif
    let q = (x0[p] + u[p]) * params.inv_h;
    let c = mls_grid_cell(q);
    atomicAdd(&mls_count[c], 1u);
    mls_cell[p] = c;
    let s = mls_span_of(q.y, params.mls_spans_y) * params.mls_spans_x + mls_span_of(q.x, params.mls_spans_x);
    atomicStore(&mls_occ[s], 1u);
}
