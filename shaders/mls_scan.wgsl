// Stage `p2g` with MLS, pass 3 of 5 (one workgroup): exclusive prefix sum of
// the per-cell counts into cell starts, resetting the counts to serve as
// fill cursors. Each of the 256 invocations sums a contiguous run of cells.
// CPU twin: `Mls::bin`.
#include "shared/common.wgsl"

@group(0) @binding({{B_MLS_COUNT}}) var<storage, read_write> mls_count: array<u32>;
@group(0) @binding({{B_MLS_START}}) var<storage, read_write> mls_start: array<u32>;

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
        sum += mls_count[i];
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
        mls_start[n] = acc;
    }
    workgroupBarrier();
    var acc = partial[lid];
    for (var i = lo; i < hi; i++) {
        mls_start[i] = acc;
        acc += mls_count[i];
        mls_count[i] = 0u;
    }
}
