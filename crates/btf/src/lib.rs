//! Bidirectional texture functions (BTFs) of cloth: the measured data model, per-view PCA
//! compression and CPU reconstruction of thesis §5.3–5.5.
//!
//! A BTF is the appearance of a flat material sample as a set of registered images
//! ("normtextures"), one per pair of view and light directions. The Bonn UBO2003 measurements
//! the thesis uses take 81 view × 81 light directions on one of two samplings of the
//! hemisphere (Table 5.1) — 6,561 images, 1230 MiB at 256² in 8-bit RGB. This crate
//!
//! * describes the samplings and interpolates between their directions ([`Sampling`]:
//!   Table 5.1; the bilinear light weights τ_m of eq. 5.3 and view weights ω_m of eq. 5.5);
//! * reads BTF folders in the UBO2003 naming ([`BtfDir`], validated from file names and image
//!   headers before any pixel is loaded) and writes them ([`write_btf_dir`]) — §5.3.3;
//! * compresses each view slot by PCA into a mean and c eigen-normtextures with weights
//!   ([`BtfPca::compress`], §5.4, eq. 5.1), streaming slot by slot with bounded memory, and
//!   stores them quantized in a validated `.btfpca` file ([`format`](mod@format));
//! * reconstructs on the CPU ([`reconstruct`]): the per-slot coefficients γ (eq. 5.3), the
//!   texel sum T_j = Σ_k γ_kj B_kj from B_0j, the mean (eq. 5.4), and view interpolation
//!   (eq. 5.5); and measures the error against the measurement ([`BtfPca::stats`]);
//! * renders a mesh textured by the compressed BTF under a point or directional light
//!   ([`render`]: per-vertex γ and ω, per-fragment texel sums blended over the triangle; a CPU
//!   reference and a wgpu renderer behind the default feature `gpu`) — §5.5;
//! * extracts the per-frame fin geometry of silhouette enhancement ([`fins`]: silhouette edges
//!   chained into loops, extruded along the vertex normals, the corrected texture coordinates
//!   of eqs. 5.16–5.21) — §5.7.3; and the fin BTF drawn on them ([`fin_pca`]: 81 grazing-view
//!   images under Table 5.3's lights, their PCA of eq. 5.14 in a validated `.finpca` file, the
//!   alpha of Listing 5.1) — §5.7.2.
//!
//! γ is computed apart from the texel sum so that environment illumination (γ*, §5.5.2) can
//! accumulate many light directions into it ([`BtfPca::accumulate_gamma`]); [`env`](mod@env) does so
//! for an environment seen through a per-vertex visibility matrix (eqs. 5.10–5.11, RGB γ*). Background: the
//! BTF as a set of textures or of apparent BRDFs and its compression by per-view
//! factorisation are surveyed in §2.1.10–2.1.12; [`compare`](mod@compare) sets per-view
//! factorisation beside full-matrix and per-cluster factorisation of the texels' ABRDFs
//! (Fig. 2.22) on one BTF held as 8-bit codes ([`AbrdfMatrix`]).
//!
//! Colour: images are handled as **linear** RGB. 8-bit and 16-bit PNG/JPEG files are decoded
//! through the sRGB transfer function, EXR is taken as linear, and the writer encodes 8-bit
//! sRGB. Errors in 8-bit units ([`ErrorStats`]) are measured after sRGB encoding, like the
//! thesis's difference images.
//!
//! ```
//! use btf::{BtfPca, BtfPcaParams, Sampling, ViewSlot};
//! use glam::Vec3;
//!
//! // An analytic 4 × 4 BTF: albedo per texel × max(l·n, 0), brighter for grazing views.
//! let s = Sampling::H1;
//! let load = |j: usize| {
//!     let view_gain = 1.0 + 0.2 * (1.0 - s.vector(j).z);
//!     let data = (0..81)
//!         .flat_map(|i| {
//!             let cos = s.vector(i).z.max(0.0);
//!             (0..16).flat_map(move |t| {
//!                 let albedo = 0.2 + 0.04 * t as f32;
//!                 [albedo, 0.5 * albedo, 0.25] .map(|a| a * cos * view_gain)
//!             })
//!         })
//!         .collect();
//!     ViewSlot::new(j, 4, 4, data)
//! };
//! let params = BtfPcaParams { components: 4, ..Default::default() };
//! let (pca, report) = BtfPca::compress_with(s, 4, 4, &params, load, None).unwrap();
//! assert!(report.min_components() >= 1);
//!
//! // Light straight above, front view: texel 0 is albedo 0.2 (no view gain).
//! let rgb = pca.eval(Vec3::Z, Vec3::Z, 0.0, 0.0);
//! assert!((rgb[0] - 0.2).abs() < 2e-3);
//! // γ for the same light in view slot 0, then the texel sum (eqs. 5.3–5.4).
//! let gamma = pca.gamma(0, Vec3::Z);
//! assert_eq!(pca.texel(0, &gamma, 0, 0), rgb);
//! ```

pub mod compare;
pub mod compress;
pub mod dataset;
pub mod env;
mod error;
pub mod fin_pca;
pub mod fins;
pub mod format;
mod io;
mod model;
pub mod reconstruct;
pub mod render;
pub mod sampling;
pub mod stats;

pub use compare::{AbrdfMatrix, TexelModel};
pub use compress::{BtfPcaParams, CompressReport, DEFAULT_COMPONENTS, MAX_COMPONENTS, SlotReport};
pub use dataset::{BtfDir, MAX_NORMTEXTURE_SIDE, ViewSlot, image_file_name, read_image};
pub use error::{BtfError, CodecError, Result};
pub use io::{
    linear_to_srgb, linear_to_srgb8, srgb_to_linear, write_btf_dir, write_btf_view, write_png_srgb8,
};
pub use model::{BtfPca, SlotPca, Storage, Texture};
pub use reconstruct::MAX_GAMMAS;
pub use sampling::{ANGLE_SNAP_DEG, DIRECTIONS, RINGS, Sampling, Weights4};
pub use stats::ErrorStats;
