// Binning (shared/bins.wgsl), pass 2 of 4: count the particles per grid cell and note each
// particle's cell. With MLS (stage `p2g`) also mark the integration cells
// that hold one and, with MUSL, keep each particle's position at the step's
// start in `x_start`. For the gather passes (stage `shape_eval`) the cell is
// the particle's stencil anchor (see shared/bins.wgsl), and a particle whose
// shape has left the grid is reported, as the scatter p2g would.
// CPU twin: `Mls::bin` (src/cpu/mls.rs); the gather's binning has none (the
// CPU scatters into private grids).
#include "shared/common.wgsl"
#if ANCHOR_BINS
#include "shared/shape_bindings.wgsl" LME_ACCESS=read
#include "shared/shape.wgsl"
#endif
#include "shared/bins.wgsl"
#if MLS
#include "shared/mls.wgsl"
#endif

@group(0) @binding({{B_X0}}) var<storage, read> x0: array<vec2<f32>>;
@group(0) @binding({{B_U}}) var<storage, read> u: array<vec2<f32>>;
@group(0) @binding({{B_CELL_COUNT}}) var<storage, read_write> cell_count: array<atomic<u32>>;
@group(0) @binding({{B_CELL_OF}}) var<storage, read_write> cell_of: array<u32>;
#if MLS
@group(0) @binding({{B_MLS_OCC}}) var<storage, read_write> mls_occ: array<atomic<u32>>;
#if MUSL
@group(0) @binding({{B_X_START}}) var<storage, read_write> x_start: array<vec2<f32>>;
#endif
#endif

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let p = linear_index(gid, nwg);
    if sim.running == 0u || p >= params.n_particles {
        return;
    }
    let x = x0[p] + u[p];
#if MLS
#if MUSL
    // The step's start positions, for the remap and the stress after g2p.
    x_start[p] = x;
#endif
#endif
    let q = x * params.inv_h;
#if ANCHOR_BINS
    let sc = shape_ctx(p, x);
    if !shape_valid(sc) {
        report_fault(FAULT_LEFT_GRID, p);
    }
    let c = bin_anchor_cell(shape_anchor(sc));
#else
    let c = bin_cell(q);
#endif
    atomicAdd(&cell_count[c], 1u);
    cell_of[p] = c;
#if MLS
    let s = mls_span_of(q.y, params.mls_spans_y) * params.mls_spans_x + mls_span_of(q.x, params.mls_spans_x);
    atomicStore(&mls_occ[s], 1u);
#endif
}
