//! Light directions for ambient occlusion with image-based illumination: the *lightsphere*
//! (nested octahedral directions l_j with solid angles ω_j) and HDR environment maps sampled
//! per direction (radiance I_j).
//!
//! Implements paper 000 §3.4 "Creating the lightsphere", §4.2 "Changing the Lightsphere
//! configuration" and §5 "Image Based Illumination" (= thesis §4.4.3 and §4.4.5):
//!
//! * level s of the octahedron midpoint subdivision has k = 2 + 4^(s+1) directions
//!   (6, 18, 66, 258, 1026, …) and the directions of level s are the first k(s) of every
//!   finer level, so visibility columns M_ij computed at a coarse level are reused (§3.4,
//!   §4.2); see [`Lightsphere`] and [`direction_count`];
//! * a vertex colour is c_i = Σ_j M_ij I_j (§3.3, the seed's only equation for this step);
//!   I_j comes from an equirectangular ("latitude-longitude", θ ∈ [0, π], φ ∈ [0, 2π]) HDR
//!   map, rotated relative to the object by rotating the look-up directions (§5); see
//!   [`Environment`].
//!
//! Where this crate goes beyond the seed, and why:
//! * ω_j is defined as the area of l_j's spherical Voronoi cell (exact, f64), so that
//!   Σ_j ω_j = 4π and [`Lightsphere::nearest`] returns exactly the cell a direction lies in;
//! * the seed blurs the lat-long image in 2-D (HDRShop), which is wrong at the poles; the
//!   prefilter here is a true spherical Gaussian ([`Environment::prefiltered`]);
//! * the default I_j is the mean radiance over the Voronoi cell
//!   ([`RadianceMethod::CellMean`]), which preserves the map's power for every level; the
//!   seed's prefiltered look-up is [`RadianceMethod::PrefilteredLookup`].
//!
//! The lat-long convention shared with the `synth` crate is in [`latlong`].
//!
//! # Examples
//! ```
//! use lightsphere::{Environment, Lightsphere, RadianceMethod};
//! use glam::Quat;
//!
//! let sphere = Lightsphere::new(2)?; // k = 66 directions
//! // A sky: bright upper hemisphere, dim lower one (8×4 lat-long texels).
//! let texels = (0..32).map(|i| if i < 16 { [2.0f32; 3] } else { [0.5f32; 3] }).collect();
//! let env = Environment::from_latlong(8, 4, texels)?
//!     .with_rotation(Quat::from_rotation_y(0.3));
//! let radiance = env.radiance_per_direction(&sphere, RadianceMethod::CellMean)?;
//! // The cell means preserve the map's power: Σ_j I_j ω_j = ∫ L dω.
//! let error = env.relative_power_error(&sphere, &radiance)?;
//! assert!(error.iter().all(|e| e.abs() < 1e-6));
//! # Ok::<(), lightsphere::LightsphereError>(())
//! ```

mod environment;
mod error;
pub mod latlong;
mod sphere;

pub use environment::MAX_PREFILTER_SIGMA_DEG;
pub use environment::{
    CellMean, CellMeanParams, CellNormalization, Environment, HDR_TEXELS_FLOOR,
    HDR_TEXELS_PER_BYTE, MAX_ENV_DIMENSION, MAX_ENV_TEXELS, MAX_RADIANCE, PrefilterParams,
    RadianceMethod, matched_sigma_deg,
};
pub use error::LightsphereError;
pub use sphere::{Lightsphere, MAX_LEVEL, direction_count};
