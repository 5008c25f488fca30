//! The handlers of the commands whose work is longest to set out (sweep,
//! bench); `main.rs` keeps the command line and the short ones.

pub mod bench;
pub mod common;
pub mod sweep;
