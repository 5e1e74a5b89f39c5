//! The crate's error type.

use std::path::PathBuf;

/// Everything that can go wrong while acquiring a GPU or reading results back.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    /// No adapter exists for the allowed backends.
    #[error(
        "no GPU adapter found (backends tried: {backends}; adapters seen: {seen}). \
         On a machine without a GPU install Mesa's software Vulkan driver \
         (`apt-get install mesa-vulkan-drivers`) and, if unset, export XDG_RUNTIME_DIR; \
         commands with a `--backend cpu` option run without a GPU"
    )]
    NoAdapter {
        /// The backends that were searched.
        backends: String,
        /// Adapters that exist but were excluded (name and backend), or `none`.
        seen: String,
    },
    /// Adapters exist, but none offers what the GPU paths need (Mesa's GL driver, for one:
    /// no `textureLoad` from depth textures, no `Rgba32Float` render targets).
    #[error(
        "no usable GPU adapter: {adapters}. Install a Vulkan driver (on a machine without a \
         GPU, Mesa's software one: `apt-get install mesa-vulkan-drivers`); commands with a \
         `--backend cpu` option run without a GPU"
    )]
    Unsupported {
        /// Each adapter with the capabilities it lacks.
        adapters: String,
    },
    /// The device reported a validation error (recorded by the handler that
    /// [`GpuContext::new`](crate::GpuContext::new) installs instead of wgpu's panic).
    #[error("the GPU rejected the work: {0}")]
    Validation(String),
    /// `CLOTH_VIS_ADAPTER` named an adapter that does not exist.
    #[error("no adapter name contains {wanted:?} (set by {env}); available: {available}")]
    AdapterNotFound {
        /// The requested substring.
        wanted: String,
        /// The variable that asked for it.
        env: &'static str,
        /// Names of the adapters that exist.
        available: String,
    },
    /// The adapter refused to create a device.
    #[error("adapter {adapter} refused to create a device: {source}")]
    RequestDevice {
        /// Adapter name.
        adapter: String,
        /// wgpu's reason.
        #[source]
        source: wgpu::RequestDeviceError,
    },
    /// A requested size is zero or exceeds the device limit.
    #[error("{what} of {value} is outside 1..={maximum} on this device; choose a smaller size")]
    SizeOutOfRange {
        /// Which size (e.g. "offscreen width").
        what: &'static str,
        /// The requested value.
        value: u32,
        /// The largest allowed value.
        maximum: u32,
    },
    /// Mapping a read-back buffer or waiting for the device failed.
    #[error("GPU read-back failed: {0}")]
    Readback(String),
    /// Writing an image file failed (nothing is left at `path`).
    #[error("cannot write {path}: {reason}")]
    Write {
        /// Target file.
        path: PathBuf,
        /// What went wrong.
        reason: String,
    },
    /// Image dimensions do not match the pixel count.
    #[error("image of {width}x{height} needs {expected} pixels but {actual} were given")]
    ImageSize {
        /// Width in pixels.
        width: u32,
        /// Height in pixels.
        height: u32,
        /// width × height.
        expected: usize,
        /// Pixels supplied.
        actual: usize,
    },
}
