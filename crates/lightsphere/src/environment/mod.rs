//! HDR environment maps in the lat-long parameterisation (paper 000 §5, thesis §4.4.5).
//!
//! "We now have the environment parameterized with (θ, φ) … Thus, we can easily look-up the
//! intensity from the light coming out of the light direction l_j. When the environment map
//! is rotated relative to the object, the light directions are multiplied by the same rotation
//! matrix to obtain the new look-up positions."
//!
//! An [`Environment`] is a lat-long map (convention in [`crate::latlong`]) plus a rotation
//! `world_from_env`; every look-up by a world direction first applies its inverse.

mod cell_mean;
mod io;
mod per_direction;
mod prefilter;

pub use per_direction::{CellMean, CellMeanParams, CellNormalization, RadianceMethod};
pub use prefilter::{MAX_PREFILTER_SIGMA_DEG, PrefilterParams, matched_sigma_deg};

use crate::{LightsphereError, latlong};
use glam::{DQuat, DVec3, Quat, Vec3};
use std::path::Path;

/// Largest supported width or height of an environment map, in texels.
pub const MAX_ENV_DIMENSION: usize = 32_768;

/// Largest accepted texel radiance. The sun's disk is about 2·10⁷ W sr⁻¹ m⁻² and HDR captures
/// in relative units stay far below that; a texel near f32's limit (a corrupt or crafted RGBE
/// exponent reaches 10³⁸) overflows the lighting sums and the tone curve's x², rendering black
/// or NaN pixels instead of an error (issue #12).
pub const MAX_RADIANCE: f32 = 1e15;

/// Largest supported texel count (2^27 ≈ 134 M texels, 1.6 GB as `[f32; 3]`: a 16k × 8k map).
pub const MAX_ENV_TEXELS: usize = 1 << 27;

/// Texels any Radiance `.hdr` may claim whatever its size (2^22, a 2048 × 2048 map; 48 MB as
/// `[f32; 3]`). Beyond it, the header must be backed by the file's bytes (resource policy,
/// ARCHITECTURE.md): see [`HDR_TEXELS_PER_BYTE`].
pub const HDR_TEXELS_FLOOR: u64 = 1 << 22;

/// Texels per byte of file a Radiance `.hdr` may claim beyond [`HDR_TEXELS_FLOOR`]. Adaptive
/// run-length encoding packs at most 127 texels of one channel into 2 bytes, 4 channels per
/// texel, so a scanline holds at most ≈ 16 texels per byte; 32 leaves room for headers. (The
/// pre-1991 "old" RLE can pack more; such files larger than the floor are refused.)
pub const HDR_TEXELS_PER_BYTE: u64 = 32;

/// A lat-long HDR environment map with a rotation relative to the world.
///
/// # Examples
/// ```
/// use lightsphere::Environment;
/// use glam::Vec3;
/// // A 4×2 map: the upper hemisphere (row 0) is white, the lower one black.
/// let mut texels = vec![[1.0f32; 3]; 4];
/// texels.extend(vec![[0.0f32; 3]; 4]);
/// let env = Environment::from_latlong(4, 2, texels)?;
/// assert_eq!(env.radiance(Vec3::Y), Vec3::ONE);
/// let p = env.total_power();
/// assert!((p[0] - 2.0 * std::f64::consts::PI).abs() < 1e-12);
/// # Ok::<(), lightsphere::LightsphereError>(())
/// ```
#[derive(Clone)]
pub struct Environment {
    width: usize,
    height: usize,
    texels: Vec<[f32; 3]>,
    world_from_env: DQuat,
    /// Mean of the first and last row: the value at +Y and −Y.
    pole_values: [[f32; 3]; 2],
}

impl std::fmt::Debug for Environment {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Environment")
            .field("width", &self.width)
            .field("height", &self.height)
            .field("world_from_env", &self.world_from_env)
            .finish_non_exhaustive()
    }
}

/// Check width and height against the limits before anything is allocated.
pub(crate) fn check_size(
    path: Option<&Path>,
    width: usize,
    height: usize,
) -> Result<(), LightsphereError> {
    let ok = (1..=MAX_ENV_DIMENSION).contains(&width)
        && (1..=MAX_ENV_DIMENSION).contains(&height)
        && width * height <= MAX_ENV_TEXELS;
    if ok {
        Ok(())
    } else {
        Err(LightsphereError::EnvironmentSize {
            path: path.map(Path::to_path_buf),
            width,
            height,
            max_dimension: MAX_ENV_DIMENSION,
            max_texels: MAX_ENV_TEXELS,
        })
    }
}

impl Environment {
    /// A map from row-major texels (row 0 = top = +Y, see [`crate::latlong`]).
    ///
    /// # Errors
    /// [`LightsphereError::EnvironmentSize`] for a zero or too large size,
    /// [`LightsphereError::TexelCount`] when `texels.len() != width * height`,
    /// [`LightsphereError::InvalidTexel`] for a negative, NaN or infinite value or one above
    /// [`MAX_RADIANCE`] (the first one in row-major order).
    pub fn from_latlong(
        width: usize,
        height: usize,
        texels: Vec<[f32; 3]>,
    ) -> Result<Self, LightsphereError> {
        Self::from_texels(None, width, height, texels)
    }

    pub(crate) fn from_texels(
        path: Option<&Path>,
        width: usize,
        height: usize,
        texels: Vec<[f32; 3]>,
    ) -> Result<Self, LightsphereError> {
        check_size(path, width, height)?;
        if texels.len() != width * height {
            return Err(LightsphereError::TexelCount {
                width,
                height,
                expected: width * height,
                actual: texels.len(),
            });
        }
        for (i, t) in texels.iter().enumerate() {
            for (channel, &value) in t.iter().enumerate() {
                // −0.0 is accepted (it compares equal to 0).
                if !(0.0..=MAX_RADIANCE).contains(&value) {
                    return Err(LightsphereError::InvalidTexel {
                        path: path.map(Path::to_path_buf),
                        row: i / width,
                        col: i % width,
                        channel,
                        value,
                    });
                }
            }
        }
        let row_mean = |row: &[[f32; 3]]| {
            let mut sum = [0.0f64; 3];
            for t in row {
                for c in 0..3 {
                    sum[c] += f64::from(t[c]);
                }
            }
            sum.map(|s| (s / row.len() as f64) as f32)
        };
        let pole_values = [
            row_mean(&texels[..width]),
            row_mean(&texels[(height - 1) * width..]),
        ];
        Ok(Self {
            width,
            height,
            texels,
            world_from_env: DQuat::IDENTITY,
            pole_values,
        })
    }

    /// Load a lat-long `.hdr` (Radiance RGBE) or `.exr` (RGB/RGBA, half or float) file.
    ///
    /// The size is checked against [`MAX_ENV_DIMENSION`] and [`MAX_ENV_TEXELS`] from the
    /// header, before the pixels are decoded.
    ///
    /// # Errors
    /// [`LightsphereError::UnsupportedFormat`], [`LightsphereError::Io`],
    /// [`LightsphereError::Decode`] (truncated or corrupt file),
    /// [`LightsphereError::ExrMissingRgb`], [`LightsphereError::EnvironmentSize`],
    /// [`LightsphereError::InvalidTexel`] — each naming the file.
    pub fn load(path: &Path) -> Result<Self, LightsphereError> {
        io::load(path)
    }

    /// Write the texels as a float RGB OpenEXR file. The data go to a temporary file beside
    /// `path` that is renamed over it at the end, so a failure leaves no partial file. The
    /// rotation is not stored.
    ///
    /// # Errors
    /// [`LightsphereError::Io`] or [`LightsphereError::Encode`], naming the file.
    pub fn write_exr(&self, path: &Path) -> Result<(), LightsphereError> {
        io::write_exr(self, path)
    }

    /// Width in texels (azimuth).
    #[must_use]
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in texels (polar angle).
    #[must_use]
    pub fn height(&self) -> usize {
        self.height
    }

    /// Row-major linear RGB texels, row 0 (+Y) first.
    #[must_use]
    pub fn texels(&self) -> &[[f32; 3]] {
        &self.texels
    }

    /// Texel (`row`, `col`).
    ///
    /// # Panics
    /// When `row >= height` or `col >= width`.
    #[must_use]
    pub fn texel(&self, row: usize, col: usize) -> [f32; 3] {
        assert!(
            row < self.height && col < self.width,
            "texel ({row}, {col}) out of range"
        );
        self.texels[row * self.width + col]
    }

    /// The rotation from the map's frame to the world (unit).
    #[must_use]
    pub fn world_from_env(&self) -> Quat {
        self.world_from_env.as_quat()
    }

    /// The same map rotated relative to the object: look-ups by a world direction `d` read
    /// the map at `world_from_env⁻¹ · d`. The quaternion is normalised.
    ///
    /// # Panics
    /// When `world_from_env` has zero length or non-finite components (a programming error);
    /// see [`Environment::try_with_rotation`].
    #[must_use]
    pub fn with_rotation(self, world_from_env: Quat) -> Self {
        match self.try_with_rotation(world_from_env) {
            Ok(env) => env,
            Err(e) => panic!("{e}"),
        }
    }

    /// [`Environment::with_rotation`], returning an error for a quaternion that cannot be
    /// normalised.
    ///
    /// # Errors
    /// [`LightsphereError::InvalidRotation`].
    pub fn try_with_rotation(mut self, world_from_env: Quat) -> Result<Self, LightsphereError> {
        self.world_from_env = crate::sphere::unit_quat(world_from_env)?;
        Ok(self)
    }

    /// Map-frame direction of a world direction.
    pub(crate) fn env_from_world(&self, dir_in_world: DVec3) -> DVec3 {
        self.world_from_env.inverse() * dir_in_world
    }

    /// Bilinearly interpolated radiance arriving from world direction `dir_in_world` (need not
    /// be unit). Wraps in φ. Between the first (last) row's centres and the pole it
    /// interpolates in θ towards the row's mean, which is the value at the pole, so the
    /// look-up is continuous everywhere, the poles included. A zero or non-finite direction
    /// gives zero.
    #[must_use]
    pub fn radiance(&self, dir_in_world: Vec3) -> Vec3 {
        self.radiance_f64(dir_in_world.as_dvec3())
    }

    /// [`Environment::radiance`] for an f64 direction.
    #[must_use]
    pub fn radiance_f64(&self, dir_in_world: DVec3) -> Vec3 {
        let d = self.env_from_world(dir_in_world);
        let Some((x, y)) = latlong::texel_coordinates(d, self.width, self.height) else {
            return Vec3::ZERO;
        };
        let h = self.height as f64;
        if y < 0.0 {
            // Between the north pole (y = −½) and the centre of row 0.
            let t = (y + 0.5) / 0.5;
            let pole = Vec3::from_array(self.pole_values[0]);
            return pole.lerp(self.row_sample(0, x), t.clamp(0.0, 1.0) as f32);
        }
        if y > h - 1.0 {
            let t = (h - 0.5 - y) / 0.5;
            let pole = Vec3::from_array(self.pole_values[1]);
            return pole.lerp(
                self.row_sample(self.height - 1, x),
                t.clamp(0.0, 1.0) as f32,
            );
        }
        let y0 = y.floor();
        let ty = (y - y0) as f32;
        let r0 = (y0 as usize).min(self.height - 1);
        let r1 = (r0 + 1).min(self.height - 1);
        self.row_sample(r0, x).lerp(self.row_sample(r1, x), ty)
    }

    /// Linear interpolation along row `row` at continuous column `x`, wrapping in φ.
    fn row_sample(&self, row: usize, x: f64) -> Vec3 {
        let w = self.width;
        let x0 = x.floor();
        let tx = (x - x0) as f32;
        let c0 = (x0 as i64).rem_euclid(w as i64) as usize;
        let c1 = (c0 + 1) % w;
        let line = &self.texels[row * w..(row + 1) * w];
        Vec3::from_array(line[c0]).lerp(Vec3::from_array(line[c1]), tx)
    }

    /// The texel (piecewise-constant) value at a world direction; zero for invalid input.
    pub(crate) fn texel_at(&self, dir_in_world: DVec3) -> Vec3 {
        let d = self.env_from_world(dir_in_world);
        match latlong::texel_containing(d, self.width, self.height) {
            Some((r, c)) => Vec3::from_array(self.texels[r * self.width + c]),
            None => Vec3::ZERO,
        }
    }

    /// ∫ L dω per channel (f64): the sum over texels of radiance × exact texel solid angle.
    #[must_use]
    pub fn total_power(&self) -> [f64; 3] {
        let mut total = [0.0f64; 3];
        for (row, line) in self.texels.chunks_exact(self.width).enumerate() {
            let mut sum = [0.0f64; 3];
            for t in line {
                for c in 0..3 {
                    sum[c] += f64::from(t[c]);
                }
            }
            let omega = latlong::texel_solid_angle(row, self.width, self.height);
            for c in 0..3 {
                total[c] += sum[c] * omega;
            }
        }
        total
    }
}
