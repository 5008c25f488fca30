//! Stage `cfl`: the time step of `model::time_step` (paper eq. 43, the
//! last-step rule), which is backend-neutral and lives in the model layer
//! so the GPU path and `check` use the same rule.
//! GPU twins: `shaders/cfl.wgsl`, `shaders/step_begin.wgsl`.

pub use crate::model::time_step::{max_speed, time_step};
