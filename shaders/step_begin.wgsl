// Stage `step_begin` (one invocation): this step's Δt from the CFL reduction
// and whether the step runs at all. Twin of the Δt and stop logic of
// CpuBackend (src/cpu/mod.rs, Stage::Cfl and `advance`).
#include "shared/common.wgsl"
#include "shared/clock.wgsl"

// A step that would reach within this fraction of the time left of t_end
// lands on it exactly (src/cpu/cfl.rs LAST_STEP_REL).
const LAST_STEP_REL: f32 = 1e-6;

@compute @workgroup_size(1)
fn main() {
    let fault = atomicLoad(&sim.fault);
    let cmax = bitcast<f32>(atomicLoad(&sim.cmax_bits));
    // The next `cfl` pass accumulates from zero.
    atomicStore(&sim.cmax_bits, 0u);
    sim.final_step = 0u;
    // A stop within LAST_STEP_REL of the last step's Δt below counts as
    // reached (model::time_step::stop_reached; GpuBackend::stop_reached).
    let slack = ticks_of(LAST_STEP_REL * sim.dt);
    if fault != FAULT_NONE || ticks_le(sim.t_stop_ticks, ticks_add(sim.ticks, slack))
        || ticks_le(params.t_end_ticks, sim.ticks) {
        // sim.dt keeps the last step's Δt: the next stop's slack (here and
        // on the host) is taken from it.
        sim.running = 0u;
        return;
    }
    var dt = params.cfl_h / cmax;
    if params.fixed_dt > 0.0 {
        dt = params.fixed_dt;
    }
    let rem_end = ticks_seconds(ticks_sub(params.t_end_ticks, sim.ticks));
    if dt >= rem_end * (1.0 - LAST_STEP_REL) {
        dt = rem_end;
        sim.final_step = 1u;
    }
    sim.dt = dt;
    sim.running = 1u;
}
