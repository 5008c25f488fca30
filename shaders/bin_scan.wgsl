// Binning (shared/bins.wgsl), pass 3 of 4 (one workgroup): exclusive prefix sum of
// the per-cell counts into cell starts, resetting the counts to serve as
// fill cursors. Each of the 256 invocations sums a contiguous run of cells.
// CPU twin: `Mls::bin` (src/cpu/mls.rs).
#include "shared/common.wgsl"

@group(0) @binding({{B_CELL_COUNT}}) var<storage, read_write> cell_count: array<u32>;
@group(0) @binding({{B_CELL_START}}) var<storage, read_write> cell_start: array<u32>;

var<workgroup> partial: array<u32, 256>;

@compute @workgroup_size(256)
fn main(@builtin(local_invocation_index) lid: u32) {
    // No early return: barriers need uniform control flow (a stopped step's
    // later passes return early, so the result is unused then).
    let n = (params.nx - 1u) * (params.ny - 1u);
    let chunk = (n + 255u) / 256u;
    let lo = min(lid * chunk, n);
    let hi = min(lo + chunk, n);
    var sum = 0u;
    for (var i = lo; i < hi; i++) {
        sum += cell_count[i];
    }
    partial[lid] = sum;
    workgroupBarrier();
    if lid == 0u {
        var acc = 0u;
        for (var k = 0u; k < 256u; k++) {
            let s = partial[k];
            partial[k] = acc;
            acc += s;
        }
        cell_start[n] = acc;
    }
    workgroupBarrier();
    var acc = partial[lid];
    for (var i = lo; i < hi; i++) {
        cell_start[i] = acc;
        acc += cell_count[i];
        cell_count[i] = 0u;
    }
}
