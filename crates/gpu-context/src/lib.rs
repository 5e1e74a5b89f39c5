//! GPU context for cloth-vis: one small helper that picks a wgpu adapter on any machine,
//! read-back of buffers and textures, linear HDR images written atomically as PNG or EXR, and
//! the boilerplate every GPU crate shares: one-line bind-group layouts ([`layout`]), pipeline
//! builders that count what they build ([`pipeline`]), and the GPU-or-skip test harness
//! ([`testing`]).
//!
//! Every GPU entry point elsewhere in the workspace takes `&wgpu::Device` and `&wgpu::Queue`;
//! acquiring them is this crate's only job. The device is created with the adapter's own limits
//! and, when offered, `TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES` (MSAA on `Rgba32Float`),
//! `DEPTH32FLOAT_STENCIL8` and `FLOAT32_BLENDABLE`, which the shared frame (crate `render`)
//! uses. Adapter choice, in order:
//!
//! 1. the environment: `CLOTH_VIS_BACKEND` (or wgpu's own `WGPU_BACKEND`), a comma list of
//!    `vulkan`, `gl`, `metal`, `dx12`, restricts the backends; `CLOTH_VIS_ADAPTER` (or
//!    `WGPU_ADAPTER_NAME`) picks the adapter whose name contains the given text;
//! 2. a hardware adapter (discrete, then integrated, then virtual);
//! 3. a software adapter, e.g. Mesa's lavapipe (`apt-get install mesa-vulkan-drivers`), which is
//!    what CI and machines without a GPU use.
//!
//! Only adapters that offer what the GPU paths need are chosen (WebGPU's downlevel flags and
//! `Rgba32Float` render targets; Mesa's GL driver lacks both). With no adapter at all,
//! [`GpuContext::new`] returns [`GpuError::NoAdapter`], and with adapters that all lack
//! something [`GpuError::Unsupported`] naming what; both messages say what to install. The
//! device records validation errors instead of panicking (wgpu's default), and the next
//! read-back returns them as [`GpuError::Validation`].
//!
//! No seed section: this is infrastructure (DESIGN.md, "GPU").
//!
//! # Examples
//!
//! ```no_run
//! use gpu_context::{GpuContext, GpuOptions};
//! let ctx = GpuContext::new(&GpuOptions::default())?;
//! println!("rendering on {}", ctx.summary());
//! # Ok::<(), gpu_context::GpuError>(())
//! ```

mod adapter;
mod error;
mod image_out;
pub mod layout;
mod offscreen;
pub mod pipeline;
pub mod testing;

pub use adapter::{
    ADAPTER_ENV, AdapterSummary, BACKEND_ENV, GpuContext, GpuOptions, take_device_error,
};
pub use error::GpuError;
pub use image_out::{HdrImage, write_rgba8_png};
pub use offscreen::{
    COLOR_FORMAT, DEPTH_FORMAT, OffscreenTarget, read_buffer, read_hdr_image, read_texture,
};
pub use pipeline::{PipelineStats, RenderPipelineDesc};
