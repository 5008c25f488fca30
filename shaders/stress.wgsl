// Stage `stress`: Δε = Δt sym(Σ v_I ⊗ ∇N_I), ρ ← ρ/(1 + tr Δε), σ += D:Δε.
// CPU twin: src/cpu/stress.rs.
#include "shared/common.wgsl"
#include "shared/shape_bindings.wgsl" LME_ACCESS=read
#include "shared/shape.wgsl"
#include "shared/material_linear_elastic.wgsl"
#include "shared/material_bindings.wgsl"

@group(0) @binding({{B_X0}}) var<storage, read> x0: array<vec2<f32>>;
@group(0) @binding({{B_U}}) var<storage, read> u: array<vec2<f32>>;
@group(0) @binding({{B_RHO}}) var<storage, read_write> rho: array<f32>;
@group(0) @binding({{B_STRESS}}) var<storage, read_write> stress: array<f32>;
@group(0) @binding({{B_NODE_ACC}}) var<storage, read> node_acc: array<f32>;

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let p = linear_index(gid, nwg);
    if sim.running == 0u || p >= params.n_particles {
        return;
    }
    let c = shape_ctx(p, x0[p] + u[p]);
    // Velocity gradient L = Σ v ⊗ ∇N as (xx, xy, yx, yy).
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
    let dt = sim.dt;
    let de = vec3<f32>(dt * l.x, dt * l.w, 0.5 * dt * (l.y + l.z));
    let jac = 1.0 + de.x + de.y;
    if !is_finite(jac) {
        report_fault(FAULT_NON_FINITE_STRAIN, p);
        return;
    }
    if jac <= 0.0 {
        report_fault(FAULT_DENSITY, p);
        return;
    }
    rho[p] = rho[p] / jac;
    let s = update_stress(material_of(p), vec3<f32>(stress[3u * p], stress[3u * p + 1u], stress[3u * p + 2u]), de);
    if !(is_finite(s.x) && is_finite(s.y) && is_finite(s.z)) {
        report_fault(FAULT_NON_FINITE_STRESS, p);
        return;
    }
    stress[3u * p] = s.x;
    stress[3u * p + 1u] = s.y;
    stress[3u * p + 2u] = s.z;
}
