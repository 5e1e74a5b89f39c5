//! Progress inside one computation: how many (receiver row, direction) cells of the call are
//! done, so that a caller can draw a bar over a single long `compute` (issue #18 item 6).
//!
//! The `cpu` backend reports each chunk of rows as its worker finishes it (all of the call's
//! columns for those rows); the GPU backends report each batch of directions when the GPU has
//! finished it (`wgpu::Queue::on_submitted_work_done`, fired by the engine's polls), so the
//! count follows the device, not the recording of commands.

use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

/// Called with (cells done, cells in the call); a cell is one (receiver row, direction) of the
/// columns being computed. Called from worker threads (the `cpu` backend's rayon pool, wgpu's
/// polling thread), possibly concurrently, so successive calls may arrive slightly out of
/// order; the last call of a computation reports `done == total`. Keep it short: a progress
/// bar's `set_position`.
pub type ProgressFn = Arc<dyn Fn(u64, u64) + Send + Sync>;

/// Counts the cells of one computation and forwards the running total.
pub(crate) struct Ticker {
    total: u64,
    done: AtomicU64,
    report: Option<ProgressFn>,
}

impl Ticker {
    /// A counter over `total` cells reporting to `report` (none: counting only).
    pub(crate) fn new(total: u64, report: Option<ProgressFn>) -> Self {
        Self {
            total,
            done: AtomicU64::new(0),
            report,
        }
    }

    /// `cells` more are done.
    pub(crate) fn tick(&self, cells: u64) {
        let done = self.done.fetch_add(cells, Ordering::Relaxed) + cells;
        if let Some(report) = &self.report {
            report(done, self.total);
        }
    }
}
