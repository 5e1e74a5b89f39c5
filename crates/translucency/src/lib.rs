//! # translucency
//!
//! Real-time subsurface appearance of deformable meshes (seed 004, Banterle & Chalmers, "A
//! fast translucency appearance model for real-time applications"; SEED-NOTES §5): light
//! entering the object is gathered at one accumulation point, projected onto spherical
//! harmonics every frame, and leaves along the refraction vector attenuated by the thickness
//! the light crossed —
//!
//! L^e(x_out, ω_out) = (1/π) F_t(η, ω_out) · (σ_tr d + 1) e^{−σ_tr d} / (σ′_t d³) · B(r)  (eq. 12)
//!
//! with B(r) = r̃ᵀ M r̃ (eq. 10, the corrected symmetric M).
//!
//! * [`sh`]: the nine real SH basis functions (R&H's polynomials, no Condon–Shortley phase),
//!   exact projection of lat-long maps, cube-map projection with exact texel solid angles,
//!   the irradiance matrix, rotation, windowing against ringing and the documented clamp.
//! * [`cube`]: the cube-map face layout shared by the GPU pass and the CPU reference.
//! * [`material`]: σ_a, σ′_s, η, the dipole's σ′_t and σ_tr, Jensen et al. 2001's presets.
//! * [`model`]: Schlick's F_t, the attenuation and its clamp, the refraction vector, the
//!   accumulation frame with the "blindness" (cube scaling) and "shift" (ray–box) fixes,
//!   eq. 12 per point — the CPU reference of the GPU pipeline.
//! * `gpu` (feature `gpu`, default): the per-frame pipeline — external cube map of the lit
//!   object, SH reduction, light-space linear-distance map with one peeled layer and a
//!   separable Gaussian, and eq. 12 per pixel added to the render crate's shared frame.
//!
//! **One thickness.** d is the distance from the light map's first surface to the shaded
//! point, so everything in front of the point along the light counts as material — also a
//! zero-thickness flap (a back-to-back triangle pair, which `cloth-vis inspect` counts) standing
//! off the surface: its footprint on the surface behind it is attenuated as if the gap were
//! filled, a small dark dash. `bun_zipper_res3.ply` shows a few (70 pairs from its
//! decimation); with the pairs and repeats removed (3,711 of its 3,851 triangles kept) the
//! same render loses them. The few small dark triangles `cloth-vis translucency` leaves on it
//! under a point light are not this crate's term: they are the direct term ρ/π E max(0, n·l)
//! the command adds per vertex (Gouraud), dark at about five vertices whose own faces fold
//! back (151–180° between face normals) or crease (61–66°), so that their angle-weighted
//! normal faces away from a light their neighbours face. With eq. 12 replaced by a constant
//! they remain; with the direct term left out they are gone.
//!
//! # Example
//! ```
//! use glam::DVec3;
//! use translucency::{Sh9, Material, model};
//!
//! // A delta light along +z: B(t) = 0.25 + 0.5 t + 0.15625 (3t² − 1) (SEED-NOTES §5.6).
//! let sh = Sh9::delta(DVec3::Z, [1.0; 3]);
//! assert!((sh.irradiance(DVec3::Z)[0] - 1.0625).abs() < 1e-12);
//! assert!((sh.irradiance(DVec3::X)[0] - 0.09375).abs() < 1e-12);
//! // …which rings below zero behind the light; the documented clamp removes it.
//! assert!(sh.irradiance(DVec3::new(0.866, 0.0, -0.5))[0] < 0.0);
//! assert_eq!(sh.irradiance_clamped(DVec3::new(0.866, 0.0, -0.5))[0], 0.0);
//!
//! // Marble's dipole coefficients, and eq. 12's attenuation through 5 mm of it.
//! let marble = Material::preset("marble")?;
//! let (tr, tp) = (marble.sigma_tr()[0], marble.sigma_t_prime()[0]);
//! assert!((tp - 2.1921).abs() < 1e-12);
//! let a = model::attenuation(tr, tp, 5.0);
//! assert!(a > 0.0 && a < model::attenuation(tr, tp, 1.0));
//! # Ok::<(), translucency::TranslucencyError>(())
//! ```

pub mod cube;
mod error;
#[cfg(feature = "gpu")]
pub mod gpu;
pub mod material;
pub mod model;
pub mod sh;

pub use cube::CubeMap;
pub use error::TranslucencyError;
#[cfg(feature = "gpu")]
pub use gpu::{PassTimes, PipelineParams, TranslucencyPass, TranslucentMesh};
pub use material::{Material, PRESETS};
pub use model::{AccumulationFrame, Light};
pub use sh::{Sh9, Window};
