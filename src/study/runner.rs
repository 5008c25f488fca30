//! The studies' jobs run on the sweep machinery (`crate::sweep::runner`);
//! this name stays so each study reads `super::runner::{Job, JobResult}`.

pub use crate::sweep::runner::*;
