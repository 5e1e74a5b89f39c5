//! The knobs of the GPU backends (`depth` and `query`): plain values, available without the
//! `gpu` feature so [`crate::VisibilityParams`] is the same type on every build.

/// Default depth-map resolution (texels per side). 1024 keeps a 64-layer batch in 256 MiB and
/// runs in seconds on lavapipe; the accuracy target is stated at 2048.
pub const DEFAULT_DEPTH_RESOLUTION: u32 = 1024;
/// Constant depth bias in texels of depth (the "units" of polygon offset (1, 1)). Tuned on the
/// bunny (res4 and full) and a sphere over a plane against the `cpu` backend at 256–2048.
pub const DEFAULT_BIAS_CONSTANT_TEXELS: f32 = 1.0;
/// Slope-scaled depth bias in texels per unit tan θ (the "factor" of polygon offset (1, 1)).
/// Tuned with [`DEFAULT_BIAS_CONSTANT_TEXELS`].
pub const DEFAULT_BIAS_SLOPE_TEXELS: f32 = 1.0;
/// Cap on tan θ in the slope term, so grazing directions (n·l → 0) keep a finite bias.
pub const DEFAULT_MAX_SLOPE: f32 = 8.0;
/// Normal offset of the tested point, in texels. Tuned with the biases above.
pub const DEFAULT_NORMAL_OFFSET_TEXELS: f32 = 0.5;
/// Memory budget of one batch of depth maps (layers × resolution² × 4 bytes).
pub const DEFAULT_MAX_ARRAY_BYTES: u64 = 256 << 20;

/// Tuning knobs of the `depth` backend. The `query` backend uses the same resolution, bias
/// and normal offset (so both GPU backends decide alike); it ignores `max_array_bytes` (one
/// depth map at a time).
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct DepthParams {
    /// Depth-map resolution, texels per side.
    pub resolution: u32,
    /// Constant depth bias, texels of depth.
    pub bias_constant_texels: f32,
    /// Slope-scaled depth bias, texels per unit tan θ.
    pub bias_slope_texels: f32,
    /// Cap on tan θ in the slope term.
    pub max_slope: f32,
    /// Normal offset of the tested point, texels.
    pub normal_offset_texels: f32,
    /// Memory budget of one batch of depth-map layers, bytes.
    pub max_array_bytes: u64,
}

impl Default for DepthParams {
    fn default() -> Self {
        Self {
            resolution: DEFAULT_DEPTH_RESOLUTION,
            bias_constant_texels: DEFAULT_BIAS_CONSTANT_TEXELS,
            bias_slope_texels: DEFAULT_BIAS_SLOPE_TEXELS,
            max_slope: DEFAULT_MAX_SLOPE,
            normal_offset_texels: DEFAULT_NORMAL_OFFSET_TEXELS,
            max_array_bytes: DEFAULT_MAX_ARRAY_BYTES,
        }
    }
}

impl DepthParams {
    /// The same parameters at another depth-map resolution.
    pub fn with_resolution(mut self, resolution: u32) -> Self {
        self.resolution = resolution;
        self
    }
}
