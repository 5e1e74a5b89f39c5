//! Pictures for reports and commands, where people would rather look than read:
//!
//! - [`chart`]: SVG line charts with linear or log10 axes (the reproduction charts of
//!   `cargo xtask repro`, `cloth-vis anim stats --error-plot`, thesis Fig. 3.15);
//! - [`strip`]: K evenly spaced frames of an animation drawn side by side through one camera
//!   and one [`render::Renderer`] (the way thesis §3.2 shows generated sequences, Figs.
//!   3.7–3.10, and §3.3.2 its clusters, Figs. 3.12/3.13).
//!
//! Both are used by the `cloth-vis` binary and by `xtask`; neither is part of the facade's
//! library API.
//!
//! # Example
//! ```
//! use figures::chart::{Axis, Series, chart_svg};
//! let svg = chart_svg(
//!     "d_f per frame",
//!     ["frame", "d_f"],
//!     [Axis::Linear, Axis::Log],
//!     &[Series { label: "k = 8".into(), points: vec![(0.0, 1e-3), (1.0, 2e-3)] }],
//! );
//! assert!(svg.starts_with("<svg") && svg.contains("k = 8"));
//! ```

use std::path::PathBuf;

pub mod chart;
pub mod strip;

/// What drawing a figure can fail with.
#[derive(Debug, thiserror::Error)]
pub enum FigureError {
    /// The request cannot be drawn (bad panel count or size, no triangles); the message names
    /// the flag and the value.
    #[error("{path}: {message}")]
    Request {
        /// The file the figure was for.
        path: PathBuf,
        /// What is wrong and how to fix it.
        message: String,
    },
    /// The renderer refused a panel.
    #[error(transparent)]
    Render(#[from] render::RenderError),
    /// GPU work or image output failed (naming the file).
    #[error(transparent)]
    Gpu(#[from] gpu_context::GpuError),
}
