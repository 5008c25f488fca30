// Binning (shared/bins.wgsl), pass 4 of 4: list each particle under its
// grid cell (order within a cell is arbitrary). CPU twin: `Mls::bin`
// (src/cpu/mls.rs).
#include "shared/common.wgsl"

@group(0) @binding({{B_CELL_COUNT}}) var<storage, read_write> cell_count: array<atomic<u32>>;
@group(0) @binding({{B_CELL_START}}) var<storage, read> cell_start: array<u32>;
@group(0) @binding({{B_CELL_OF}}) var<storage, read> cell_of: array<u32>;
@group(0) @binding({{B_CELL_ORDER}}) var<storage, read_write> cell_order: array<u32>;

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let p = linear_index(gid, nwg);
    if sim.running == 0u || p >= params.n_particles {
        return;
    }
    let c = cell_of[p];
    cell_order[cell_start[c] + atomicAdd(&cell_count[c], 1u)] = p;
}
