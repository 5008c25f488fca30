//! Opening a GPU for tests. Without an adapter a test skips loudly: one
//! `SKIPPED <test>: no GPU adapter (<reason>)` line on the process's real
//! stderr, which libtest does not capture. With `LME_MPM_REQUIRE_GPU=1`
//! (set by `.ci/run`) a missing adapter fails the test instead, so a CI
//! image that loses its Vulkan driver turns red rather than green.

use lme_mpm::gpu::context::{self, AdapterRequest, GpuContext};
use std::io::Write;

/// The environment variable that makes a missing adapter a failure.
pub const REQUIRE_GPU: &str = "LME_MPM_REQUIRE_GPU";

/// Whether the environment asks for a GPU: set to anything but "" or "0".
pub fn required() -> bool {
    std::env::var(REQUIRE_GPU).is_ok_and(|v| !v.is_empty() && v != "0")
}

/// The running test's name (libtest names each test's thread after it),
/// with `label` when it says more than the name.
fn test_name(label: &str) -> String {
    match std::thread::current().name() {
        Some(n) if n != "main" && n != label => format!("{n} ({label})"),
        _ => label.to_string(),
    }
}

/// A device on any adapter (software included), or None after printing why
/// the test is skipped. Panics when no adapter exists and `REQUIRE_GPU` is
/// set, and whenever an adapter exists but cannot be opened. Scatters use
/// the compare-exchange loop when `force_cas` is given or, as for
/// `lme-mpm run`, when `LME_MPM_FORCE_CAS` is set, so the whole suite can be
/// run on that path.
pub fn open(label: &str, force_cas: bool) -> Option<GpuContext> {
    if std::env::var_os("NODEVICE_SELECT").is_none() {
        // SAFETY: set before any GPU thread starts; tests read it only through Mesa.
        unsafe { std::env::set_var("NODEVICE_SELECT", "1") };
    }
    let req = AdapterRequest {
        name: std::env::var("LME_MPM_TEST_ADAPTER").ok(),
        allow_software: true,
        force_cas: force_cas || std::env::var_os("LME_MPM_FORCE_CAS").is_some(),
    };
    match context::open(&req) {
        Ok(ctx) => Some(ctx),
        Err(lme_mpm::Error::NoAdapter(why)) => {
            let test = test_name(label);
            if required() {
                panic!("{test}: {REQUIRE_GPU} is set but there is no GPU adapter ({why})");
            }
            // Straight to the file descriptor: `eprintln!` would be captured
            // and shown only for failing tests.
            let _ = writeln!(std::io::stderr(), "SKIPPED {test}: no GPU adapter ({why})");
            None
        }
        // An adapter exists but cannot be opened: that is a failure, not a skip.
        Err(e) => panic!("{}: {e}", test_name(label)),
    }
}

/// Runs a test's own small compute kernel once: binds `buffers` (binding
/// number, buffer) to group 0 of `pipeline`, dispatches `groups`
/// workgroups, and returns `read`'s first `bytes` bytes as f32s.
pub fn dispatch_and_read(
    ctx: &GpuContext,
    pipeline: &wgpu::ComputePipeline,
    buffers: &[(u32, &wgpu::Buffer)],
    groups: u32,
    read: &wgpu::Buffer,
    bytes: u64,
) -> Vec<f32> {
    let dev = &ctx.device;
    let staging = dev.create_buffer(&wgpu::BufferDescriptor {
        label: Some("staging"),
        size: bytes,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let entries: Vec<wgpu::BindGroupEntry> = buffers
        .iter()
        .map(|&(binding, b)| wgpu::BindGroupEntry {
            binding,
            resource: b.as_entire_binding(),
        })
        .collect();
    let group = dev.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &pipeline.get_bind_group_layout(0),
        entries: &entries,
    });
    let mut enc = dev.create_command_encoder(&Default::default());
    {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.dispatch_workgroups(groups, 1, 1);
    }
    enc.copy_buffer_to_buffer(read, 0, &staging, 0, bytes);
    ctx.queue.submit([enc.finish()]);
    staging.map_async(wgpu::MapMode::Read, .., |r| r.unwrap());
    dev.poll(wgpu::PollType::wait_indefinitely()).unwrap();
    let view = staging.get_mapped_range(..).unwrap();
    bytemuck::cast_slice(&view[..]).to_vec()
}
