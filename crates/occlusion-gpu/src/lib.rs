//! The visibility-matrix query engine for deforming meshes under HDR light (paper 000 =
//! thesis §4.4, "Hardware-accelerated ambient occlusion computation").
//!
//! For N receiver vertices and the k directions l_j of a [`lightsphere::Lightsphere`] it
//! computes the *visibility matrix* (§3.2)
//!
//! > M_ij = n_i·l_j when vertex i is unoccluded towards l_j (and n_i·l_j > 0), else 0,
//!
//! from which the vertex radiance c_i = Σ_j M_ij I_j (§3.3) and the ambient term
//! a_i = (1/π) Σ_j ω_j M_ij (ω_j the lightsphere's solid angles; 1 = fully open) follow. No
//! precomputation: a deforming mesh recomputes M per frame, and a finer lightsphere level
//! reuses the columns already computed ([`VisibilityEngine::refine`], §3.4, §4.2).
//!
//! Backends ([`Backend`]):
//! * `Cpu` — exact ray casting, the accuracy reference: one shadow ray per (vertex,
//!   direction) with n·l > 0 from the vertex pushed 1e-4 × the bounding-box diagonal along its
//!   normal, any-hit traversal of `obvhs`'s compressed 8-wide BVH, multi-threaded with rayon.
//!   `obvhs` was chosen over `bvh` 0.13 for its early-exit shadow-ray traversal
//!   (`ray_traverse_miss`) over 8-wide compressed nodes (`bvh` collects candidates per ray
//!   over a binary tree); see `benches/visibility.rs` for rays/s.
//! * `Depth` — the seed's future work (§8.1) on the GPU: orthographic Depth32Float maps per
//!   direction in batches of 2D-array layers, then a compute pass depth-tests every vertex with
//!   a slope-scaled bias (the counterpart of `glPolygonOffset(1, 1)`), writing visibility bits
//!   and accumulating a_i in storage buffers; only what is asked for is read back.
//!
//! The published `query` backend (one hardware occlusion query per vertex) is not
//! implemented yet.
//!
//! Several objects with transforms occlude each other ([`Scene`], [`SceneObject`]); only
//! receiver objects get matrix rows, in object and vertex order. A vertex with a zero normal
//! (used by no triangle) has an all-zero row and a_i = c_i = NaN.
//!
//! # Examples
//! ```
//! use glam::Vec3;
//! use lightsphere::Lightsphere;
//! use occlusion_gpu::{Scene, VisibilityEngine, VisibilityParams};
//!
//! // A unit square in the xz plane facing +y: nothing occludes its vertices.
//! let positions = vec![
//!     Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0),
//!     Vec3::new(1.0, 0.0, 1.0), Vec3::new(0.0, 0.0, 1.0),
//! ];
//! let scene = Scene::single(positions, vec![Vec3::Y; 4], vec![[0, 2, 1], [0, 3, 2]])?;
//! let sphere = Lightsphere::new(2)?;
//! let mut engine = VisibilityEngine::cpu(VisibilityParams::default());
//! let matrix = engine.compute(&scene, &sphere)?;
//! let ambient = matrix.ambient();
//! assert!(ambient.iter().all(|a| (a - 1.0).abs() < 0.05)); // open: ≈ 1 up to quadrature
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod cpu;
mod engine;
mod error;
mod gpu;
mod matrix;
mod scene;

pub use cpu::{CpuParams, DEFAULT_OFFSET_RELATIVE};
pub use engine::{Backend, VisibilityEngine, VisibilityParams};
pub use error::OcclusionError;
pub use gpu::{
    DEFAULT_BIAS_CONSTANT_TEXELS, DEFAULT_BIAS_SLOPE_TEXELS, DEFAULT_DEPTH_RESOLUTION,
    DEFAULT_MAX_ARRAY_BYTES, DEFAULT_MAX_SLOPE, DEFAULT_NORMAL_OFFSET_TEXELS, DepthParams,
};
pub use matrix::VisibilityMatrix;
pub use scene::{MAX_ELEMENTS, Scene, SceneObject};
