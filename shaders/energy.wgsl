// Energy diagnostics at sample times: Σ ½ m |v|², Σ V W(σ), and the bound
// Σ (m |g| + |F|) |u| on the work of gravity and the loads (F the full
// traction or point-load force of a particle, with EXT_FORCE), reduced per
// workgroup then added into energy_out[0..3]. CPU twin: src/cpu/energy.rs.
#include "shared/common.wgsl"
#include "shared/material.wgsl"
#if DEF_GRAD
@group(0) @binding({{B_DEF_GRAD}}) var<storage, read> def_grad: array<vec4<f32>>;
#endif
#if PLASTIC
@group(0) @binding({{B_PLASTIC}}) var<storage, read> plastic: array<vec4<f32>>;
#endif

@group(0) @binding({{B_U}}) var<storage, read> u: array<vec2<f32>>;
@group(0) @binding({{B_V}}) var<storage, read> v: array<vec2<f32>>;
@group(0) @binding({{B_MASS}}) var<storage, read> mass: array<f32>;
@group(0) @binding({{B_RHO}}) var<storage, read> rho: array<f32>;
@group(0) @binding({{B_STRESS}}) var<storage, read> stress: array<f32>;
#if EXT_FORCE
// (fx, fy, ramp_time) per particle (shared/body_force.wgsl).
@group(0) @binding({{B_EXT_FORCE}}) var<storage, read> ext_force: array<f32>;
#endif
@group(0) @binding({{B_ENERGY_OUT}}) var<storage, read_write> energy_out: array<{{ATOMIC_T}}>;

#include "shared/atomics.wgsl" ARR=energy_out FN=energy_add

var<workgroup> wg: array<vec4<f32>, 256>;

fn particle_def_grad(p: u32) -> vec4<f32> {
#if DEF_GRAD
    return def_grad[p];
#else
    return vec4<f32>(1.0, 0.0, 0.0, 1.0);
#endif
}

fn particle_plastic(p: u32) -> vec4<f32> {
#if PLASTIC
    return plastic[p];
#else
    return vec4<f32>(0.0);
#endif
}

@compute @workgroup_size(256)
fn main(
    @builtin(global_invocation_id) gid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let p = linear_index(gid, nwg);
    var e = vec4<f32>(0.0);
    if p < params.n_particles {
        let m = mass[p];
        let s = vec3<f32>(stress[3u * p], stress[3u * p + 1u], stress[3u * p + 2u]);
        var load = m * length(params.gravity);
#if EXT_FORCE
        load += length(vec2<f32>(ext_force[3u * p], ext_force[3u * p + 1u]));
#endif
        e = vec4<f32>(
            0.5 * m * dot(v[p], v[p]),
            m / rho[p] * strain_energy_density(material_of(p), s, particle_def_grad(p), particle_plastic(p)),
            load * length(u[p]),
            0.0,
        );
    }
    wg[lid] = e;
    for (var stride = 128u; stride > 0u; stride >>= 1u) {
        workgroupBarrier();
        if lid < stride {
            wg[lid] += wg[lid + stride];
        }
    }
    if lid == 0u {
        energy_add(0u, wg[0].x);
        energy_add(1u, wg[0].y);
        energy_add(2u, wg[0].z);
    }
}
