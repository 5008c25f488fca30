// Included by every stage: shared types and the two bindings all use.
#include "shared/types.wgsl"

@group(0) @binding({{B_PARAMS}}) var<uniform> params: Params;
@group(0) @binding({{B_SIM}}) var<storage, read_write> sim: Sim;

// Nodal accumulators, NODE_STRIDE floats per node: mass (kg), momentum then
// velocity (x, y), force (x, y).
const NODE_STRIDE: u32 = 5u;
