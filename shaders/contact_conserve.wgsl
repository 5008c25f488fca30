// Contact pairs, after g2p: each field given back the momentum that the
// interface's PIC share (g2p.wgsl, CONTACT_PIC_FRACTION) changed, as one
// velocity shift of all the field's particles: v_p -= Σ m Δv / M_field.
// CPU twin: src/cpu/contact_conserve.rs.
#include "shared/common.wgsl"

@group(0) @binding({{B_V}}) var<storage, read_write> v: array<vec2<f32>>;
@group(0) @binding({{B_FIELD}}) var<storage, read> field: array<u32>;
@group(0) @binding({{B_CONTACT_PIC}}) var<storage, read> contact_pic: array<f32>;

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let p = linear_index(gid, nwg);
    if sim.running == 0u || p >= params.n_particles {
        return;
    }
    let f = field[p];
    let m = contact_pic[3u * f];
    if m > 0.0 {
        v[p] -= vec2<f32>(contact_pic[3u * f + 1u], contact_pic[3u * f + 2u]) / m;
    }
}
