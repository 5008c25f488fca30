// Stage `clear_grid`: zero the nodal accumulators and the reactions (and,
// with walls, the nodes' contact weights and walls' forces, which the
// CPU's `wall_touch` and `wall_contact` zero).
// With CONTACT, every field's nodes, the fields' mass gradients and
// volumes (`contact_grad.wgsl` scatters them) and the smallest particle
// half-width (`contact_slack`, kept by atomicMin), and the momentum the
// interface's PIC share changes in g2p (`contact_pic`).
// CPU twin: src/cpu/clear_grid.rs.
#include "shared/common.wgsl"

@group(0) @binding({{B_NODE_ACC}}) var<storage, read_write> node_acc: array<f32>;
@group(0) @binding({{B_REACTIONS}}) var<storage, read_write> reactions: array<f32>;
#if WALLS
@group(0) @binding({{B_WALL_TOUCH}}) var<storage, read_write> wall_touch: array<f32>;
@group(0) @binding({{B_WALL_FORCE}}) var<storage, read_write> wall_force: array<f32>;
#if WALL_PRELOAD
@group(0) @binding({{B_WALL_PRE_FORCE}}) var<storage, read_write> wall_pre_force: array<f32>;
#endif
#endif
#if CONTACT
@group(0) @binding({{B_CONTACT_GRAD}}) var<storage, read_write> contact_grad: array<f32>;
@group(0) @binding({{B_CONTACT_SLACK}}) var<storage, read_write> contact_slack: array<u32>;
@group(0) @binding({{B_CONTACT_PIC}}) var<storage, read_write> contact_pic: array<f32>;
#endif

@compute @workgroup_size(256)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let n = linear_index(gid, nwg);
    if sim.running == 0u {
        return;
    }
    // Constraint groups' reactions, then walls' (the whole buffer).
    if n < arrayLength(&reactions) {
        reactions[n] = 0.0;
    }
#if CONTACT
    if n == 0u {
        // The largest finite f32: atomicMin on the bits of positive floats.
        contact_slack[0] = 0x7f7fffffu;
    }
    // The momentum g2p's interface blend changes, per field (its mass,
    // entry 0, stays).
    if n < N_FIELDS {
        contact_pic[3u * n + 1u] = 0.0;
        contact_pic[3u * n + 2u] = 0.0;
    }
    if n >= field_nodes() {
        return;
    }
    for (var k = 0u; k < 3u; k++) {
        contact_grad[3u * n + k] = 0.0;
    }
#else
    if n >= params.n_nodes {
        return;
    }
#endif
    for (var k = 0u; k < NODE_STRIDE; k++) {
        node_acc[n * NODE_STRIDE + k] = 0.0;
    }
#if WALLS
    wall_touch[2u * n] = 0.0;
    wall_touch[2u * n + 1u] = 0.0;
    wall_force[2u * n] = 0.0;
    wall_force[2u * n + 1u] = 0.0;
#if WALL_PRELOAD
    wall_pre_force[2u * n] = 0.0;
    wall_pre_force[2u * n + 1u] = 0.0;
#endif
#endif
}
