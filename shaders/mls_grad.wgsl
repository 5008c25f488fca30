// Stage `stress` with solver.mls_scope = "force", the velocity gradients the
// strain-rate correction needs: one invocation per Gauss point g,
// ω_g L(x_g) into mls_grad[4g..4g+4], or, built with PARTICLES, per
// particle p, V_p L_p into mls_grad[4(n_g + p)..], L = Σ_I v_I ⊗ ∇N_I as
// (xx, xy, yx, yy) from the nodal velocities (after grid_predict), zero
// outside the integration cells whose fits are all regular (mls_occ == 1).
// Positions are those of the fit (MUSL: the step's start, x_start).
// mls_strain.wgsl then sums them. CPU twin: `Mls::strain_correction`
// (src/cpu/mls.rs).
#include "shared/common.wgsl"
#include "shared/shape_bindings.wgsl" LME_ACCESS=read
#include "shared/shape.wgsl"
#include "shared/mls.wgsl"

@group(0) @binding({{B_X0}}) var<storage, read> x0: array<vec2<f32>>;
@group(0) @binding({{B_U}}) var<storage, read> u: array<vec2<f32>>;
#if MUSL
@group(0) @binding({{B_X_START}}) var<storage, read> x_start: array<vec2<f32>>;
#endif
#if PARTICLES
@group(0) @binding({{B_MASS}}) var<storage, read> mass: array<f32>;
@group(0) @binding({{B_RHO}}) var<storage, read> rho: array<f32>;
#endif
@group(0) @binding({{B_MLS_OCC}}) var<storage, read> mls_occ: array<u32>;
@group(0) @binding({{B_NODE_ACC}}) var<storage, read> node_acc: array<f32>;
@group(0) @binding({{B_MLS_GRAD}}) var<storage, read_write> mls_grad: array<vec4<f32>>;

// L = Σ v_I ⊗ ∇N_I at x as (xx, xy, yx, yy); p the particle (LME's λ) or 0.
fn grad_at(p: u32, x: vec2<f32>) -> vec4<f32> {
    let c = shape_ctx(p, x);
    var l = vec4<f32>(0.0);
    for (var k = 0u; k < STENCIL; k++) {
        let w = shape_node(c, k);
        if !w.ok {
            continue;
        }
        let b = w.node * NODE_STRIDE;
        let vn = vec2<f32>(node_acc[b + 1u], node_acc[b + 2u]);
        l += vec4<f32>(vn.x * w.dn.x, vn.x * w.dn.y, vn.y * w.dn.x, vn.y * w.dn.y);
    }
    return l;
}

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
#if PARTICLES
    let p = linear_index(gid, nwg);
    if sim.running == 0u || p >= params.n_particles {
        return;
    }
#if MUSL
    let x = x_start[p];
#else
    let x = x0[p] + u[p];
#endif
    let q = x * params.inv_h;
    let span = mls_span_of(q.y, params.mls_spans_y) * params.mls_spans_x + mls_span_of(q.x, params.mls_spans_x);
    var out = vec4<f32>(0.0);
    if mls_occ[span] == 1u {
        out = grad_at(p, x) * (mass[p] / rho[p]);
    }
    mls_grad[mls_n_gauss() + p] = out;
#else
    let g = linear_index(gid, nwg);
    if sim.running == 0u || g >= mls_n_gauss() {
        return;
    }
    let gp = mls_gauss_point(g);
    var out = vec4<f32>(0.0);
    if mls_occ[gp.span] == 1u {
        out = grad_at(0u, gp.x) * gp.w;
    }
    mls_grad[g] = out;
#endif
}
