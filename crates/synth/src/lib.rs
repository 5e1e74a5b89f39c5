//! Procedural data for demos and tests: a cloth drape animation, HDR skies with a sun, a
//! woven-cloth BTF and wool fin images.
//!
//! Nothing here reads a file; everything is deterministic for its parameters (including
//! the seed). Output is plain data (glam vectors, `Vec`s), not other project crates' types.
//!
//! * [`simulate_cloth`]: a square cloth dropped onto a sphere standing on the ground,
//!   simulated with small-step XPBD (stretch constraints, long-range tethers, isometric
//!   bending, obstacle and ground contact with Coulomb friction, vertex self-collision
//!   through a spatial hash). The default — 66 × 66 = 4,356 vertices, 120 frames at 30 fps,
//!   24 substeps — takes about a second on one core and ends in irregular folds that
//!   shadow themselves. It provides the deforming sequences that the thesis's animation
//!   methods (§3.2 jump maps, §3.3 clustered PCA of trajectories) and dynamic ambient
//!   occlusion (§4.4) work on; its trajectories are genuinely high-rank (about 10 principal
//!   components for 99.9% of the energy), not a few sine modes. [`obstacle_mesh`]
//!   triangulates the sphere for rendering beside the cloth.
//! * [`sky`]: an equirectangular HDR environment (Preetham clear sky, Lambertian ground, a
//!   limb-darkened sun disc a chosen multiple — default 5·10⁴ — brighter than the mean sky,
//!   power-conserving at any resolution) in the shared [`latlong`] convention used by
//!   `lightsphere` (thesis §4.4.5 lights the cloth with such maps).
//! * [`WovenBtf`] ([`btf`]): a procedural bidirectional texture function of plain-weave
//!   cloth, the stand-in for the measured Bonn UBO2003 BTFs (thesis §5.3): an analytic,
//!   tileable height field of interlaced yarns, ray-marched per view with the images
//!   registered to the frontal view's plane (§5.3.3), and lit with cast shadows. It shows
//!   what a BTF adds to a texture — parallax and masking under oblique views, yarns
//!   shadowing each other under grazing light. [`WovenBtf::view`] traces one view,
//!   [`ViewHits::shade`] lights it; 81 × 81 images of 64² take a few seconds.
//! * [`WoolFins`] ([`fins`]): a procedural wool fin BTF, the stand-in for the grazing-view
//!   images of fuzzy cloth used for silhouette enhancement (thesis §5.7.2 "BTF fins",
//!   Tab. 5.3): a periodic layer of curved, tapering strands seen from the fixed view
//!   θ_V = 90° against black, lit from any direction with Kajiya–Kay diffuse reflection, a
//!   forward-scattering lobe and self-shadowing through the fibre cloud. Each
//!   [`FinImage`] is premultiplied RGB with the fibre coverage as alpha, falling off at the
//!   tips.
//! * [`LambertianBtf`]: a BTF without mesostructure (every image ρ · cos θ_l), the oracle of
//!   environment lighting — under a uniform sky with nothing in the way it reflects ρ L.
//!
//! No seed section specifies this crate, so no seed equation is implemented here; the
//! methods are cited in each module (Macklin et al. 2016/2019 for XPBD, Bergou et al. 2006
//! for bending, Kim et al. 2012 for tethers, Preetham et al. 1999 for the sky, the thesis's
//! §5.3 acquisition set-up for the BTF's sampling and registration, Kajiya & Kay 1989 and
//! the §5.7.2 set-up for the fins).
//!
//! # Examples
//! ```
//! use synth::{ClothParams, SkyParams};
//!
//! let params = ClothParams { grid: 16, frames: 10, ..Default::default() };
//! let anim = synth::simulate_cloth(&params)?;
//! assert_eq!((anim.frame_count(), anim.vertex_count()), (10, 256));
//! // The cloth falls: its mean height drops.
//! let mean_y = |f: &[glam::Vec3]| f.iter().map(|p| p.y).sum::<f32>() / f.len() as f32;
//! assert!(mean_y(&anim.frames[9]) < mean_y(&anim.frames[0]));
//!
//! let image = synth::sky(&SkyParams { width: 128, height: 64, ..Default::default() })?;
//! let brightest = image.texels.iter().map(|t| t[1]).fold(0.0f32, f32::max);
//! assert!(brightest > 100.0 * image.texel(0, 0)[1]); // the sun
//!
//! let btf = synth::WovenBtf::new(&synth::WovenBtfParams { res: 8, ..Default::default() })?;
//! let image = btf.view(glam::Vec3::Z)?.shade(glam::Vec3::Z); // frontal view and light
//! assert_eq!(image.len(), 8 * 8);
//! # Ok::<(), synth::SynthError>(())
//! ```

pub mod btf;
mod cloth;
mod error;
pub mod fins;
pub mod latlong;
mod rng;
mod sky;

pub use btf::{
    LambertianBtf, MAX_SUPERSAMPLE, MAX_WOVEN_SAMPLES, MAX_YARNS, MIN_VIEW_ELEVATION_DEG,
    SurfacePoint, ViewHits, WovenBtf, WovenBtfParams, Yarn,
};
pub use cloth::{
    ClothAnimation, ClothParams, MAX_GRID, MAX_OBSTACLE_DETAIL, MAX_POSITIONS,
    MAX_SELF_COLLISION_DISTANCE, MAX_SUBSTEPS, Obstacle, obstacle_mesh, simulate_cloth,
    simulate_cloth_with_progress,
};
pub use error::{Result, SynthError};
pub use fins::{
    FIN_VIEW_DIR, FinImage, MAX_FIN_SAMPLES, MAX_FIN_SEGMENTS, MAX_FIN_SIDE, MAX_FIN_SUPERSAMPLE,
    MAX_STRAND_COORD, MAX_STRAND_ROOT_RADIUS, MAX_STRAND_SEGMENTS, WoolFinParams, WoolFins,
    WoolStrand,
};
pub use latlong::LatLongImage;
pub use sky::{MAX_TEXELS, SkyParams, sky, sun_direction, sun_radiance};
