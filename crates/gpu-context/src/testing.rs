//! The GPU-or-skip harness every crate's GPU tests use.
//!
//! The project's rule (README): a test that needs a GPU adapter **fails** when `CI` is set and
//! **skips with a printed warning** otherwise. libtest captures `eprintln!` of passing tests,
//! so a skip printed that way never reaches the user; [`gpu_or_skip`] goes through
//! [`test_data::skip`], which writes to the stderr handle itself and numbers the skips of the
//! test binary (`SKIPPED (3 in this binary): …`).
//!
//! ```no_run
//! let Some(gpu) = gpu_context::testing::gpu_or_skip() else { return };
//! println!("testing on {}", gpu.summary());
//! ```

use crate::{GpuContext, GpuOptions};

/// A GPU context with the default options, or `None` after a visible skip message.
///
/// # Panics
/// When no adapter exists and `CI` is set: CI must run every GPU test.
#[track_caller]
pub fn gpu_or_skip() -> Option<GpuContext> {
    match GpuContext::new(&GpuOptions::default()) {
        Ok(ctx) => Some(ctx),
        Err(e) => test_data::skip(&format!("no GPU adapter: {e}")),
    }
}
