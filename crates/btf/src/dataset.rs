//! A measured BTF as a folder of normtextures (thesis §5.3.3), and one view slot of it in
//! memory (§5.4: "the n normtextures N_ij, i ∈ 1…n per view slot j").
//!
//! **File names** follow the Bonn UBO2003 archives: one image per (light, view) pair named
//!
//! ```text
//! tl{θl:03} pl{φl:03} tv{θv:03} pv{φv:03}.{png|jpg|jpeg|exr}      e.g. "tl017 pl060 tv000 pv000.jpg"
//! ```
//!
//! with integer degrees. Accepted variations: `_` instead of a space, 1–3 digits per angle,
//! upper- or lower-case letters and extension, and any prefix before the four fields when it
//! is separated from them by a space or `_` (`CORDUROY tl000 pl000 tv000 pv000.jpg`). Files
//! whose names start with `.` (hidden and temporary files), sub-folders and files with other
//! extensions are ignored; a file with an image extension whose name does not match is an
//! error ([`BtfError::BadFileName`]), so a typo never silently drops an image.
//!
//! [`BtfDir::open`] decides the sampling (H1 or H2) from the θ values, checks that each of the
//! 81 × 81 pairs is present exactly once and that every image has the same size — reading only
//! the image headers — before any pixel buffer is allocated.

use std::path::{Path, PathBuf};

use rayon::prelude::*;

use crate::error::{BtfError, Result};
use crate::io::{decode_into, kind_of, read_dimensions};
use crate::sampling::{DIRECTIONS, Sampling};

/// The largest normtexture side accepted from an image header (resource policy, ARCHITECTURE.md).
/// A view slot holds 81 · 3 · w · h f32, 1.0 GB at 1024²; measured BTFs are 256² or smaller
/// (the thesis's UBO2003 samples), and a larger one should be cropped into tiles first.
pub const MAX_NORMTEXTURE_SIDE: usize = 1024;

/// Deflate, the compression of PNG, cannot shrink data by more than 1032:1; a header that
/// claims more raw bytes than that times the file size (plus the header's own bytes) describes
/// pixels the file cannot hold.
const DEFLATE_MAX_RATIO: u64 = 1032;

/// Refuses an image size beyond [`MAX_NORMTEXTURE_SIDE`], or a PNG whose claimed pixels its
/// bytes cannot hold, before anything of that size is allocated.
fn check_image_size(path: &Path, width: usize, height: usize) -> Result<()> {
    let too_large = |reason: String| BtfError::ImageTooLarge {
        path: path.to_path_buf(),
        width,
        height,
        reason,
    };
    if width > MAX_NORMTEXTURE_SIDE || height > MAX_NORMTEXTURE_SIDE {
        return Err(too_large(format!(
            "each side may be at most {MAX_NORMTEXTURE_SIDE} (btf::MAX_NORMTEXTURE_SIDE); crop \
             a larger BTF into tiles"
        )));
    }
    let is_png = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if is_png {
        let file_bytes = std::fs::metadata(path)
            .map_err(|e| BtfError::io(path, "stat", e))?
            .len();
        // At least one byte per pixel (8-bit grey), one filter byte per row.
        let raw = (width as u64 + 1) * height as u64;
        if raw > DEFLATE_MAX_RATIO * file_bytes + 4096 {
            return Err(too_large(format!(
                "the file has {file_bytes} bytes, and deflate cannot compress {raw} bytes of \
                 pixels into so few; the header is corrupt"
            )));
        }
    }
    Ok(())
}

/// Reads one normtexture file (PNG, JPEG or EXR) as linear RGB under the same rules as
/// [`BtfDir::open`] and [`BtfDir::load_view`]: regular files only, the header's size checked
/// against [`MAX_NORMTEXTURE_SIDE`] (and, for PNG, against what the file's bytes can hold)
/// before anything of that size is allocated, 8- and 16-bit values through the sRGB transfer
/// function, NaN/∞ refused. Returns width, height and 3·w·h floats, row-major.
///
/// # Errors
/// [`BtfError::Io`], [`BtfError::Codec`], [`BtfError::ImageTooLarge`],
/// [`BtfError::NonFinite`], each naming the file.
pub fn read_image(path: &Path) -> Result<(usize, usize, Vec<f32>)> {
    let (width, height) = read_dimensions(path)?;
    if width == 0 || height == 0 {
        return Err(BtfError::codec(
            path,
            "read the header of",
            "the image is empty",
        ));
    }
    check_image_size(path, width, height)?;
    let mut out = vec![0.0f32; 3 * width * height];
    decode_into(path, width, height, &mut out)?;
    check_finite(&out, || path.display().to_string())?;
    Ok((width, height, out))
}

/// Number of (view, light) pairs: 81 × 81 = 6,561 images.
pub(crate) const fn pair_count() -> usize {
    DIRECTIONS * DIRECTIONS
}

/// The UBO2003 file name of (view slot `view`, light `light`) with extension `ext`:
/// `tl{θl:03} pl{φl:03} tv{θv:03} pv{φv:03}.{ext}`.
///
/// # Panics
/// If `view` or `light` ≥ 81.
///
/// # Examples
/// ```
/// assert_eq!(btf::image_file_name(btf::Sampling::H1, 0, 2, "png"), "tl017 pl060 tv000 pv000.png");
/// ```
pub fn image_file_name(sampling: Sampling, view: usize, light: usize, ext: &str) -> String {
    let (tl, pl) = sampling.dir_deg_u32(light);
    let (tv, pv) = sampling.dir_deg_u32(view);
    format!("tl{tl:03} pl{pl:03} tv{tv:03} pv{pv:03}.{ext}")
}

/// The four angles of a file name: (θl, φl, θv, φv) in degrees.
pub(crate) type Angles = [u32; 4];

/// Parses a UBO2003 file stem; `Err(reason)` when it does not match.
fn parse_stem(stem: &str) -> std::result::Result<Angles, &'static str> {
    let fields: Vec<&str> = stem.split([' ', '_']).filter(|f| !f.is_empty()).collect();
    if fields.len() < 4 {
        return Err("fewer than four fields tl…, pl…, tv…, pv…");
    }
    let tail = &fields[fields.len() - 4..];
    let mut out = [0u32; 4];
    for ((field, key), o) in tail.iter().zip(["tl", "pl", "tv", "pv"]).zip(&mut out) {
        if field.len() < 3 || !field.is_char_boundary(2) || !field[..2].eq_ignore_ascii_case(key) {
            return Err("the last four fields must be tl…, pl…, tv…, pv… in this order");
        }
        let digits = &field[2..];
        if digits.is_empty() || digits.len() > 3 || !digits.bytes().all(|b| b.is_ascii_digit()) {
            return Err("each angle must be 1–3 decimal digits of integer degrees");
        }
        *o = digits.parse().map_err(|_| "angle is not a number")?;
    }
    Ok(out)
}

/// A BTF folder whose 6,561 files have been found and validated (names, completeness, sizes),
/// with no pixel loaded yet.
#[derive(Clone, Debug)]
pub struct BtfDir {
    root: PathBuf,
    sampling: Sampling,
    width: usize,
    height: usize,
    /// `files[view * 81 + light]`.
    files: Vec<PathBuf>,
}

/// A parsed candidate file.
pub(crate) struct Found {
    pub path: PathBuf,
    /// (θl, φl, θv, φv) in degrees.
    pub angles: Angles,
}

impl BtfDir {
    /// Scans `path` for UBO2003 image names, decides the sampling, and validates the folder
    /// (see the [module docs](crate::dataset) for the accepted names). Reads image headers
    /// only.
    ///
    /// # Errors
    /// [`BtfError::Io`] if the folder cannot be listed; [`BtfError::BadFileName`] for an image
    /// file whose name does not parse; [`BtfError::UnknownSampling`] for a θ in neither
    /// sampling or folders that mix both; [`BtfError::NotADirection`] for a φ not on the
    /// ring's grid; [`BtfError::DuplicateImage`] / [`BtfError::MissingImage`] unless every
    /// pair is present exactly once; [`BtfError::EmptyDir`] without any image;
    /// [`BtfError::Codec`] for an unreadable header; [`BtfError::SizeMismatch`] naming the
    /// first image whose size differs from view 0, light 0.
    pub fn open(path: impl AsRef<Path>) -> Result<Self> {
        let root = path.as_ref().to_path_buf();
        let found = scan(&root)?;
        if found.is_empty() {
            return Err(BtfError::EmptyDir { dir: root });
        }
        let sampling = decide_sampling(&found)?;
        let mut table: Vec<Option<usize>> = vec![None; pair_count()];
        for (n, f) in found.iter().enumerate() {
            let [tl, pl, tv, pv] = f.angles;
            let index = |role, t, p| {
                sampling
                    .index_of(t, p)
                    .ok_or_else(|| BtfError::NotADirection {
                        path: f.path.clone(),
                        role,
                        theta: t,
                        phi: p,
                        sampling: sampling.name(),
                    })
            };
            let light = index("light", tl, pl)?;
            let view = index("view", tv, pv)?;
            let slot = &mut table[view * DIRECTIONS + light];
            if let Some(first) = *slot {
                return Err(BtfError::DuplicateImage {
                    first: found[first].path.clone(),
                    second: f.path.clone(),
                    view,
                    light,
                });
            }
            *slot = Some(n);
        }
        let missing = table.iter().filter(|s| s.is_none()).count();
        if let Some(first) = table.iter().position(Option::is_none) {
            let ext = found[0]
                .path
                .extension()
                .and_then(|e| e.to_str())
                .unwrap_or("png");
            let (view, light) = (first / DIRECTIONS, first % DIRECTIONS);
            return Err(BtfError::MissingImage {
                dir: root,
                expected: image_file_name(sampling, view, light, ext),
                view,
                light,
                missing,
            });
        }
        let mut found: Vec<Option<Found>> = found.into_iter().map(Some).collect();
        let files: Vec<PathBuf> = table
            .iter()
            .map(|s| {
                let f = s.and_then(|n| found[n].take());
                f.map(|f| f.path).unwrap_or_default()
            })
            .collect();
        let (width, height) = check_sizes(&files)?;
        Ok(Self {
            root,
            sampling,
            width,
            height,
            files,
        })
    }

    /// The folder.
    pub fn root(&self) -> &Path {
        &self.root
    }

    /// The sampling found (H1 or H2).
    pub fn sampling(&self) -> Sampling {
        self.sampling
    }

    /// Normtexture width w in texels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Normtexture height h in texels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// The file of (view slot `view`, light `light`).
    ///
    /// # Errors
    /// [`BtfError::IndexOutOfRange`] for an index ≥ 81.
    pub fn file(&self, view: usize, light: usize) -> Result<&Path> {
        check_index("view slot", view)?;
        check_index("light", light)?;
        Ok(&self.files[view * DIRECTIONS + light])
    }

    /// Loads the 81 light images of view slot `view` as linear RGB (8- and 16-bit images
    /// through the sRGB transfer function, EXR as stored), decoding in parallel.
    /// Memory: 81 · 3 · w · h f32 (64 MB at 256²).
    ///
    /// # Errors
    /// [`BtfError::IndexOutOfRange`] for `view ≥ 81`; [`BtfError::Io`] / [`BtfError::Codec`]
    /// naming a file that cannot be read or decoded; [`BtfError::SizeMismatch`] if a file
    /// changed size since [`BtfDir::open`]; [`BtfError::NonFinite`] for NaN/∞ in an EXR.
    pub fn load_view(&self, view: usize) -> Result<ViewSlot> {
        check_index("view slot", view)?;
        let len = 3 * self.width * self.height;
        let mut data = vec![0.0f32; DIRECTIONS * len];
        data.par_chunks_mut(len)
            .enumerate()
            .try_for_each(|(light, out)| {
                let path = &self.files[view * DIRECTIONS + light];
                decode_into(path, self.width, self.height, out)?;
                check_finite(out, || path.display().to_string())
            })?;
        Ok(ViewSlot {
            view,
            width: self.width,
            height: self.height,
            data,
        })
    }

    /// Loads one image as 3·w·h linear RGB floats (row-major, RGB interleaved).
    ///
    /// # Errors
    /// As [`BtfDir::load_view`].
    pub fn load_image(&self, view: usize, light: usize) -> Result<Vec<f32>> {
        let path = self.file(view, light)?;
        let mut out = vec![0.0f32; 3 * self.width * self.height];
        decode_into(path, self.width, self.height, &mut out)?;
        check_finite(&out, || path.display().to_string())?;
        Ok(out)
    }
}

fn check_index(what: &'static str, index: usize) -> Result<()> {
    if index >= DIRECTIONS {
        return Err(BtfError::IndexOutOfRange {
            what,
            index,
            len: DIRECTIONS,
        });
    }
    Ok(())
}

pub(crate) fn check_finite(values: &[f32], what: impl Fn() -> String) -> Result<()> {
    match values.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(BtfError::NonFinite {
            what: what(),
            index,
            value: values[index],
        }),
        None => Ok(()),
    }
}

/// Lists the folder; parses every image name. Sorted by file name so errors are deterministic.
pub(crate) fn scan(root: &Path) -> Result<Vec<Found>> {
    let entries = std::fs::read_dir(root).map_err(|e| BtfError::io(root, "list", e))?;
    let mut found = Vec::new();
    for entry in entries {
        let entry = entry.map_err(|e| BtfError::io(root, "list", e))?;
        let path = entry.path();
        let name = entry.file_name();
        let Some(name) = name.to_str() else { continue };
        if name.starts_with('.') {
            continue;
        }
        let Some((stem, ext)) = name.rsplit_once('.') else {
            continue;
        };
        if kind_of(ext).is_none() {
            continue;
        }
        let is_dir = entry
            .file_type()
            .map_err(|e| BtfError::io(&path, "stat", e))?
            .is_dir();
        if is_dir {
            continue;
        }
        let angles = parse_stem(stem).map_err(|reason| BtfError::BadFileName {
            path: path.clone(),
            reason,
        })?;
        found.push(Found { path, angles });
    }
    found.sort_by(|a, b| a.path.cmp(&b.path));
    Ok(found)
}

/// H1 or H2 from the θ values of the names (θ = 0 is in both).
fn decide_sampling(found: &[Found]) -> Result<Sampling> {
    let h1 = Sampling::H1.ring_thetas();
    let h2 = Sampling::H2.ring_thetas();
    let mut first: [Option<&Path>; 2] = [None, None];
    for f in found {
        let [tl, _, tv, _] = f.angles;
        for (role, theta) in [("light", tl), ("view", tv)] {
            if theta == 0 {
                continue;
            }
            let which = if h1.contains(&theta) {
                0
            } else if h2.contains(&theta) {
                1
            } else {
                return Err(BtfError::UnknownSampling {
                    path: f.path.clone(),
                    role,
                    theta,
                    reason: "not a ring of H1 or H2",
                });
            };
            if first[which].is_none() {
                first[which] = Some(&f.path);
                // Both samplings seen: this file introduced the second one.
                if first[1 - which].is_some() {
                    return Err(BtfError::UnknownSampling {
                        path: f.path.clone(),
                        role,
                        theta,
                        reason: if which == 0 {
                            "this θ is an H1 ring, but other files use H2 rings"
                        } else {
                            "this θ is an H2 ring, but other files use H1 rings"
                        },
                    });
                }
            }
        }
    }
    Ok(if first[1].is_some() {
        Sampling::H2
    } else {
        Sampling::H1
    })
}

/// Reads every header (in parallel) and checks all sizes against the first file's.
pub(crate) fn check_sizes(files: &[PathBuf]) -> Result<(usize, usize)> {
    let sizes: Vec<Result<(usize, usize)>> = files.par_iter().map(|p| read_dimensions(p)).collect();
    let mut reference: Option<(usize, usize)> = None;
    for (path, size) in files.iter().zip(sizes) {
        let (w, h) = size?;
        check_image_size(path, w, h)?;
        match reference {
            None => {
                if w == 0 || h == 0 {
                    return Err(BtfError::codec(
                        path,
                        "read the header of",
                        "the image is empty",
                    ));
                }
                reference = Some((w, h));
            }
            Some((rw, rh)) if (rw, rh) != (w, h) => {
                return Err(BtfError::SizeMismatch {
                    path: path.clone(),
                    reference: files[0].clone(),
                    expected_w: rw,
                    expected_h: rh,
                    found_w: w,
                    found_h: h,
                });
            }
            Some(_) => {}
        }
    }
    Ok(reference.unwrap_or((0, 0)))
}

/// The 81 normtextures of one view slot S_j as linear RGB (thesis §5.4): image i is the
/// vector X_ij = (r₁₁, g₁₁, b₁₁, …, r_hw, g_hw, b_hw) of dimension 3·h·w.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewSlot {
    view: usize,
    width: usize,
    height: usize,
    /// 81 × 3wh, light-major.
    data: Vec<f32>,
}

impl ViewSlot {
    /// A view slot from 81 · 3 · `width` · `height` linear RGB floats, light-major (image of
    /// light 0 first), each image row-major with RGB interleaved.
    ///
    /// # Errors
    /// [`BtfError::IndexOutOfRange`] for `view ≥ 81`, [`BtfError::InvalidParameter`] for an
    /// empty size, [`BtfError::LengthMismatch`] for a wrong length, [`BtfError::NonFinite`] for
    /// NaN/∞.
    pub fn new(view: usize, width: usize, height: usize, data: Vec<f32>) -> Result<Self> {
        check_index("view slot", view)?;
        if width == 0 || height == 0 {
            return Err(BtfError::InvalidParameter {
                what: "ViewSlot::new",
                name: "width × height",
                value: format!("{width} × {height}"),
                reason: "a normtexture has at least one texel",
            });
        }
        let expected = DIRECTIONS
            .checked_mul(3 * width)
            .and_then(|n| n.checked_mul(height));
        if expected != Some(data.len()) {
            return Err(BtfError::LengthMismatch {
                what: "ViewSlot::new data",
                expected: expected.unwrap_or(usize::MAX),
                found: data.len(),
                hint: "pass 81 images of width · height RGB texels, light-major",
            });
        }
        check_finite(&data, || format!("view slot {view} data"))?;
        Ok(Self {
            view,
            width,
            height,
            data,
        })
    }

    /// The view slot index j.
    pub fn view(&self) -> usize {
        self.view
    }

    /// Width in texels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in texels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// The normtexture of light `light` (3·w·h floats).
    ///
    /// # Panics
    /// If `light ≥ 81`.
    pub fn image(&self, light: usize) -> &[f32] {
        let len = 3 * self.width * self.height;
        &self.data[light * len..(light + 1) * len]
    }

    /// All 81 images, light-major (the 81 × 3wh data matrix of the slot's PCA).
    pub fn data(&self) -> &[f32] {
        &self.data
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_parse() {
        assert_eq!(parse_stem("tl017 pl060 tv000 pv000"), Ok([17, 60, 0, 0]));
        assert_eq!(parse_stem("tl017_pl060_tv085_pv345"), Ok([17, 60, 85, 345]));
        assert_eq!(parse_stem("CORDUROY TL17 PL60 tv0 pv0"), Ok([17, 60, 0, 0]));
        assert!(parse_stem("tl017 pl060 tv000").is_err());
        assert!(parse_stem("pl060 tl017 tv000 pv000").is_err());
        assert!(parse_stem("tl0170 pl060 tv000 pv000").is_err());
        assert!(parse_stem("tl01x pl060 tv000 pv000").is_err());
        assert!(parse_stem("tlé pl060 tv000 pv000").is_err());
    }
}
