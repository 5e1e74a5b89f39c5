//! The crate's single error type.

use std::path::{Path, PathBuf};

/// Everything that can go wrong in this crate.
///
/// Every variant names the offending input (file, level, texel, parameter) and its value, and
/// the message says how to fix it.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum LightsphereError {
    /// A lightsphere level above [`crate::MAX_LEVEL`] was requested.
    #[error(
        "lightsphere level {requested} is above the supported maximum {maximum} \
         ({} directions); choose a level in 0..={maximum}",
        crate::direction_count(*maximum)
    )]
    LevelTooHigh {
        /// The level asked for.
        requested: u32,
        /// The highest supported level.
        maximum: u32,
    },

    /// A rotation quaternion that cannot be normalised (zero length or non-finite).
    #[error(
        "rotation quaternion {value:?} (x, y, z, w) cannot be normalised: it has zero length or \
         non-finite components; pass a unit quaternion such as Quat::from_rotation_y(angle)"
    )]
    InvalidRotation {
        /// The quaternion components `[x, y, z, w]`.
        value: [f32; 4],
    },

    /// An environment map whose width or height is zero or above the supported maximum.
    #[error(
        "{}: environment size {width}x{height} is outside the supported range (1..={max_dimension} \
         texels per side and at most {max_texels} texels in all); resample the map",
        origin_name(.path.as_deref())
    )]
    EnvironmentSize {
        /// The file, or `None` for in-memory input.
        path: Option<PathBuf>,
        /// Width in texels.
        width: usize,
        /// Height in texels.
        height: usize,
        /// [`crate::MAX_ENV_DIMENSION`].
        max_dimension: usize,
        /// [`crate::MAX_ENV_TEXELS`].
        max_texels: usize,
    },

    /// A Radiance header claims more texels than its file's bytes can encode.
    #[error(
        "{path}: the header claims {width}x{height} texels, but the file has {bytes} bytes and \
         run-length encoded scanlines hold at most {per_byte} texels per byte beyond the first \
         {floor} texels; the header is corrupt or the file truncated"
    )]
    HdrHeaderTooLarge {
        /// The file.
        path: PathBuf,
        /// Width from the header.
        width: usize,
        /// Height from the header.
        height: usize,
        /// The file's size.
        bytes: u64,
        /// [`crate::HDR_TEXELS_PER_BYTE`].
        per_byte: u64,
        /// [`crate::HDR_TEXELS_FLOOR`].
        floor: u64,
    },

    /// `from_latlong` was given the wrong number of texels.
    #[error(
        "from_latlong: a {width}x{height} map needs {expected} texels but {actual} were given; \
         pass exactly width*height texels in row-major order, row 0 (top, +Y) first"
    )]
    TexelCount {
        /// Width in texels.
        width: usize,
        /// Height in texels.
        height: usize,
        /// `width * height`.
        expected: usize,
        /// The length of the texel vector.
        actual: usize,
    },

    /// A texel that is negative, NaN, infinite or above [`crate::MAX_RADIANCE`].
    #[error(
        "{}: texel (row {row}, col {col}) channel {channel} has value {value}; radiance must be \
         finite, >= 0 and <= 1e15 (MAX_RADIANCE: larger values overflow the lighting sums), so \
         clamp, rescale or repair the map before loading it",
        origin_name(.path.as_deref())
    )]
    InvalidTexel {
        /// The file, or `None` for in-memory input.
        path: Option<PathBuf>,
        /// Row (0 = top, +Y).
        row: usize,
        /// Column.
        col: usize,
        /// Channel (0 = R, 1 = G, 2 = B).
        channel: usize,
        /// The offending value.
        value: f32,
    },

    /// A file extension other than `.hdr` or `.exr`.
    #[error(
        "{}: unsupported environment format (extension {extension:?}); use a lat-long map in \
         .hdr (Radiance RGBE) or .exr (RGB or RGBA) format",
        .path.display()
    )]
    UnsupportedFormat {
        /// The file.
        path: PathBuf,
        /// Its extension (empty when it has none).
        extension: String,
    },

    /// The file could not be opened, read, written or renamed.
    #[error("{}: cannot {operation} the file: {source}", .path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// What was being done ("open", "write", "rename", ...).
        operation: &'static str,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },

    /// The decoder rejected the file (truncated, corrupt, unsupported variant).
    #[error(
        "{}: cannot decode the {format} data: {source}; check that the file is complete and a \
         valid {format} image",
        .path.display()
    )]
    Decode {
        /// The file.
        path: PathBuf,
        /// "Radiance HDR" or "OpenEXR".
        format: &'static str,
        /// The decoder's error.
        #[source]
        source: Box<dyn std::error::Error + Send + Sync>,
    },

    /// An EXR file without a layer holding `R`, `G` and `B` channels.
    #[error(
        "{}: the EXR file has no layer with channels R, G and B (found: {channels}); export the \
         environment as an RGB or RGBA image",
        .path.display()
    )]
    ExrMissingRgb {
        /// The file.
        path: PathBuf,
        /// The channel names found, comma separated.
        channels: String,
    },

    /// The EXR encoder failed.
    #[error("{}: cannot encode the OpenEXR image: {source}", .path.display())]
    Encode {
        /// The file that was being written.
        path: PathBuf,
        /// The encoder's error.
        #[source]
        source: Box<dyn std::error::Error + Send + Sync>,
    },

    /// A prefilter width that is not finite, not positive or too large.
    #[error(
        "prefilter sigma {sigma_deg} degrees is outside (0, {maximum}]; pass a finite positive \
         angular standard deviation in degrees"
    )]
    InvalidSigma {
        /// The value given.
        sigma_deg: f64,
        /// [`crate::MAX_PREFILTER_SIGMA_DEG`].
        maximum: f64,
    },

    /// A tuning parameter outside its valid range.
    #[error("parameter {name} = {value} is invalid: it must be {requirement}")]
    InvalidParameter {
        /// The parameter's field name.
        name: &'static str,
        /// The value given.
        value: f64,
        /// The valid range, in words.
        requirement: &'static str,
    },

    /// A per-direction radiance slice whose length differs from the lightsphere's.
    #[error(
        "{actual} radiance values were given for a lightsphere with {expected} directions; pass \
         one value per light direction, in the lightsphere's order"
    )]
    RadianceCount {
        /// The lightsphere's direction count.
        expected: usize,
        /// The slice length.
        actual: usize,
    },
}

/// How a texel source is named in messages: the file path, or "from_latlong input".
fn origin_name(path: Option<&Path>) -> String {
    match path {
        Some(path) => path.display().to_string(),
        None => "from_latlong input".to_owned(),
    }
}
