// Stage `cfl`: largest signal speed max_p max(|v_p|, c_p) (paper eq. 43),
// reduced per workgroup, then into Sim.cmax_bits. Runs before step_begin,
// every step (cheap), so the reduction never sees a stale maximum.
// CPU twin: src/cpu/cfl.rs.
#include "shared/common.wgsl"
#include "shared/material.wgsl"

@group(0) @binding({{B_V}}) var<storage, read> v: array<vec2<f32>>;
@group(0) @binding({{B_RHO}}) var<storage, read> rho: array<f32>;
// The state, for models whose wave speed depends on it (the others ignore
// it, and the compiler drops the loads).
@group(0) @binding({{B_STRESS}}) var<storage, read> stress: array<f32>;
#if PLASTIC
@group(0) @binding({{B_PLASTIC}}) var<storage, read> plastic: array<vec4<f32>>;
#endif

var<workgroup> wg_max: atomic<u32>;

@compute @workgroup_size(256)
fn main(
    @builtin(global_invocation_id) gid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let p = linear_index(gid, nwg);
    var s = 0.0;
    if p < params.n_particles {
#if PLASTIC
        let q = plastic[p];
#else
        let q = vec4<f32>(0.0);
#endif
        let sp = vec3<f32>(stress[3u * p], stress[3u * p + 1u], stress[3u * p + 2u]);
        s = max(length(v[p]), wave_speed(material_of(p), rho[p], sp, q));
    }
    // Positive f32 values order like their u32 bits.
    atomicMax(&wg_max, bitcast<u32>(s));
    workgroupBarrier();
    if lid == 0u {
        atomicMax(&sim.cmax_bits, atomicLoad(&wg_max));
    }
}
