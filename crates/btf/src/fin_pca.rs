//! The fin BTF of silhouette enhancement (thesis §5.7.2, "BTFF"): the images of a fuzzy
//! material seen at one fixed grazing view against black, their compression (eq. 5.14) in a
//! validated `.finpca` file, and the per-fragment evaluation of eq. 5.15 with the alpha of
//! Listing 5.1. The fin geometry the images are drawn on is [`crate::fins`].
//!
//! # The images and their folder
//! A fin BTF is 81 images of the material sample seen at **θ_V = 90°, φ_V = 0°** (the view
//! grazes the sample, so the fibres stand up in the image as they do at a silhouette) under the
//! 81 light directions of **Table 5.3** — the rings θ_L ∈ {0, 15, 30, 45, 60, 75}° with 1, 6,
//! 12, 18, 20 and 24 azimuths, i.e. the H2 directions of Table 5.1 ([`FIN_SAMPLING`]). The
//! background is black, so the colour is what the fibres add over black and alpha can be
//! extracted from it (§5.7.2). A folder holds one file per light in the UBO2003 naming with the
//! fixed view, `tl{θl:03} pl{φl:03} tv090 pv000.png` ([`fin_image_name`]; `_` may replace the
//! spaces; PNG, JPEG or EXR), read under the rules of [`crate::BtfDir`] (regular files, sizes
//! checked before decoding, 8-bit through the sRGB curve). A measured set named this way is
//! read the same way as the synthetic one `cloth-vis btf fins synth` writes.
//!
//! Image axes: a column runs along the fin's edge (texture coordinate s, wrapping, one image
//! width per material unit); row 0 is the fibre tips (t = 1), the last row the base (t = 0).
//! Light directions are in the **fin frame**: z = the surface normal, x = the direction towards
//! the viewer projected onto the tangent plane (the view is φ_V = 0), y = z × x ([`fin_frame`]).
//!
//! # Compression (eq. 5.14)
//! F_i ≈ B_0 + Σ_{k=1}^{c} p_ik B_k, i = 1…81: the PCA of the 81 images as vectors in
//! R^{3·h·w}. The equation as printed has no B_0, though the text calls the result an affine
//! subspace; the mean is kept here as the affine term (the centred data have rank ≤ 80, so
//! c = 80 — or any larger c asked, clamped — reconstructs every image to float rounding).
//! Default c = 16, the thesis's "around 16 additional textures". The file shares the
//! `.btfpca` layout ([`crate::format`](mod@crate::format)) with one slot instead of 81 and its
//! own signature ([`FIN_MAGIC`]), so it is validated by the same reader.
//!
//! # Evaluation (eq. 5.15, Listing 5.1)
//! F(l) ≈ g (γ_0 B_0 + Σ_k γ_k B_k) with γ_0 = Σ_m τ_m and γ_k = Σ_m τ_m p_{i_m k}, τ_m the
//! bilinear weights of the four measured directions around l (eq. 5.3's interpolation), g the
//! light's radiance. Alpha is r + g + b, set to 0 below the cut 0.04 that removes camera noise
//! ([`ALPHA_CUT`]); Listing 5.1 does not clamp it, [`fin_alpha`] clamps it to 1 so it stays a
//! coverage.
//!
//! ```
//! use btf::fin_pca::{FinPca, FIN_SAMPLING};
//! use btf::{BtfPcaParams, ViewSlot};
//!
//! // 81 analytic 4 × 2 images: fibre brightness ∝ cos θ_L, dimmer towards the tips.
//! let data: Vec<f32> = (0..81)
//!     .flat_map(|i| {
//!         let cos = FIN_SAMPLING.vector(i).z;
//!         (0..8).flat_map(move |t| [0.1 * (1 + t / 4) as f32 * cos; 3])
//!     })
//!     .collect();
//! let images = ViewSlot::new(0, 4, 2, data)?;
//! let fins = FinPca::from_images(&images, &BtfPcaParams::default())?;
//! let bytes = fins.to_bytes();
//! let back = FinPca::from_bytes(&bytes)?;
//! // Light straight above: image 0; the base row (t = 0) is twice the tip row.
//! let gamma = back.gamma(glam::Vec3::Z);
//! let base = back.texel(&gamma, 0, 1);
//! assert!((base[0] - 0.2).abs() < 2e-3);
//! # Ok::<(), btf::BtfError>(())
//! ```

use std::path::{Path, PathBuf};

use glam::Vec3;
use rayon::prelude::*;

use crate::compress::BtfPcaParams;
use crate::dataset::{ViewSlot, check_finite, check_sizes, scan};
use crate::error::{BtfError, Result};
use crate::format::{Kind, parse};
use crate::io::{decode_into, write_png_srgb8};
use crate::model::{BtfPca, SlotPca, Storage};
use crate::sampling::{DIRECTIONS, Sampling};

/// The light directions of Table 5.3: the H2 rings of Table 5.1.
pub const FIN_SAMPLING: Sampling = Sampling::H2;
/// The fixed view (θ_V, φ_V) in degrees (§5.7.2).
pub const FIN_VIEW_DEG: (u32, u32) = (90, 0);
/// Listing 5.1's `alpha_adjust`: alpha below it is set to 0.
pub const ALPHA_CUT: f32 = 0.04;
/// The `.finpca` signature.
pub const FIN_MAGIC: [u8; 8] = *b"\x89BTFFIN\n";

const FIN_KIND: Kind = Kind {
    magic: FIN_MAGIC,
    name: "not a .finpca file",
    slots: 1,
    slots_reason: "must be 1 (a fin BTF has one view)",
};

/// The file name of light `light` (0..81, Table 5.3 order): `tl{θ:03} pl{φ:03} tv090
/// pv000.{ext}`.
///
/// # Panics
/// If `light ≥ 81`.
///
/// ```
/// assert_eq!(btf::fin_pca::fin_image_name(7, "png"), "tl030 pl000 tv090 pv000.png");
/// ```
pub fn fin_image_name(light: usize, ext: &str) -> String {
    let (tl, pl) = FIN_SAMPLING.dir_deg_u32(light);
    let (tv, pv) = FIN_VIEW_DEG;
    format!("tl{tl:03} pl{pl:03} tv{tv:03} pv{pv:03}.{ext}")
}

/// Alpha of a fin colour (Listing 5.1): r + g + b, 0 below `cut`, at most 1.
pub fn fin_alpha(rgb: [f32; 3], cut: f32) -> f32 {
    let a = rgb[0] + rgb[1] + rgb[2];
    if a >= cut { a.min(1.0) } else { 0.0 }
}

/// The fin frame at a surface point: (x, y, z) with z = the unit normal, x = `to_eye`
/// projected onto the tangent plane (normalised), y = z × x. When `to_eye` is along the
/// normal (not a silhouette) x is any tangent. `None` for a zero or non-finite normal.
pub fn fin_frame(normal: Vec3, to_eye: Vec3) -> Option<[Vec3; 3]> {
    let z = normal.try_normalize()?;
    let x = (to_eye - z * to_eye.dot(z))
        .try_normalize()
        .unwrap_or_else(|| z.any_orthonormal_vector());
    Some([x, z.cross(x), z])
}

/// Writes a fin BTF folder: `image(light)` returns the `width × height` linear RGB texels of
/// light `light` (row-major, row 0 the tips), each written as an 8-bit sRGB PNG named by
/// [`fin_image_name`] (values clamped to [0, 1]), atomically, in parallel.
///
/// # Errors
/// [`BtfError::InvalidParameter`] for a zero size, [`BtfError::LengthMismatch`] if `image`
/// returns the wrong number of texels, [`BtfError::Io`] if the folder or a file cannot be
/// written.
pub fn write_fin_dir<F>(dir: &Path, width: usize, height: usize, image: F) -> Result<()>
where
    F: Fn(usize) -> Vec<[f32; 3]> + Sync,
{
    if width == 0 || height == 0 || width > u32::MAX as usize / 4 || height > u32::MAX as usize {
        return Err(BtfError::InvalidParameter {
            what: "write_fin_dir",
            name: "width × height",
            value: format!("{width} × {height}"),
            reason: "a fin image has at least one texel (and fits a PNG)",
        });
    }
    std::fs::create_dir_all(dir).map_err(|e| BtfError::io(dir, "create", e))?;
    (0..DIRECTIONS).into_par_iter().try_for_each(|light| {
        let texels = image(light);
        write_png_srgb8(
            &dir.join(fin_image_name(light, "png")),
            width,
            height,
            &texels,
        )
    })
}

/// A fin BTF folder whose 81 files have been found and validated (names, completeness,
/// sizes), with no pixel loaded yet.
#[derive(Clone, Debug)]
pub struct FinDir {
    root: PathBuf,
    width: usize,
    height: usize,
    files: Vec<PathBuf>,
}

impl FinDir {
    /// Scans `path` for the 81 images (see the [module docs](self)); reads headers only.
    ///
    /// # Errors
    /// [`BtfError::Io`] if the folder cannot be listed; [`BtfError::BadFileName`] for an image
    /// whose name does not parse; [`BtfError::FinDir`] for an image of another view, a light
    /// that is not a Table 5.3 direction, a duplicate or a missing light, or no image at all;
    /// [`BtfError::Codec`] / [`BtfError::SizeMismatch`] / [`BtfError::ImageTooLarge`] naming
    /// the first bad header.
    pub fn open(path: impl AsRef<Path>) -> Result<Self> {
        let root = path.as_ref().to_path_buf();
        let fail = |dir: &Path, problem: String| BtfError::FinDir {
            dir: dir.to_path_buf(),
            problem,
            example: fin_image_name(44, "png"),
        };
        let found = scan(&root)?;
        if found.is_empty() {
            return Err(fail(&root, "no fin image found".into()));
        }
        let mut files: Vec<Option<PathBuf>> = vec![None; DIRECTIONS];
        for f in found {
            let [tl, pl, tv, pv] = f.angles;
            if (tv, pv) != FIN_VIEW_DEG {
                return Err(fail(
                    &f.path,
                    format!("the view is (θ = {tv}°, φ = {pv}°), not the grazing (90°, 0°)"),
                ));
            }
            let light = FIN_SAMPLING.index_of(tl, pl).ok_or_else(|| {
                fail(
                    &f.path,
                    format!("light (θ = {tl}°, φ = {pl}°) is not a direction of Table 5.3"),
                )
            })?;
            if let Some(first) = &files[light] {
                return Err(fail(
                    &f.path,
                    format!("light {light} is already given by {}", first.display()),
                ));
            }
            files[light] = Some(f.path);
        }
        let missing = files.iter().filter(|f| f.is_none()).count();
        if let Some(first) = files.iter().position(Option::is_none) {
            return Err(BtfError::FinDir {
                dir: root,
                problem: format!("{missing} of the 81 light images are missing"),
                example: fin_image_name(first, "png"),
            });
        }
        let files: Vec<PathBuf> = files.into_iter().flatten().collect();
        let (width, height) = check_sizes(&files)?;
        Ok(Self {
            root,
            width,
            height,
            files,
        })
    }

    /// The folder.
    pub fn root(&self) -> &Path {
        &self.root
    }

    /// Image width (along the fin edge).
    pub fn width(&self) -> usize {
        self.width
    }

    /// Image height (base to tips).
    pub fn height(&self) -> usize {
        self.height
    }

    /// The file of light `light`, or `None` for `light ≥ 81`.
    pub fn file(&self, light: usize) -> Option<&Path> {
        self.files.get(light).map(PathBuf::as_path)
    }

    /// Loads the 81 images as linear RGB, decoding in parallel (memory 81 · 3 · w · h f32).
    ///
    /// # Errors
    /// [`BtfError::Io`] / [`BtfError::Codec`] naming a file that cannot be read or decoded;
    /// [`BtfError::SizeMismatch`] if a file changed size since [`FinDir::open`];
    /// [`BtfError::NonFinite`] for NaN/∞ in an EXR.
    pub fn load(&self) -> Result<ViewSlot> {
        let len = 3 * self.width * self.height;
        let mut data = vec![0.0f32; DIRECTIONS * len];
        data.par_chunks_mut(len)
            .zip(&self.files)
            .try_for_each(|(out, path)| {
                decode_into(path, self.width, self.height, out)?;
                check_finite(out, || path.display().to_string())
            })?;
        ViewSlot::new(0, self.width, self.height, data)
    }
}

/// A compressed fin BTF (eq. 5.14 with the mean): one [`SlotPca`] over the 81 lights of
/// Table 5.3.
#[derive(Clone, Debug, PartialEq)]
pub struct FinPca {
    /// A [`BtfPca`] with a single slot (sampling H2): the reconstruction code is shared.
    pca: BtfPca,
}

impl FinPca {
    /// Compresses a fin folder (`params.components` c, default 16; `parallel_slots` unused).
    ///
    /// # Errors
    /// As [`FinDir::load`] and [`FinPca::from_images`].
    pub fn compress(dir: &FinDir, params: &BtfPcaParams) -> Result<Self> {
        Self::from_images(&dir.load()?, params)
    }

    /// Compresses 81 images given as a [`ViewSlot`] (image i = light i of Table 5.3).
    ///
    /// # Errors
    /// [`BtfError::InvalidParameter`] for c = 0; [`BtfError::Pca`] if the decomposition fails.
    pub fn from_images(images: &ViewSlot, params: &BtfPcaParams) -> Result<Self> {
        if params.components == 0 {
            return Err(BtfError::InvalidParameter {
                what: "FinPca::from_images",
                name: "components",
                value: "0".into(),
                reason: "keep at least one eigen-image",
            });
        }
        let slot = SlotPca::fit(
            images,
            params.components,
            params.storage,
            params.mean_storage,
        )?;
        Ok(Self {
            pca: BtfPca {
                sampling: FIN_SAMPLING,
                width: images.width(),
                height: images.height(),
                requested_components: params.components,
                storage: params.storage,
                mean_storage: params.mean_storage,
                slots: vec![slot],
            },
        })
    }

    /// Image width (along the fin edge).
    pub fn width(&self) -> usize {
        self.pca.width
    }

    /// Image height (base to tips).
    pub fn height(&self) -> usize {
        self.pca.height
    }

    /// The component count asked for.
    pub fn requested_components(&self) -> usize {
        self.pca.requested_components
    }

    /// Storage of the eigen-images.
    pub fn storage(&self) -> Storage {
        self.pca.storage
    }

    /// The PCA: mean, eigen-images B_k, weights p_ik and eigenvalues.
    pub fn slot(&self) -> &SlotPca {
        &self.pca.slots[0]
    }

    /// The number of γ coefficients: c + 1.
    pub fn gamma_len(&self) -> usize {
        self.pca.gamma_len(0)
    }

    /// γ_0 … γ_c for a light direction in the fin frame (all zero at or below the horizon).
    pub fn gamma(&self, light_dir_in_fin_frame: Vec3) -> Vec<f32> {
        self.pca.gamma(0, light_dir_in_fin_frame)
    }

    /// γ_0 B_0 + Σ_k γ_k B_k at texel (x, y) (no light radiance g).
    ///
    /// # Panics
    /// If `gamma.len() ≠ c + 1` or the texel is outside the image.
    pub fn texel(&self, gamma: &[f32], x: usize, y: usize) -> [f32; 3] {
        self.pca.texel(0, gamma, x, y)
    }

    /// The texel at fin texture coordinates (s, t): s wraps once per image width, t = 1 is
    /// row 0 (the tips) and t = 0 the last row (the base), clamped.
    pub fn texel_of(&self, s: f32, t: f32) -> (usize, usize) {
        let (w, h) = (self.pca.width, self.pca.height);
        let x = ((s - s.floor()) * w as f32) as usize;
        let y = ((1.0 - t) * h as f32).floor();
        let y = if y.is_finite() {
            y.clamp(0.0, (h - 1) as f32)
        } else {
            0.0
        };
        (x.min(w - 1), y as usize)
    }

    /// The reconstruction of image `light` (row-major linear RGB).
    ///
    /// # Panics
    /// If `light ≥ 81`.
    pub fn image(&self, light: usize) -> Vec<[f32; 3]> {
        self.pca.image(0, light)
    }

    /// The reconstruction error against the images it was compressed from (8-bit sRGB units,
    /// PSNR), over all 81.
    ///
    /// # Errors
    /// [`BtfError::LengthMismatch`] for images of another size.
    pub fn stats(&self, images: &ViewSlot) -> Result<crate::ErrorStats> {
        self.pca.stats_slot(images)
    }

    /// Serialises to the `.finpca` layout (the `.btfpca` layout with one slot).
    pub fn to_bytes(&self) -> Vec<u8> {
        self.pca.to_bytes_with(&FIN_MAGIC)
    }

    /// Parses and validates `.finpca` bytes.
    ///
    /// # Errors
    /// [`BtfError::FinFormat`] naming the first invalid field; never panics on any input.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self> {
        parse_fin(bytes, Path::new("<bytes>"))
    }

    /// Writes a `.finpca` file atomically (temporary file + rename).
    ///
    /// # Errors
    /// [`BtfError::Io`] if it cannot be written (then `path` is untouched).
    pub fn write(&self, path: &Path) -> Result<()> {
        atomic_out::write_bytes(path, &self.to_bytes())?;
        Ok(())
    }

    /// Reads and validates a `.finpca` file (regular files only).
    ///
    /// # Errors
    /// [`BtfError::Io`] if it cannot be read, [`BtfError::FinFormat`] naming the file and the
    /// first invalid field.
    pub fn read(path: &Path) -> Result<Self> {
        let bytes = input_guard::read_regular(path).map_err(|e| BtfError::io(path, "read", e))?;
        parse_fin(&bytes, path)
    }
}

fn parse_fin(bytes: &[u8], path: &Path) -> Result<FinPca> {
    let pca = parse(bytes, path, &FIN_KIND).map_err(|e| match e {
        BtfError::Format {
            path,
            field,
            value,
            reason,
        } => BtfError::FinFormat {
            path,
            field,
            value,
            reason,
        },
        other => other,
    })?;
    if pca.sampling != FIN_SAMPLING {
        return Err(BtfError::FinFormat {
            path: path.to_path_buf(),
            field: "sampling",
            value: pca.sampling.name().into(),
            reason: "a fin BTF uses the directions of Table 5.3 (H2)",
        });
    }
    Ok(FinPca { pca })
}
