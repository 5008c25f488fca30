// Stage `step_begin` (one invocation): this step's Δt from the CFL reduction
// and whether the step runs at all. Twin of the Δt and stop logic of
// CpuBackend (src/cpu/mod.rs, Stage::Cfl and `advance`).
#include "shared/common.wgsl"

// A step that would reach within this fraction of the time left of t_end
// lands on it exactly (src/cpu/cfl.rs LAST_STEP_REL).
const LAST_STEP_REL: f32 = 1e-6;

@compute @workgroup_size(1)
fn main() {
    let fault = atomicLoad(&sim.fault);
    let cmax = bitcast<f32>(atomicLoad(&sim.cmax_bits));
    // The next `cfl` pass accumulates from zero.
    atomicStore(&sim.cmax_bits, 0u);
    let rem_stop = (sim.t_stop_hi - sim.t) + (sim.t_stop_lo - sim.t_lo);
    let rem_end = (params.t_end_hi - sim.t) + (params.t_end_lo - sim.t_lo);
    sim.final_step = 0u;
    if fault != FAULT_NONE || rem_stop <= 0.0 || rem_end <= 0.0 {
        sim.running = 0u;
        sim.dt = 0.0;
        return;
    }
    var dt = params.cfl_h / cmax;
    if params.fixed_dt > 0.0 {
        dt = params.fixed_dt;
    }
    if dt >= rem_end * (1.0 - LAST_STEP_REL) {
        dt = rem_end;
        sim.final_step = 1u;
    }
    sim.dt = dt;
    sim.running = 1u;
}
