//! # shadows
//!
//! Hard shadows of deforming casters by stencil shadow volumes (thesis §2.4.1, with the
//! silhouettes of §2.2.3), the smooth shadow boundary of §5.5.1 (eq. 5.6), and caster levels
//! of detail chosen by the perception experiment of §4.2 — checked against exact ray-traced
//! shadows (SEED-NOTES §2–§3).
//!
//! * [`volume`]: per-frame volumes of a caster for a point or directional light — silhouette
//!   and border edges, quads extruded to infinity (w = 0) or a finite distance, front and back
//!   caps for z-fail; one-sided solids and two-sided cloth; allocation-free rebuilds.
//! * [`boundary`]: eq. 5.6's per-vertex texture coordinate u = (1 + cos(α + ∠(n̂, l̂)))/2, the
//!   1,024-texel step texture and its blurred variant, the prose's angle-linear reading.
//! * [`lod`]: caster levels by meshoptimizer's simplifier, sampled symmetric Hausdorff distance
//!   in % of the diagonal, the `soft` (1 %) and `hard` (10 %) presets of §4.2.
//! * [`ground`]: a receiver plane sampled on a grid and its exact mask by rays through
//!   occlusion-gpu's BVH — the twin every stencil result is checked against; and
//!   [`exact_view_mask`], the exact mask of any camera's view (first hit per pixel, then its
//!   segment to the light).
//! * `gpu` (feature `gpu`, default): the z-fail stencil pipeline and the ground mask seen by an
//!   orthographic camera from above ([`stencil_ground_mask`]); `frame`: the effect in the
//!   render crate's shared frame — per light, stencil reset, volumes, and the light's direct
//!   term added where the count is 0, through eq. 5.6's texture (`StencilShadows`).
//!
//! # Example
//! ```
//! use glam::{DVec3, Vec3};
//! use shadows::{GroundGrid, Light, exact_ground_mask};
//! use shadows::volume::{CasterTopology, Extrusion, ShadowVolume, Sides, VolumeParams};
//!
//! // A unit square at height 1 under a light straight above: a square shadow on y = 0.
//! let positions = [
//!     Vec3::new(-0.5, 1.0, -0.5), Vec3::new(0.5, 1.0, -0.5),
//!     Vec3::new(0.5, 1.0, 0.5), Vec3::new(-0.5, 1.0, 0.5),
//! ];
//! let triangles = [[0, 2, 1], [0, 3, 2]];
//! let light = Light::Directional(DVec3::Y);
//! let grid = GroundGrid::new(0.0, [-1.0, -1.0, 1.0, 1.0], 8)?;
//! let mask = exact_ground_mask(&positions, &triangles, &light, &grid)?;
//! assert_eq!(mask.iter().sum::<f32>(), 16.0); // the middle 4 × 4 cells
//!
//! // Its volume: the square is open, so its four border edges are silhouettes; with
//! // two-sided casting both faces count, whichever way they are wound.
//! let topology = CasterTopology::new(positions.len(), &triangles)?;
//! let mut volume = ShadowVolume::new();
//! let params = VolumeParams { sides: Sides::Two, extrusion: Extrusion::Finite(10.0), ..Default::default() };
//! let stats = volume.build(&topology, &positions, &light, &params)?;
//! assert_eq!((stats.casting_faces, stats.silhouette_edges), (2, 4));
//! // Below the square the volume winds once, beside it not at all.
//! assert_eq!(volume.winding_number(DVec3::new(0.1, 0.0, 0.2), DVec3::NEG_Y), Some(1));
//! assert_eq!(volume.winding_number(DVec3::new(0.9, 0.0, 0.2), DVec3::NEG_Y), Some(0));
//! # Ok::<(), shadows::ShadowError>(())
//! ```

pub mod boundary;
mod error;
#[cfg(feature = "gpu")]
pub mod frame;
#[cfg(feature = "gpu")]
mod gpu;
pub mod ground;
mod light;
pub mod lod;
mod view;
pub mod volume;

pub use boundary::{BoundaryMode, BoundaryTexture, DEFAULT_ALPHA_DEG, boundary_u};
pub use error::ShadowError;
#[cfg(feature = "gpu")]
pub use gpu::{
    Counting, MaskRenderer, SHADOWS_SHADER, stencil_ground_mask, stencil_test_state,
    volume_stencil_state,
};
pub use ground::{GroundGrid, exact_ground_mask, ground_extrusion};
pub use light::Light;
pub use lod::{Hausdorff, LodLevel, LodTarget, caster_lod, connected_pieces, hausdorff, simplify};
pub use view::exact_view_mask;
