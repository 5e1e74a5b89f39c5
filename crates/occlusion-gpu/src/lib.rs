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
//! Feature `gpu` (default) builds the `Depth`, `Query` and `Rays` backends, M resident on the
//! GPU and the triangle-id pass of vertex filtering on wgpu; without it the crate is the exact CPU
//! engine (rays, fans, [`RayCaster`], vertex filtering with the CPU rasteriser, levels, rigid
//! look-ups) with no GPU stack to build.
//!
//! A deforming mesh keeps its BVH: when only positions change, the `cpu` and `rays` backends
//! refit the tree of the previous frame (O(N)) instead of building one (O(N log N)), and
//! rebuild once the refitted tree's SAH cost passes [`REBUILD_SAH_RATIO`] × its cost when
//! built; an unchanged scene (refinement, vertex filtering, an idle frame) reuses it as it is
//! ([`VisibilityEngine::last_bvh`] says which happened; M is the same either way). On the
//! full bunny the `rays` backend's host side then costs 0.2 ms reusing, 3.5 ms refitting (and
//! uploading) against 20–22 ms building.
//!
//! Backends ([`Backend`]):
//! * `Cpu` — exact ray casting, the accuracy reference: one shadow ray per (vertex,
//!   direction) with n·l > 0 from the vertex pushed 1e-4 × the bounding-box diagonal along its
//!   normal, multi-threaded with rayon. The rays of 64 neighbouring vertices towards one
//!   direction walk an `obvhs` binary BVH together as a packet, or each vertex's directions
//!   walk it as fans from its origin — fans from k = 258 up, where they are 1.2–1.6× faster
//!   ([`CpuMethod`]); see `benches/visibility.rs` for rays/s.
//! * `Depth` — the seed's future work (§8.1) on the GPU: orthographic Depth32Float maps per
//!   direction in batches of 2D-array layers, then a compute pass depth-tests every vertex with
//!   a slope-scaled bias (the counterpart of `glPolygonOffset(1, 1)`), writing visibility bits
//!   and accumulating a_i in storage buffers; only what is asked for is read back.
//! * `Query` — the published algorithm (§3.2, Figure 2): per direction the scene into an
//!   orthographic depth map, then every vertex drawn as a point (depth test LessEqual, no
//!   depth write) inside its own hardware occlusion query; a vertex with a sample passing is
//!   visible, M_ij = n_i·l_j. The bias of `glPolygonOffset(1, 1)` is applied in the vertex
//!   shader with the `Depth` backend's formula, so the two depth-map backends agree up to
//!   vertices whose biased depth lies within rounding of the stored depth (the rasteriser's
//!   depth of a point and the compute shader's clip z round differently): on lavapipe 0–18
//!   of the bunny's 34,834 used vertices and 0–63 of the cloth's 4,356 differ at
//!   512²–1024², levels 0–4 (`cargo xtask repro visibility`). Unlike the seed, whose §8.1
//!   names the per-query read-back as its drawback, the query results are resolved into a
//!   GPU buffer per batch of ≤ 4096-query sets and packed into the same bits and a_i buffers
//!   by a compute pass: no stall, no read-back per query. Slow by nature (N·k draws): the
//!   published baseline.
//! * `Rays` — the `cpu` backend's exact rays cast on the GPU: the BVH built on the CPU
//!   (`obvhs` PLOC, padded boxes), origins rounded as the CPU rounds them, and a compute
//!   shader that walks the tree per (vertex, word of 32 directions) with the CPU's
//!   Möller–Trumbore test and edge tolerance. No map, no bias, no resolution: M equals
//!   `cpu`'s up to rays within rounding of an edge or the tangent plane (the full bunny at
//!   k = 258: identical, M's hash; 2 grazing rays of the sphere over a plane's 285,606), and
//!   [`CpuParams::max_distance`] applies. The tree is kept between calls, as `cpu`'s is.
//!   For GPUs that rasterise slowly; not yet timed on one (lavapipe: 3.1 s for the bunny at
//!   k = 258, compute emulated on the CPU).
//!
//! Which backend is fastest depends on the machine. On an NVIDIA H100 (Vulkan, driver
//! 580.159.04, `cargo xtask bench visibility-gpu`, medians of 21 frames) the full bunny at
//! k = 1026 took 415 ms with `Depth` at 1024² (141 ms at 256², 821 ms at 2048²) and 157 ms
//! with `Cpu` on the same machine's 16 threads: a data-centre GPU rasterises on a small part
//! of its chip (0.4 ms per 1024² depth map of the bunny's 69k triangles), so there `Cpu` is
//! both exact and faster. `Depth` wins at small k (the bunny at k = 6: 4.3 against 24.7 ms)
//! and on dense meshes at moderate k (k = 258: the 100k-vertex dragon 127 against 257 ms,
//! igea 169 against 257 ms). GPUs built for raster were not measured, nor `Rays` on any
//! GPU (it was written after that loan ended).
//!
//! Every GPU backend can keep its result on the GPU:
//! [`VisibilityEngine::compute_resident`] returns a [`GpuVisibility`] whose bits and a_i
//! buffers a renderer binds directly — M stays on the GPU from frame to frame, and only what
//! is asked for is read back (§8.1).
//!
//! A single rigidly rotating object needs no recompute: [`RigidLighting`] looks the
//! environment up in the rotated light directions (§6).
//!
//! Callers that cast their own rays (the `hemicube` crate's exact maps, its point-light
//! tests) use [`RayCaster`] on the same prepared scene: one ray at a time
//! ([`RayCaster::occluded`]), or fans of up to 64 rays from one origin
//! ([`RayCaster::unoccluded_fan`], [`RayFan`]) that walk a binary BVH together with one SIMD
//! test per group of four lanes and a common-origin triangle test — the same answers, 3.4–4.1×
//! faster on a hemicube's pixels.
//!
//! Several objects with transforms occlude each other ([`Scene`], [`SceneObject`]); only
//! receiver objects get matrix rows, in object and vertex order. A vertex with a zero normal
//! (used by no triangle) has an all-zero row and a_i = c_i = NaN.
//!
//! Per-frame savings (paper 000 §4): *vertex filtering* ([`FilteredVisibility`],
//! [`VertexFilter`], §4.1) computes only the rows of vertices of triangles seen for the first
//! time ([`VisibilityEngine::compute_rows`]), found by a triangle-id pass from the camera
//! ([`TriangleIdRenderer`], or [`visible_triangles_cpu`] without an adapter); a deforming mesh
//! re-initialises the unseen list each frame (§6), so it computes exactly the vertices of the
//! visible triangles. The *adaptive level* ([`LevelController`], §4.2) picks the lightsphere
//! level per animated frame from a target frame time and refines one level at a time when idle.
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
mod depth_params;
mod engine;
mod error;
mod fan;
mod filter;
#[cfg(feature = "gpu")]
mod gpu;
mod level;
mod matrix;
mod progress;
mod rays;
mod refit;
mod rigid;
mod scene;

pub use cpu::{CpuMethod, CpuParams, DEFAULT_OFFSET_RELATIVE, FAN_MIN_COLUMNS};
pub use depth_params::{
    DEFAULT_BIAS_CONSTANT_TEXELS, DEFAULT_BIAS_SLOPE_TEXELS, DEFAULT_DEPTH_RESOLUTION,
    DEFAULT_MAX_ARRAY_BYTES, DEFAULT_MAX_SLOPE, DEFAULT_NORMAL_OFFSET_TEXELS, DepthParams,
};
pub use engine::{Backend, BvhStats, BvhUpdate, VisibilityEngine, VisibilityParams};
pub use error::OcclusionError;
pub use fan::{FAN_GROUP, FAN_SIZE, RayFan, fan_groups};
#[cfg(feature = "gpu")]
pub use filter::TriangleIdRenderer;
pub use filter::{
    Camera, DEFAULT_FILTER_THRESHOLD_FRACTION, FilterParams, FilterThreshold, FilteredVisibility,
    FrameStats, TriangleSet, TriangleVisibility, VertexFilter, triangle_rows,
    visible_triangles_cpu,
};
#[cfg(feature = "gpu")]
pub use gpu::GpuVisibility;
pub use level::{
    DEFAULT_MAX_IDLE_LEVEL, DEFAULT_MAX_LEVEL, DEFAULT_MIN_LEVEL, DEFAULT_RISE_AFTER_FRAMES,
    DEFAULT_RISE_FRACTION, LevelChange, LevelController, LevelParams,
};
pub use matrix::{VisibilityMatrix, clamp_ambient};
pub use progress::ProgressFn;
pub use rays::{RayCache, RayCaster};
pub use refit::REBUILD_SAH_RATIO;
pub use rigid::RigidLighting;
pub use scene::{MAX_ELEMENTS, Scene, SceneObject};
