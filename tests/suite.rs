//! Every integration test but `no_alloc` in one test binary: one link
//! against the library and wgpu instead of thirty, and the harness packs the
//! files' tests onto the cores together (a long test of one file no longer
//! leaves a core idle while the next file waits). Each file stays a module
//! of its own name, so `cargo test --release --test suite boundaries::` runs
//! one file. `tests/no_alloc.rs` stays a binary of its own: its counting
//! global allocator would count every other test's allocations too.

#[path = "common/mod.rs"]
mod common;

#[path = "benchmarks.rs"]
mod benchmarks;
#[path = "boundaries.rs"]
mod boundaries;
#[path = "cases.rs"]
mod cases;
#[path = "cli.rs"]
mod cli;
#[path = "constraint_points.rs"]
mod constraint_points;
#[path = "contact.rs"]
mod contact;
#[path = "driver.rs"]
mod driver;
#[path = "file_imports.rs"]
mod file_imports;
#[path = "fused_step.rs"]
mod fused_step;
#[path = "gmm.rs"]
mod gmm;
#[path = "gpu_large.rs"]
mod gpu_large;
#[path = "gpu_resume.rs"]
mod gpu_resume;
#[path = "gpu_shaders.rs"]
mod gpu_shaders;
#[path = "granular_collapse.rs"]
mod granular_collapse;
#[path = "implicit.rs"]
mod implicit;
#[path = "initial_states.rs"]
mod initial_states;
#[path = "layers.rs"]
mod layers;
#[path = "material_returns.rs"]
mod material_returns;
#[path = "mls_force.rs"]
mod mls_force;
#[path = "mls_reconstruction.rs"]
mod mls_reconstruction;
#[path = "modified_cam_clay.rs"]
mod modified_cam_clay;
#[path = "plan_coverage.rs"]
mod plan_coverage;
#[path = "preflight.rs"]
mod preflight;
#[path = "readme.rs"]
mod readme;
#[path = "render.rs"]
mod render;
#[path = "results.rs"]
mod results;
#[path = "run_parity.rs"]
mod run_parity;
#[path = "run_safety.rs"]
mod run_safety;
#[path = "saturated.rs"]
mod saturated;
#[path = "shape_functions.rs"]
mod shape_functions;
#[path = "stage_parity.rs"]
mod stage_parity;
#[path = "studies.rs"]
mod studies;
#[path = "sweep.rs"]
mod sweep;
