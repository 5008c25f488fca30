//! Opening a GPU for tests: skip loudly when no adapter exists.

use lme_mpm::gpu::context::{self, AdapterRequest, GpuContext};

/// A device on any adapter (software included), or None after printing why
/// the test is skipped.
pub fn open(test: &str, force_cas: bool) -> Option<GpuContext> {
    if std::env::var_os("NODEVICE_SELECT").is_none() {
        // SAFETY: set before any GPU thread starts; tests read it only through Mesa.
        unsafe { std::env::set_var("NODEVICE_SELECT", "1") };
    }
    let req = AdapterRequest {
        name: std::env::var("LME_MPM_TEST_ADAPTER").ok(),
        allow_software: true,
        force_cas,
    };
    match context::open(&req) {
        Ok(ctx) => Some(ctx),
        Err(e @ lme_mpm::Error::NoAdapter(_)) => {
            println!("SKIPPED {test}: {e}");
            eprintln!("SKIPPED {test}: {e}");
            None
        }
        // An adapter exists but cannot be opened: that is a failure, not a skip.
        Err(e) => panic!("{test}: {e}"),
    }
}
