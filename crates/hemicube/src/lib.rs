//! Static self-shadowing from per-vertex visibility maps (thesis §4.3, "Self-shadowing of
//! static meshes"; SEED-NOTES §1).
//!
//! Each vertex gets a binary map of the directions above its tangent plane from which the
//! environment is seen (§4.3.3): rendered once from the vertex with the normal as view direction,
//! then used at runtime to weight environment radiance by the pixels' delta form factors,
//! eq. 4.7 (ΔFF = G/π · ΔA), so that the vertex radiance is
//!
//! > L_o(v) = ρ · Σ_p V_p · ΔF_p · L_env(dir_p)   (eqs. 4.4–4.7 for a Lambertian vertex)
//!
//! and point lights are looked up in the map (T 6002–6005).
//!
//! * [`layout`]: the three models of §4.3.4 — hemicube (HC), single plane (SP), hemisphere grid
//!   (HS) — with every pixel's direction, exact ΔF (contour integral, f64; the seed's midpoint
//!   formulas as [`FormFactorRule::Midpoint`]) and exact solid angle.
//! * [`VisibilityMaps`]: 1 bit per pixel plus a quaternion frame per vertex (HC 64²: 1,552 bytes
//!   per vertex against the seed's 36 KiB of 24-bit RGB), 1 = open.
//! * Builders: exact rays through `occlusion-gpu`'s BVH ([`build_with_rays`], every model, the
//!   accuracy reference; with the seed's distance preselection as an option) and the GPU atlas
//!   ([`GpuBuilder`], HC and SP: many vertices per instanced draw, clip distances per tile).
//! * [`lighting`]: environment radiance through a power-conserving cube map (the seed's) or
//!   exact per-pixel look-ups, rotation without rebuilding maps, point lights by map or by ray.
//! * [`MeasuredChannel`]: per pixel the four nearest of the 81 measured BTF directions and
//!   their bilinear weights (§5.5.2, Fig. 5.12); [`BtfLightChannel`] the light side of it, which
//!   bins an environment onto a BTF's 81 light directions per vertex (eq. 5.10) for BTF
//!   rendering under environment light (`btf::env`).
//!
//! # Example
//! ```
//! use std::sync::Arc;
//! use glam::Vec3;
//! use hemicube::{BuildParams, FormFactorRule, Model, PixelLayout, build_with_rays};
//! use occlusion_gpu::Scene;
//!
//! // A unit square facing +y: nothing occludes, every vertex sees the whole hemisphere.
//! let positions = vec![
//!     Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0),
//!     Vec3::new(1.0, 0.0, 1.0), Vec3::new(0.0, 0.0, 1.0),
//! ];
//! let scene = Scene::single(positions, vec![Vec3::Y; 4], vec![[0, 2, 1], [0, 3, 2]])?;
//! let layout = Arc::new(PixelLayout::new(Model::Hemicube { res: 16 }, FormFactorRule::Exact)?);
//! let (maps, _) = build_with_rays(&scene, layout, &BuildParams::default())?;
//! for open in maps.open_fraction() {
//!     assert!((open - 1.0).abs() < 1e-5); // exact ΔF sum to 1 over the hemicube
//! }
//! assert_eq!(maps.bytes_per_vertex(), 12 * 8 + 16); // 768 bits + the frame
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod error;
mod gpu;
pub mod layout;
pub mod lighting;
mod maps;
mod measured;
mod rays;

pub use error::HemicubeError;
pub use gpu::{GpuBuilder, MAX_ATLAS_SIDE};
pub use layout::{
    DEFAULT_APERTURE_DEG, Face, FormFactorRule, MAX_HEMISPHERE_BINS, MAX_RESOLUTION, Model,
    PixelLayout, RingSpacing,
};
pub use lighting::{CubeMap, EnvLookup, PointLight, PointLighting, PointVisibility};
pub use maps::{VertexFrame, VisibilityMaps};
pub use measured::{BtfLightChannel, MeasuredChannel};
pub use rays::{
    BuildParams, BuildStats, build_with_caster, build_with_frames, build_with_progress,
    build_with_rays,
};
