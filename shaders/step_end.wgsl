// Stage `step_end` (one invocation): commit the step's time unless a stage
// found a fault (then stop). Twin of the time update in CpuBackend::step.
#include "shared/common.wgsl"

@compute @workgroup_size(1)
fn main() {
    if sim.running == 0u {
        return;
    }
    if atomicLoad(&sim.fault) != FAULT_NONE {
        sim.running = 0u;
        return;
    }
    if sim.final_step == 1u {
        sim.t = params.t_end_hi;
        sim.t_lo = params.t_end_lo;
    } else {
        // Kahan: t + t_lo accumulates Δt without f32 drift.
        let y = sim.dt - sim.t_lo;
        let t = sim.t + y;
        sim.t_lo = (t - sim.t) - y;
        sim.t = t;
    }
    sim.steps += 1u;
}
