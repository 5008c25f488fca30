// Binning (shared/bins.wgsl), pass 1 of 4: zero the per-cell particle
// counts and, with MLS, the integration cells' occupied flags.
// CPU twin: `Mls::bin` (src/cpu/mls.rs).
#include "shared/common.wgsl"

@group(0) @binding({{B_CELL_COUNT}}) var<storage, read_write> cell_count: array<u32>;
#if MLS
@group(0) @binding({{B_MLS_OCC}}) var<storage, read_write> mls_occ: array<u32>;
#endif

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = linear_index(gid, nwg);
    if sim.running == 0u {
        return;
    }
    if i < (params.nx - 1u) * (params.ny - 1u) {
        cell_count[i] = 0u;
    }
#if MLS
    if i < params.mls_spans_x * params.mls_spans_y {
        mls_occ[i] = 0u;
    }
#endif
}
