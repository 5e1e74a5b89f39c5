//! Rendering a triangle mesh textured by a compressed BTF under one point or directional light
//! (thesis §5.5, eqs. 5.2–5.5), on the CPU ([`render_cpu`]) and with wgpu
//! ([`GpuBtfRenderer`], feature `gpu`), headless, into a [`RenderedImage`].
//!
//! Fins (§5.7.3) are lit here too: [`fin_gammas`] takes γ at both ends of every fin of a
//! [`FinMesh`](crate::fins::FinMesh), [`fin_fragment`] is the CPU reference of Listing 5.1,
//! and [`GpuFinRenderer`] draws them into the shared frame in two order-independent passes
//! (see its module for why they differ from Fig. 5.22 as printed).
//!
//! # What the thesis does, and what is computed where
//!
//! §5.5 reconstructs "the texture T for a vertex V of a given triangle mesh": **per vertex**,
//! the view and light directions are taken into the vertex's tangent frame (tangent,
//! bitangent, normal); the four nearest view slots j_m with weights ω_m (eq. 5.5,
//! [`Sampling::view_weights`](crate::Sampling::view_weights)) and, for each slot, the
//! coefficients γ_kj = Σ_m τ_m p_{i_m k j} of the light (eq. 5.3 with the bilinear light
//! weights τ_m, [`BtfPca::gamma_from_weights`](crate::BtfPca::gamma_from_weights)) are
//! computed on the CPU ([`render_cpu`] and [`GpuBtfRenderer::render`] share this code).
//!
//! **Per fragment**, the texture of each of the triangle's three vertices is evaluated at the
//! fragment's texture coordinates,
//! T_v(uv) = Σ_m ω_m Σ_k γ_{k j_m} B_{k j_m}(uv) (eqs. 5.4–5.5, k = 0 is the mean B_0j), and
//! the three are blended with the fragment's barycentric weights: "when blending the three
//! resulting textures per triangle, a smooth transition is ensured as in [Chen et al. 2002]"
//! (the vertex-centred, hat-function blending of light field mapping). The result is
//! multiplied by the light's RGB radiance g (eq. 5.4). Across an edge only the edge's two
//! vertices contribute, so the image is continuous across triangles.
//!
//! # Conventions and choices
//!
//! * **Texture lookup:** the nearest texel with wrap-around, exactly as
//!   [`BtfPca::eval`](crate::BtfPca::eval) and
//!   [`BtfPca::nearest_texel`](crate::BtfPca::nearest_texel) (no bilinear filtering, on either
//!   side), at uv · [`RenderParams::uv_scale`] (a scale > 1 tiles the BTF sample over the
//!   mesh).
//! * **Tangent frames** are glTF-style [`Vec4`](glam::Vec4)s: xyz the tangent (∂P/∂u), w = ±1 the
//!   handedness, bitangent = w · (normal × tangent), pointing along increasing v (down the
//!   stored rows of the normtextures). The BTF's local +x (φ = 0) is the tangent, +y (φ = 90°)
//!   the bitangent, +z the normal. [`tangent_frames`] computes them from UVs.
//! * **Lights:** [`Light::Directional`] or [`Light::Point`]. A point light has **no distance
//!   falloff**: eq. 5.4 multiplies by the light's radiance g as given, so both lights are
//!   "g at the surface" and only the direction differs per vertex (scale g yourself for a
//!   1/d² look). A light at or below a vertex's horizon gives that vertex black (the
//!   normtextures contain the cosine falloff, see [`crate::sampling`]). There are no shadows.
//! * **Both faces** are drawn (no culling); on a back face the view is clamped to the last
//!   ring of the sampling and the light is usually below the horizon (black).
//! * **Camera:** [`Camera`], a perspective pinhole: `clip_from_world` =
//!   `perspective(fov_y, width/height, near, far) · look_at(eye, target, up)` (glam's
//!   right-handed camera, wgpu's clip space with depth 0..1), pixel centres at (x + ½, y + ½),
//!   top row first. Both paths apply the same f32 matrix; the CPU rasterises with homogeneous
//!   edge functions (no clipping needed), perspective-correct barycentrics and a depth test
//!   (`Less`, `Depth32Float` on the GPU), like the GPU.
//! * **Colour:** [`RenderedImage`] holds linear RGB (the BTF's units times g) and a coverage
//!   mask; [`RenderedImage::to_srgb8`] and [`RenderedImage::write_png`] tone map by clamping
//!   to [0, 1] and sRGB encoding.
//!
//! # Limits (GPU)
//!
//! All textures B_kj of all slots are uploaded once into one 3-D `Rgba{8,16,32}Uint` texture
//! (the widest of the BTF's storages, dequantized in the shader with the per-texture
//! (lo, step) exactly like the CPU), laid out as Σ_j (c_j + 1) layers of w × h, tiled in x and
//! y when the layers exceed `max_texture_dimension_3d` (2048 by default). Per-vertex data
//! (4 slots, 4 ω, 4·(c + 1) γ) goes into a storage buffer bounded by
//! `max_storage_buffer_binding_size` (128 MiB by default: about 440 000 vertices at c = 16).
//! Exceeding a limit is a [`BtfError::GpuLimit`](crate::BtfError::GpuLimit) naming it.
//!
//! # Examples
//! ```
//! use btf::render::{BtfMesh, Camera, Light, RenderParams, render_cpu, tangent_frames};
//! use btf::{BtfPca, BtfPcaParams, Sampling, ViewSlot};
//! use glam::{Vec2, Vec3};
//!
//! // A 2 × 2 BTF: albedo 0.5 · max(l·n, 0) at every texel, for every view.
//! let s = Sampling::H1;
//! let load = |j| {
//!     let data = (0..81).flat_map(|i| [0.5 * s.vector(i).z.max(0.0); 12]).collect();
//!     ViewSlot::new(j, 2, 2, data)
//! };
//! let (pca, _) = BtfPca::compress_with(s, 2, 2, &BtfPcaParams::default(), load, None)?;
//!
//! // A unit quad in the xy plane, facing +z.
//! let positions = [Vec3::new(-1., -1., 0.), Vec3::new(1., -1., 0.), Vec3::new(1., 1., 0.), Vec3::new(-1., 1., 0.)];
//! let normals = [Vec3::Z; 4];
//! let uvs = [Vec2::new(0., 1.), Vec2::new(1., 1.), Vec2::new(1., 0.), Vec2::new(0., 0.)];
//! let triangles = [[0, 1, 2], [0, 2, 3]];
//! let tangents = tangent_frames(&positions, &normals, &uvs, &triangles)?;
//! let mesh = BtfMesh { positions: &positions, normals: &normals, tangents: &tangents, uvs: &uvs, triangles: &triangles };
//!
//! let camera = Camera::look_at(Vec3::new(0., 0., 4.), Vec3::ZERO, Vec3::Y, 45.0, 32, 32);
//! let light = Light::Directional { dir_to_light_world: Vec3::Z, radiance: Vec3::ONE };
//! let image = render_cpu(&pca, &mesh, &light, &camera, &RenderParams::default())?;
//! let centre = image.pixel(16, 16);
//! assert!(image.covered(16, 16) && (centre[0] - 0.5).abs() < 1e-2);
//! assert!(!image.covered(0, 0));
//! # Ok::<(), btf::BtfError>(())
//! ```

mod cpu;
mod fin_shade;
#[cfg(feature = "gpu")]
mod fins_gpu;
#[cfg(feature = "gpu")]
mod gpu;
mod image;
mod mesh;
mod shade;
mod tangent;

pub use cpu::{render_cpu, render_cpu_env};
pub use fin_shade::{FinShading, fin_fragment, fin_gammas};
#[cfg(feature = "gpu")]
pub use fins_gpu::{FinDraw, GpuFinRenderer};
#[cfg(feature = "gpu")]
pub use gpu::{BtfDraw, GpuBtfRenderer};
pub use image::RenderedImage;
pub use mesh::{BtfMesh, Camera, Light, RenderParams};
pub use tangent::tangent_frames;
