//! Vector code where the CPU has it: the particle loops' bodies (`vector`
//! wraps each worker's range) are compiled twice, for baseline x86-64 and
//! for x86-64-v3 (AVX2, FMA, BMI), and the second runs where the CPU
//! reports those features at run time. The compiler contracts no
//! multiply-add into an FMA on its own, so both give the same numbers bit
//! for bit (`tests/fused_step.rs` runs a step each way and compares).
//! `LME_MPM_SIMD=off` in the environment, or `set_enabled(false)`, keeps
//! the baseline code.

use std::sync::atomic::{AtomicU8, Ordering};

/// 0: not decided yet, 1: baseline, 2: x86-64-v3.
static STATE: AtomicU8 = AtomicU8::new(0);

/// Whether the loops run their x86-64-v3 build.
pub fn enabled() -> bool {
    match STATE.load(Ordering::Relaxed) {
        1 => false,
        2 => true,
        _ => {
            let on = detected() && std::env::var("LME_MPM_SIMD").map_or(true, |v| v != "off");
            STATE.store(if on { 2 } else { 1 }, Ordering::Relaxed);
            on
        }
    }
}

/// Turns the x86-64-v3 build on (where the CPU has it) or off, for the
/// whole process.
pub fn set_enabled(on: bool) {
    STATE.store(if on && detected() { 2 } else { 1 }, Ordering::Relaxed);
}

/// Whether this CPU has the features of the x86-64-v3 build.
pub fn detected() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2")
            && std::arch::is_x86_feature_detected!("fma")
            && std::arch::is_x86_feature_detected!("bmi1")
            && std::arch::is_x86_feature_detected!("bmi2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// What the loops run, for `bench` and `check` to say.
pub fn name() -> &'static str {
    if enabled() { "x86-64-v3" } else { "baseline" }
}

/// Runs `f`, compiled for x86-64-v3 where `enabled`.
#[inline(always)]
pub fn vector<R>(f: impl FnOnce() -> R) -> R {
    #[cfg(target_arch = "x86_64")]
    if enabled() {
        // SAFETY: `enabled` is true only where the CPU reports every
        // feature `v3` is compiled with.
        return unsafe { v3(f) };
    }
    f()
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma,bmi1,bmi2")]
unsafe fn v3<R>(f: impl FnOnce() -> R) -> R {
    f()
}
