//! The linear basis decompositions of thesis §2.1.12 side by side (Fig. 2.22): full-matrix
//! factorization (FMF, eq. 2.20), per-cluster factorization (PCMF, eq. 2.22, Müller et al.
//! 2003) and per-view factorization (PVMF, eq. 2.21, Sattler et al. 2003 — this crate's
//! [`BtfPca`], §5.4) on one BTF, each with its memory, its error over all 6,561 images and its
//! time.
//!
//! # The data
//! [`AbrdfMatrix`] holds the BTF **once, as 8-bit sRGB codes** — the storage of a UBO2003
//! measurement (§5.3.3), 81 · 81 · 3 bytes per texel: 322 MB at 128², 1.29 GB at 256² (the
//! thesis's "1230 megabytes"). Rows are texels, each row the texel's apparent BRDF (ABRDF):
//! 81 views × 81 lights × RGB = [`ABRDF_LEN`] = 19,683 codes, laid out as [`abrdf_index`].
//! FMF and PCMF read it by rows, PVMF by view slots ([`AbrdfMatrix::view_slot`] decodes one
//! slot, 81 images, to linear f32). The decoded codes are the reference of every error.
//!
//! # The methods
//! * **FMF** ([`TexelModel::fmf`]): one PCA of the n × 19,683 matrix of all ABRDFs (rows =
//!   texels, mean ABRDF subtracted): BTF(x, v, l) ≈ ḡ(v, l) + Σ_k g_k(x) h_k(v, l). The PCA
//!   takes `clustering`'s `Auto` path: at 128² (n = 16,384, d = 19,683, neither side 4× the
//!   other) that is **randomized subspace iteration** (c + 10 columns, row blocks converted to
//!   f64 on the fly), because the Gram matrix (n² f64 = 2.1 GB, an O(n³) eigensolver) and the
//!   covariance (d² f64 = 3.1 GB) do not fit the time or the memory; at 16² (n = 256) it is the
//!   exact Gram path. The PCA reads an f32 matrix in memory, so the fit decodes the codes to
//!   f32 for its duration: 1.29 GB at 128² beside the 322 MB of codes.
//! * **PCMF** ([`TexelModel::pcmf`]): Kambhatla–Leen local PCA ([`clustering::LocalPca`]) of
//!   the ABRDFs into k clusters of c terms: BTF(x, v, l) ≈ ḡ_k(x)(v, l) + Σ_j g_j(x)
//!   h_{k(x),j}(v, l). *Deviation, for memory and time:* the local PCA runs on a fixed random
//!   subset of [`PcmfParams::fit_texels`] texels (it works on an f64 copy: 645 MB for 4,096
//!   ABRDFs instead of 2.6 GB for all 16,384), then every texel is assigned to the cluster of
//!   least reconstruction error and each cluster's mean and c axes are refitted on all its
//!   texels (one Lloyd step on the whole BTF, the same PCA as FMF's per cluster). With one
//!   cluster PCMF is FMF.
//! * **PVMF** ([`pvmf`]): [`BtfPca::compress_with`], one PCA per view slot over the 81 light
//!   images (§5.4, eq. 5.1), loading the slots from the codes.
//!
//! # Memory of a representation
//! Counted as stored, without headers: every texture (a mean or basis vector) at its storage
//! plus its 8-byte (lo, hi) range, the weights as f32, and for PCMF one cluster id per texel
//! (1 byte for k ≤ 256). FMF and PCMF store the mean and basis ABRDFs, PVMF the mean and
//! eigen-normtextures ([`BtfPca::payload_bytes`]). [`Compared::bytes_f32`] gives the same data
//! with every texture in f32, for a comparison at equal precision. The thesis's Fig. 2.22 uses
//! 16 bits for PCMF and 8 bits for the others ([`PcmfParams::default`], [`FmfParams::default`]).
//!
//! # Error
//! [`ErrorStats`] over all 6,561 images, in 8-bit sRGB units like [`BtfPca::stats`]: the
//! original's sRGB value is its code / 255 exactly; the reconstruction (linear) is encoded by
//! a 65,537-entry table with linear interpolation, within 10⁻⁴ codes of the exact transfer
//! function (the exact `powf` would cost most of the evaluation's time).
//!
//! Errors of a texel PCA are returned as [`BtfError::Pca`](crate::BtfError::Pca) with `view` = 81, i.e. no view slot.

mod matrix;
mod measure;
mod texel;

pub use matrix::AbrdfMatrix;
pub use texel::{DEFAULT_FIT_TEXELS, FmfParams, PcmfParams, TexelModel};

use std::time::Instant;

use crate::compress::{BtfPcaParams, CompressReport, for_each_slot_bounded, resolve_workers};
use crate::error::Result;
use crate::model::{BtfPca, Storage};
use crate::sampling::DIRECTIONS;
use crate::stats::ErrorStats;
use matrix::check_size;
use measure::Acc;

/// Values of one texel's ABRDF: 81 views × 81 lights × RGB.
pub const ABRDF_LEN: usize = DIRECTIONS * DIRECTIONS * 3;

/// Codes of one view slot within an ABRDF row (81 lights × RGB).
pub(crate) const SLOT_LEN: usize = DIRECTIONS * 3;

/// Where (view slot, light, channel) sits in an ABRDF row: `(view · 81 + light) · 3 + channel`.
///
/// # Panics
/// If `view` or `light` ≥ 81 or `channel` ≥ 3.
pub fn abrdf_index(view: usize, light: usize, channel: usize) -> usize {
    assert!(view < DIRECTIONS && light < DIRECTIONS && channel < 3);
    (view * DIRECTIONS + light) * 3 + channel
}

/// The decomposition families of Fig. 2.22 compared here.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Method {
    /// Full-matrix factorization: one PCA of all ABRDFs (eq. 2.20).
    Fmf,
    /// Per-cluster factorization: local PCA of the ABRDFs (eq. 2.22, Müller et al. 2003).
    Pcmf,
    /// Per-view factorization: one PCA per view slot (eq. 2.21, §5.4; [`BtfPca`]).
    Pvmf,
}

impl Method {
    /// "FMF", "PCMF" or "PVMF".
    pub fn name(self) -> &'static str {
        match self {
            Self::Fmf => "FMF",
            Self::Pcmf => "PCMF",
            Self::Pvmf => "PVMF",
        }
    }
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Bytes per cluster id for k clusters: 0 for one cluster, else 1, 2 or 4.
pub fn label_bytes(clusters: usize) -> usize {
    match clusters {
        0 | 1 => 0,
        2..=256 => 1,
        257..=65536 => 2,
        _ => 4,
    }
}

/// Bytes of a texel model (the formula, see the [module docs](self)): for each cluster k its
/// mean at `mean_storage` and `cluster_terms[k]` basis ABRDFs at `storage`, each with an
/// 8-byte range; n × max(c_k) f32 weights; n cluster ids.
pub fn texel_model_bytes(
    texels: usize,
    cluster_terms: &[usize],
    storage: Storage,
    mean_storage: Storage,
) -> usize {
    let stride = cluster_terms.iter().copied().max().unwrap_or(0);
    let textures: usize = cluster_terms
        .iter()
        .map(|&c| ABRDF_LEN * (mean_storage.bytes() + c * storage.bytes()) + 8 * (c + 1))
        .sum();
    textures + 4 * texels * stride + texels * label_bytes(cluster_terms.len())
}

/// Bytes of a per-view factorization (the formula): per slot j the mean normtexture at
/// `mean_storage` and c_j eigen-normtextures at `storage` (3wh values each, with an 8-byte
/// range), 81 × c_j f32 weights and r_j f32 eigenvalues. Equals [`BtfPca::payload_bytes`];
/// the `.btfpca` file adds 692 bytes of header, slot table and checksum.
///
/// # Panics
/// If `components` and `ranks` differ in length.
pub fn pvmf_bytes(
    width: usize,
    height: usize,
    components: &[usize],
    ranks: &[usize],
    storage: Storage,
    mean_storage: Storage,
) -> usize {
    assert_eq!(components.len(), ranks.len(), "one rank per slot");
    let values = 3 * width * height;
    components
        .iter()
        .zip(ranks)
        .map(|(&c, &r)| {
            values * (mean_storage.bytes() + c * storage.bytes())
                + 8 * (c + 1)
                + 4 * (DIRECTIONS * c + r)
        })
        .sum()
}

/// Header, slot table and checksum of a `.btfpca` file (its length minus the payload).
pub const BTFPCA_OVERHEAD: usize = 40 + DIRECTIONS * 8 + 4;

/// Per-view factorization (eq. 2.21, §5.4): [`BtfPca::compress_with`] on the view slots of
/// `btf`.
///
/// # Errors
/// As [`BtfPca::compress_with`].
pub fn pvmf(btf: &AbrdfMatrix, params: &BtfPcaParams) -> Result<(BtfPca, CompressReport)> {
    BtfPca::compress_with(
        btf.sampling(),
        btf.width(),
        btf.height(),
        params,
        |j| btf.view_slot(j),
        None,
    )
}

/// Error of a per-view factorization against `btf` over all 6,561 images, measured like
/// [`TexelModel::stats`] (so the three methods are compared by one yardstick).
///
/// # Errors
/// [`BtfError::LengthMismatch`](crate::BtfError::LengthMismatch) if `btf` has another size.
pub fn pvmf_stats(pca: &BtfPca, btf: &AbrdfMatrix) -> Result<ErrorStats> {
    check_size(btf, pca.width(), pca.height())?;
    let n = btf.texels();
    let accs = for_each_slot_bounded(resolve_workers(0), DIRECTIONS, |j| {
        let mut slot = vec![0u8; n * SLOT_LEN];
        for (t, run) in slot.chunks_exact_mut(SLOT_LEN).enumerate() {
            run.copy_from_slice(&btf.abrdf(t)[j * SLOT_LEN..(j + 1) * SLOT_LEN]);
        }
        let mut acc = Acc::default();
        let mut original = vec![0u8; 3 * n];
        for i in 0..DIRECTIONS {
            for (o, run) in original
                .chunks_exact_mut(3)
                .zip(slot.chunks_exact(SLOT_LEN))
            {
                o.copy_from_slice(&run[3 * i..3 * i + 3]);
            }
            let image = pca.image(j, i);
            acc.add(&original, image.as_flattened());
        }
        Ok(acc)
    })?;
    Ok(accs
        .into_iter()
        .fold(Acc::default(), Acc::merge)
        .finish(DIRECTIONS * DIRECTIONS))
}

/// What one method is asked to do in [`compare`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MethodParams {
    /// Full-matrix factorization.
    Fmf(FmfParams),
    /// Per-cluster factorization.
    Pcmf(PcmfParams),
    /// Per-view factorization.
    Pvmf(BtfPcaParams),
}

/// A fitted representation of one of the three families.
#[derive(Clone, Debug, PartialEq)]
pub enum Reconstruction {
    /// FMF or PCMF.
    Texel(TexelModel),
    /// PVMF.
    PerView(BtfPca),
}

impl Reconstruction {
    /// The family.
    pub fn method(&self) -> Method {
        match self {
            Self::Texel(m) => m.method(),
            Self::PerView(_) => Method::Pvmf,
        }
    }

    /// Bytes at the storage the representation uses (see the [module docs](self)).
    pub fn bytes(&self) -> usize {
        match self {
            Self::Texel(m) => m.bytes(),
            Self::PerView(p) => p.payload_bytes(),
        }
    }

    /// Bytes with every texture in f32.
    pub fn bytes_f32(&self) -> usize {
        match self {
            Self::Texel(m) => m.bytes_f32(),
            Self::PerView(p) => {
                let comps: Vec<usize> = p.slots().iter().map(|s| s.components()).collect();
                let ranks: Vec<usize> = p.slots().iter().map(|s| s.rank()).collect();
                pvmf_bytes(
                    p.width(),
                    p.height(),
                    &comps,
                    &ranks,
                    Storage::F32,
                    Storage::F32,
                )
            }
        }
    }

    /// The reconstructed normtexture of (view slot, light), linear RGB, row-major.
    ///
    /// # Panics
    /// If `view` or `light` ≥ 81.
    pub fn image(&self, view: usize, light: usize) -> Vec<[f32; 3]> {
        match self {
            Self::Texel(m) => m.image(view, light),
            Self::PerView(p) => p.image(view, light),
        }
    }

    /// Error against `btf` over all 6,561 images.
    ///
    /// # Errors
    /// [`BtfError::LengthMismatch`](crate::BtfError::LengthMismatch) if `btf` has another size.
    pub fn stats(&self, btf: &AbrdfMatrix) -> Result<ErrorStats> {
        match self {
            Self::Texel(m) => m.stats(btf),
            Self::PerView(p) => pvmf_stats(p, btf),
        }
    }
}

/// One row of the comparison table: the representation, its memory, error and times.
#[derive(Clone, Debug, PartialEq)]
pub struct Compared {
    /// The fitted representation.
    pub reconstruction: Reconstruction,
    /// The terms c asked for.
    pub terms: usize,
    /// Clusters (1 for FMF, k for PCMF, 81 view slots for PVMF).
    pub clusters: usize,
    /// [`Reconstruction::bytes`].
    pub bytes: usize,
    /// [`Reconstruction::bytes_f32`].
    pub bytes_f32: usize,
    /// Error over all 6,561 images.
    pub stats: ErrorStats,
    /// Wall-clock seconds of the fit (including decoding the codes it reads).
    pub fit_seconds: f64,
    /// Wall-clock seconds of the error evaluation.
    pub stats_seconds: f64,
}

/// Fits one method to `btf` and measures it.
///
/// # Errors
/// Whatever the method's fit returns.
///
/// # Examples
/// ```
/// use btf::compare::{AbrdfMatrix, FmfParams, Method, MethodParams, PcmfParams, compare};
/// use btf::{BtfPcaParams, Sampling, Storage, ViewSlot};
///
/// // A 2 × 2 BTF: per-texel albedo × the light's cosine, brighter at grazing views.
/// let s = Sampling::H1;
/// let load = |j: usize| {
///     let gain = 1.0 + 0.3 * (1.0 - s.vector(j).z);
///     let data = (0..81)
///         .flat_map(|i| {
///             let cos = s.vector(i).z.max(0.0);
///             (0..4).flat_map(move |t| [0.2, 0.1, 0.05].map(|a| a * (1.0 + t as f32) * cos * gain))
///         })
///         .collect();
///     ViewSlot::new(j, 2, 2, data)
/// };
/// let btf = AbrdfMatrix::from_slots(s, 2, 2, load, None).unwrap();
/// let f32s = Storage::F32;
/// for params in [
///     MethodParams::Fmf(FmfParams::new(3, f32s)),
///     MethodParams::Pcmf(PcmfParams::new(2, 1, f32s)),
///     MethodParams::Pvmf(BtfPcaParams { components: 3, storage: f32s, mean_storage: f32s, ..Default::default() }),
/// ] {
///     let row = compare(&btf, &params).unwrap();
///     assert_eq!(row.stats.images, 6561);
///     // The BTF has rank 1 up to its 8-bit rounding: every method reproduces it.
///     assert!(row.stats.rms_srgb8 < 0.5, "{}: {:?}", row.reconstruction.method(), row.stats);
///     if row.reconstruction.method() == Method::Fmf {
///         // Four texels: the mean and three terms span them exactly.
///         assert!(row.stats.rms_srgb8 < 1e-2);
///     }
/// }
/// ```
pub fn compare(btf: &AbrdfMatrix, params: &MethodParams) -> Result<Compared> {
    let t0 = Instant::now();
    let (reconstruction, terms) = match params {
        MethodParams::Fmf(p) => (Reconstruction::Texel(TexelModel::fmf(btf, p)?), p.terms),
        MethodParams::Pcmf(p) => (Reconstruction::Texel(TexelModel::pcmf(btf, p)?), p.terms),
        MethodParams::Pvmf(p) => (Reconstruction::PerView(pvmf(btf, p)?.0), p.components),
    };
    let fit_seconds = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let stats = reconstruction.stats(btf)?;
    let clusters = match &reconstruction {
        Reconstruction::Texel(m) => m.clusters(),
        Reconstruction::PerView(_) => DIRECTIONS,
    };
    Ok(Compared {
        terms,
        clusters,
        bytes: reconstruction.bytes(),
        bytes_f32: reconstruction.bytes_f32(),
        stats,
        fit_seconds,
        stats_seconds: t1.elapsed().as_secs_f64(),
        reconstruction,
    })
}
