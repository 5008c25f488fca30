// Stage `remap` of MUSL with MLS (B-spline paper eqs. 31–32), one
// invocation per Gauss point g: fit ρ_p^t v_p^{t+1} with the coefficients of
// this step's mls_p2g and the particles' positions at the step's start
// (`x_start`, written by bin_count: g2p has moved them since), and add
// N_I(x_g) (ρv)_g ω_g to the nodal momentum, which `remap.wgsl` (CLEAR)
// zeroed; the masses stay m_I^t. CPU twin: `Mls::remap` (src/cpu/mls.rs).
#include "shared/common.wgsl"
#include "shared/shape_bindings.wgsl" LME_ACCESS=read
#include "shared/shape.wgsl"
#include "shared/mls.wgsl"

@group(0) @binding({{B_X0}}) var<storage, read> x0: array<vec2<f32>>;
@group(0) @binding({{B_U}}) var<storage, read> u: array<vec2<f32>>;
@group(0) @binding({{B_X_START}}) var<storage, read> x_start: array<vec2<f32>>;
@group(0) @binding({{B_V}}) var<storage, read> v: array<vec2<f32>>;
@group(0) @binding({{B_RHO}}) var<storage, read> rho: array<f32>;
@group(0) @binding({{B_CELL_START}}) var<storage, read> cell_start: array<u32>;
@group(0) @binding({{B_CELL_ORDER}}) var<storage, read> cell_order: array<u32>;
@group(0) @binding({{B_MLS_COEF}}) var<storage, read> mls_coef: array<f32>;
@group(0) @binding({{B_NODE_ACC}}) var<storage, read_write> node_acc: array<{{ATOMIC_T}}>;

#include "shared/atomics.wgsl" ARR=node_acc FN=node_add

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let g = linear_index(gid, nwg);
    if sim.running == 0u || g >= mls_n_gauss() {
        return;
    }
    let c = vec3<f32>(mls_coef[3u * g], mls_coef[3u * g + 1u], mls_coef[3u * g + 2u]);
    if c.x == 0.0 {
        return;
    }
    let gp = mls_gauss_point(g);
    let qg = gp.x * params.inv_h;
    let r = mls_cells_around(qg);
    var q = vec2<f32>(0.0);
    for (var j = r.lo.y; j <= r.hi.y; j++) {
        let row = j * (params.nx - 1u);
        let s = cell_start[row + r.lo.x];
        let e = cell_start[row + r.hi.x + 1u];
        for (var idx = s; idx < e; idx++) {
            let p = cell_order[idx];
            let dw = mls_sample_at(x_start[p], qg);
            let d = dw.xy;
            let w = dw.z;
            if w == 0.0 {
                continue;
            }
            let phi = w * (c.x + c.y * d.x + c.z * d.y);
            q += phi * rho[p] * v[p];
        }
    }
    let fit = q * gp.w;
    let sc = shape_ctx(0u, gp.x);
    for (var k = 0u; k < STENCIL; k++) {
        let nw = shape_node(sc, k);
        if !nw.ok {
            continue;
        }
        let base = nw.node * NODE_STRIDE;
        node_add(base + 1u, nw.n * fit.x);
        node_add(base + 2u, nw.n * fit.y);
    }
}
