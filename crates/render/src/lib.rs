//! # render
//!
//! The one frame every cloth-vis effect draws into: an HDR colour target (`Rgba32Float`) with a
//! depth-stencil buffer (`Depth32FloatStencil8`, the stencil for shadow volumes), 4× MSAA where
//! the adapter offers it, one [`Camera`] for every pass and every CPU reference, passes recorded
//! in a fixed order with pipelines built once, an environment backdrop, a filmic tone curve,
//! and PNG/EXR output with a real alpha matte.
//!
//! No seed section of its own: it draws what the seeds compute — Gouraud-interpolated
//! per-vertex radiance c_i = ρ/π Σ_j M_ij I_j ω_j (paper 000 §3.3, thesis §4.4), the BTF
//! material of thesis §5.5 (crate `btf`), and later shadow volumes (§4.2) and translucency.
//!
//! ## The frame, in order
//!
//! | # | pass | depth | stencil | who |
//! |---|---|---|---|---|
//! | 0 | clear: colour = background (alpha 0), depth = far, stencil = 0 | — | — | [`Renderer`] |
//! | 1 | Gouraud meshes (per-vertex radiance, two-sided) | test + write | — | [`GouraudPass`] |
//! | 2 | other opaque passes ([`Phase::Opaque`]): BTF materials | test + write | — | effects |
//! | 3 | passes reading depth/stencil ([`Phase::DepthReading`]): shadow volumes, translucency | test | read/write | effects |
//! | 4 | environment backdrop, only where depth is still the far value | equal | — | [`BackdropPass`] |
//! | 5 | blended passes ([`Phase::Blended`]): BTF fins, premultiplied colour over everything | test | — | effects |
//! | 6 | MSAA resolve | | | [`Renderer`] |
//! | 7 | tone map: exposure (EV), tone curve, sRGB, un-premultiplied colour + alpha | | | [`ToneMapPass`] on the GPU ([`Renderer::render_display`], a viewer's surface), or [`output`] + [`tone`] on the read-back HDR image (PNG; linear EXR) |
//!
//! The two tone maps agree within one 8-bit code (tested). Files go through the CPU one so
//! the EXR keeps linear radiance and automatic exposure can read the objects' pixels and
//! ignore the backdrop; an interactive viewer presents the GPU one every frame.
//!
//! ## Joining the frame
//!
//! An effect builds its pipelines once against [`Renderer::pass_context`] — group 0 is the
//! view (`view.wgsl`, [`VIEW_SHADER`]: `clip_from_world`, `world_from_clip`, eye, viewport);
//! colour target, depth-stencil format and sample count come from [`FrameFormat`] — and per
//! frame hands an object implementing [`FramePass`] to [`Renderer::render`].
//!
//! ## Example
//!
//! ```no_run
//! use glam::Vec3;
//! use render::{Background, Camera, DrawMesh, FrameFormat, Renderer, output, tone::Display};
//! let gpu = gpu_context::GpuContext::new(&Default::default())?;
//! let mut renderer = Renderer::new(&gpu.device, FrameFormat::for_context(&gpu));
//! let positions = [Vec3::ZERO, Vec3::X, Vec3::Y];
//! let radiance = [Vec3::splat(0.5); 3];
//! renderer.gouraud.set_meshes(&gpu.device, &gpu.queue, &[DrawMesh {
//!     positions: &positions, triangles: &[[0, 1, 2]], front: &radiance, back: &radiance,
//! }])?;
//! let camera = Camera::look_at(Vec3::new(0.3, 0.3, 3.0), Vec3::new(0.3, 0.3, 0.0), Vec3::Y, 40.0, 256, 256);
//! let image = renderer.render(&gpu.device, &gpu.queue, &camera, Background::Transparent, &[])?;
//! let display = Display { exposure_ev: output::auto_exposure(&image), ..Default::default() };
//! output::write_png(&image, "triangle.png".as_ref(), &display, Background::Transparent)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod camera;
pub mod tone;

#[cfg(feature = "gpu")]
mod backdrop;
#[cfg(feature = "gpu")]
mod error;
#[cfg(feature = "gpu")]
mod frame;
#[cfg(feature = "gpu")]
mod gouraud;
pub mod ground;
#[cfg(feature = "gpu")]
pub mod output;
pub mod sequence;
#[cfg(feature = "gpu")]
mod target;
#[cfg(feature = "gpu")]
mod tonemap;

#[cfg(feature = "gpu")]
pub use backdrop::{BACKDROP_SHADER, Backdrop, BackdropPass, MAX_BACKDROP_WIDTH};
pub use camera::{Camera, CameraError, DepthConvention, bounding_sphere, usable_radius};
#[cfg(feature = "gpu")]
pub use error::RenderError;
#[cfg(feature = "gpu")]
pub use frame::{FramePass, PassContext, Phase, Renderer};
#[cfg(feature = "gpu")]
pub use gouraud::{DrawMesh, GOURAUD_SHADER, GouraudPass};
#[cfg(feature = "gpu")]
pub use output::Background;
#[cfg(feature = "gpu")]
pub use target::{FrameFormat, PREFERRED_SAMPLES};
#[cfg(feature = "gpu")]
pub use tonemap::{DISPLAY_FORMAT, TONEMAP_SHADER, ToneMapPass};

/// WGSL of group 0, the view, which every pass of the frame prepends to its own shader.
pub const VIEW_SHADER: &str = include_str!("view.wgsl");
