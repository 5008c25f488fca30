// Stage `p2g` with MLS, pass 4 of 5: list each particle under its grid
// cell (order within a cell is arbitrary). CPU twin: `Mls::bin`.
#include "shared/common.wgsl"

@group(0) @binding({{B_MLS_COUNT}}) var<storage, read_write> mls_count: array<atomic<u32>>;
@group(0) @binding({{B_MLS_START}}) var<storage, read> mls_start: array<u32>;
@group(0) @binding({{B_MLS_CELL}}) var<storage, read> mls_cell: array<u32>;
@group(0) @binding({{B_MLS_ORDER}}) var<storage, read_write> mls_order: array<u32>;

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let p = linear_index(gid, nwg);
    if sim.running == 0u || p >= params.n_particles {
        return;
    }
    let c = mls_cell[p];
    mls_order[mls_start[c] + atomicAdd(&mls_count[c], 1u)] = p;
}
