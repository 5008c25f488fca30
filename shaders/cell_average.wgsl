// Stage `stress`, `solver.volumetric_strain = "cell_average"` only, before
// `stress` (built with CELL_AVERAGE), which replaces each particle's
// volumetric strain rate by the volume-weighted mean over the particles of
// its body in its grid cell (a B-bar against volumetric locking):
// per particle, tr L = Σ v_I · ∇N_I from the same nodal velocities and
// weights `stress` reads, and its volume V = m / ρ, added with float
// atomics into [Σ V tr L, Σ V] of its (cell, body) slot, slot
// (cell · N_BODIES + body), the cell the lattice cell holding the
// particle's current position (clamped to the grid). Built with CLEAR: one
// invocation per grid cell zeroes its bodies' slots first.
// CPU twin: `CellAverage::update` in src/cpu/cell_average.rs.
#include "shared/common.wgsl"

#include "shared/cell_average.wgsl"

#if CLEAR
@group(0) @binding({{B_CELL_AVG}}) var<storage, read_write> cell_avg: array<f32>;

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let c = linear_index(gid, nwg);
    if sim.running == 0u || c >= (params.nx - 1u) * (params.ny - 1u) {
        return;
    }
    for (var k = 2u * N_BODIES * c; k < 2u * N_BODIES * (c + 1u); k++) {
        cell_avg[k] = 0.0;
    }
}
#else
#include "shared/shape_bindings.wgsl" LME_ACCESS=read
#include "shared/shape.wgsl"

@group(0) @binding({{B_X0}}) var<storage, read> x0: array<vec2<f32>>;
@group(0) @binding({{B_U}}) var<storage, read> u: array<vec2<f32>>;
#if MUSL
@group(0) @binding({{B_X_START}}) var<storage, read> x_start: array<vec2<f32>>;
#endif
@group(0) @binding({{B_MASS}}) var<storage, read> mass: array<f32>;
@group(0) @binding({{B_RHO}}) var<storage, read> rho: array<f32>;
@group(0) @binding({{B_NODE_ACC}}) var<storage, read> node_acc: array<f32>;
@group(0) @binding({{B_BODY}}) var<storage, read> body: array<u32>;
@group(0) @binding({{B_CELL_AVG}}) var<storage, read_write> cell_avg: array<{{ATOMIC_T}}>;

#include "shared/atomics.wgsl" ARR=cell_avg FN=avg_add

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let p = linear_index(gid, nwg);
    if sim.running == 0u || p >= params.n_particles {
        return;
    }
    let x = x0[p] + u[p];
#if MUSL
    // As `stress`: MUSL's weights are those of the step's start.
    let c = shape_ctx(p, x_start[p]);
#else
    let c = shape_ctx(p, x);
#endif
    var t = 0.0;
    for (var r = 0u; r < SHAPE_ROWS; r++) {
        let span = shape_span(c, r);
        for (var k = span.x; k < span.y; k++) {
            let w = shape_node(c, k);
            if !w.ok {
                continue;
            }
            let b = w.node * NODE_STRIDE;
            t += node_acc[b + 1u] * w.dn.x + node_acc[b + 2u] * w.dn.y;
        }
    }
    let vol = mass[p] / rho[p];
    let slot = cell_slot(x, body[p]);
    avg_add(slot, vol * t);
    avg_add(slot + 1u, vol);
}
#endif
