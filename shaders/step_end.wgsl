// Stage `step_end` (one invocation): commit the step's time unless a stage
// found a fault (then stop). Twin of the time update in CpuBackend::step.
#include "shared/common.wgsl"
#include "shared/clock.wgsl"

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
        sim.ticks = params.t_end_ticks;
    } else if params.fixed_dt > 0.0 {
        // The fixed Δt as the CPU path adds it (f64), not its f32 rounding,
        // so both paths reach the same times in the same number of steps.
        sim.ticks = ticks_add(sim.ticks, params.fixed_dt_ticks);
    } else {
        sim.ticks = ticks_add(sim.ticks, ticks_of(sim.dt));
    }
    let t = ticks_split(sim.ticks);
    sim.t = t.x;
    sim.t_lo = t.y;
    sim.steps += 1u;
}
