// Included by every stage: shared types and the two bindings all use.
#include "shared/types.wgsl"

@group(0) @binding({{B_PARAMS}}) var<uniform> params: Params;
@group(0) @binding({{B_SIM}}) var<storage, read_write> sim: Sim;

// Nodal accumulators, NODE_STRIDE floats per node: mass (kg), momentum then
// velocity (x, y), force (x, y).
const NODE_STRIDE: u32 = 5u;
#if CONTACT

// Contact pairs (`model::contact`): the nodal arrays hold N_FIELDS copies
// of the grid's nodes, stacked (node i of field f is f · n_nodes + i), and
// the scene declares N_PAIRS pairs.
const N_FIELDS: u32 = {{N_FIELDS}}u;
const N_PAIRS: u32 = {{N_PAIRS}}u;

// Nodes of all the fields.
fn field_nodes() -> u32 {
    return N_FIELDS * params.n_nodes;
}
#endif
