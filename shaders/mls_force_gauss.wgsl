// Stage `forces` with solver.mls_scope = "force", the Gauss points' part of
// the corrected internal force, one invocation per Gauss point g: adds
// −ω_g σ_h(x_g) ∇N_I(x_g) to the nodes, σ_h(x_g) from mls_fit.wgsl (in
// mls_coef), for the integration cells whose fits are all regular
// (mls_occ == 1). The particles' part, −V_p (σ_p − σ_h(x_p)) ∇N_I(x_p)
// + N_I m_p b, is forces.wgsl built with MLS_FORCE.
// CPU twin: `Mls::corrected_forces` (src/cpu/mls.rs).
#include "shared/common.wgsl"
#include "shared/shape_bindings.wgsl" LME_ACCESS=read
#include "shared/shape.wgsl"
#include "shared/mls.wgsl"

@group(0) @binding({{B_X0}}) var<storage, read> x0: array<vec2<f32>>;
@group(0) @binding({{B_U}}) var<storage, read> u: array<vec2<f32>>;
@group(0) @binding({{B_MLS_OCC}}) var<storage, read> mls_occ: array<u32>;
@group(0) @binding({{B_MLS_COEF}}) var<storage, read> mls_coef: array<f32>;
@group(0) @binding({{B_NODE_ACC}}) var<storage, read_write> node_acc: array<{{ATOMIC_T}}>;

#include "shared/atomics.wgsl" ARR=node_acc FN=node_add

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let g = linear_index(gid, nwg);
    if sim.running == 0u || g >= mls_n_gauss() {
        return;
    }
    let gp = mls_gauss_point(g);
    if mls_occ[gp.span] != 1u {
        return;
    }
    let s = vec3<f32>(mls_coef[6u * g], mls_coef[6u * g + 1u], mls_coef[6u * g + 2u]);
    let sc = shape_ctx(0u, gp.x);
    for (var k = 0u; k < STENCIL; k++) {
        let nw = shape_node(sc, k);
        if !nw.ok {
            continue;
        }
        let f = -gp.w * vec2<f32>(s.x * nw.dn.x + s.z * nw.dn.y, s.z * nw.dn.x + s.y * nw.dn.y);
        let base = nw.node * NODE_STRIDE;
        node_add(base + 3u, f.x);
        node_add(base + 4u, f.y);
    }
}
