//! A procedural wool fin BTF: the synthetic stand-in for the grazing-view images of a
//! fuzzy material that the thesis uses for silhouette enhancement of fuzzy cloth (§5.7.2
//! "BTF fins", Tab. 5.3), so that the fin pipeline can be tested and demonstrated without
//! photographs of wool.
//!
//! # What is rendered
//! The thesis photographs a wool sample from a fixed grazing view (θ_V = 90°, φ_V = 0°)
//! against a black background under 81 light directions; the images' alpha falls off
//! towards the fibre tips. Here a layer of curved, tapering strands stands on a base plane
//! (`strands.rs`); for the fixed view, [`WoolFins::new`] finds once, for every sub-sample
//! of every pixel, the nearest fibre point (`view.rs`) and builds a density grid of the
//! fibre cloud (`shadow.rs`); [`WoolFins::image`] then lights those points from one
//! directional light, with Kajiya–Kay diffuse reflection, a forward-scattering lobe and
//! self-shadowing through the cloud. 81 calls give the 81 images of Tab. 5.3.
//!
//! # Conventions
//! * Tangent frame: z = the sample's normal (the fibres rise along +z from the base at
//!   z = 0), x = towards the viewer ([`FIN_VIEW_DIR`] = +x is the view θ_V = 90°,
//!   φ_V = 0°), y = z × x, so (x, y, z) is right-handed. A direction
//!   d(θ, φ) = (sin θ cos φ, sin θ sin φ, cos θ) points away from the sample (towards the
//!   light); φ_L = 0° lights the fibres from the viewer's side, φ_L = 180° from behind.
//! * Orthographic camera looking along −x; lengths are in material units, one unit being
//!   the image's width. Column i covers y ∈ [i, i+1)/width; the image is **periodic in y**
//!   with period 1 (a fibre crossing y = 1 reappears at y = 0), so it tiles seamlessly
//!   along the fin's edge. Pixels are square: the image covers z ∈ [0, height/width]. Row
//!   0 is the top (the tips), the last row touches the base z = 0; what lies below the
//!   base is not in the image. Images are row-major, top row first.
//! * Sub-sample (a, b) of `n × n` (a along y, b downwards) of pixel (column i, row r)
//!   sits at y = (i·n + a + ½)/(width·n), z = (height·n − r·n − b − ½)/(width·n); its ray
//!   comes from x = +∞ along −x.
//!
//! # Fibre layer
//! `strands` strands are rooted at (x, y, 0) with x uniform in [−depth, 0] and y uniform
//! in [0, 1). Each is a polyline of `segments` equal segments whose direction at arc
//! fraction u is `normalize(a + c·(cos(2πfu + γ), sin(2πfu + γ), 0))`: a tilted axis a
//! (tilt uniform in [0, `max_tilt_deg`], azimuth uniform) plus a gentle curl (amplitude c
//! uniform in [0, `curl`], f uniform in [0.5, 1.5] turns, phase γ uniform), so strands
//! always rise. Lengths are uniform in [`length_min`, `length_max`] × the image height.
//! The radius falls linearly with arc length from `root_radius_px` pixel widths at the
//! root to 0 at the tip: coverage, hence alpha, falls off towards the tips. Each strand's
//! colour is `colour` × (1 + `colour_variation`·r), r uniform in [−1, 1), clamped to
//! [0, 1]. Everything is drawn from one SplitMix64 stream seeded with `seed`.
//! [`WoolFins::from_strands`] accepts any other set of [`WoolStrand`]s instead.
//!
//! # Rendering
//! The view is fixed, so the nearest hit of each sub-sample is computed once: every
//! segment is a capsule whose radius tapers linearly along it, rasterised in the yz-plane
//! (a sub-sample is covered when its distance to the projected axis is below the radius
//! there; its depth is the axis's x plus the height of the fibre's front surface,
//! √(r² − dist²)); the covering segment with the largest depth wins. Pixel colour is the
//! mean over its sub-samples of their radiance (0 for a sub-sample that sees only the black
//! background) and alpha the fraction of sub-samples that see a fibre: the colour is
//! premultiplied over black, which is what a camera in front of a black background
//! records.
//!
//! # Reflectance model
//! A fibre point with unit tangent t, lit from unit direction l and seen from v = +x, has
//! the radiance (linear RGB)
//!
//! ```text
//! L = E · T(p, l) · ρ ⊙ ( k_d · √(1 − (t·l)²) + k_f · max(−l·v, 0)^p )
//! ```
//!
//! the Kajiya–Kay (1989) diffuse term plus a forward-scattering lobe that is brightest when
//! the light is behind the fibres as the viewer sees them (−l·v = 1, i.e. φ_L = 180° at
//! grazing θ_L). The lobe is not energy-normalised: its peak is 1 for any exponent p, so
//! k_f alone sets how bright back-lit wool gets. E is the light's irradiance at normal
//! incidence divided by π; as for the woven BTF ([`WovenBtf`](crate::WovenBtf)) the light
//! has irradiance π, so E = 1 and an unshadowed fibre lit perpendicular to its axis has
//! radiance k_d·ρ, as a white Lambertian surface facing the light would have radiance 1.
//! Every channel of a pixel is ≤ alpha · max ρ · (k_d + k_f) (≤ 0.864 with the defaults);
//! nothing is clamped. A light at or below the horizon (`l.z ≤ 0`), or a direction that
//! is not finite or has zero length, gives black colour with the coverage alpha.
//!
//! # Self-shadowing
//! T(p, l) ∈ [0, 1] is the transmittance from p towards the light through the fibre
//! cloud, `exp(−σ ∫ κ ds)`. The extinction κ is a grid (cells of about two pixel widths,
//! at most 128 per axis, periodic in y) into which every segment splats its mean projected
//! area 2r·ds·π/4 (the mean of sin over isotropic directions); so with σ = 1 the fibres
//! are as opaque to the light as they look to the camera, and σ < 1 stands for wool's
//! translucency. A blurred fibre would shadow itself along its own length; to avoid that,
//! strands are dealt into 4 groups by index and a point of group g is shadowed only by the
//! other three, scaled by 4/3 (an unbiased estimate of the cloud without its own strand).
//! The march steps one cell from p until the ray leaves the grid (at most 4096 steps). T
//! is evaluated once per pixel and strand, at the mean position of the sub-samples that
//! strand covers in the pixel: under cells of two pixels it hardly changes within a pixel,
//! and sharing the march makes an image 1.5 times faster.
//! The base plane z = 0 would block light arriving from below it, but every light this
//! shades has `l.z > 0`, and p lies above the base, so no such light reaches p.
//!
//! # Deviations
//! Real wool has crimped, scaly, translucent fibres with light scattering inside them,
//! inter-reflections and a fuzzy transition into the fabric; the thesis's images also
//! carry camera noise and a matte. Here fibres are smooth tapered tubes; the Kajiya–Kay
//! term lights a fibre's far side as its near side, and the forward lobe depends only on
//! the light (the view is fixed), not on the fibre's orientation as the transmission lobe
//! of a real fibre would; shadowing is a smooth density approximation (no sharp shadows of
//! single fibres); there is no multiple scattering; and the base itself is never visible
//! (it is at or below the image's bottom edge).
//!
//! # Cost
//! Building rasterises every segment once (its projected area in sub-samples) and splats
//! it into the grid; an image costs one shadow march per pixel and strand seen in it, each
//! as many trilinear look-ups as the ray crosses cells (rayon over rows; with σ = 0 no
//! march at all). Measured with `cargo run --release -p synth --example wool_fins`
//! (default parameters: 128² pixels × 2² sub-samples, 400 strands, the 81 lights of
//! Tab. 5.3) on the project's 2-core development machine while another engineer's builds
//! kept its load average about 2: building 0.02–0.04 s; the 81 images 2.0–2.2 s on both
//! cores (3.5–3.8 s of CPU), 3.8 s on one thread (`RAYON_NUM_THREADS=1`). The cost grows
//! about with width³ at a fixed aspect (covered sub-samples × cells per march): 64² ×
//! 2²: 0.27 s, 256² × 2² (same 400 strands): 16 s.

mod shadow;
mod strands;
mod view;

use crate::error::{Result, SynthError, check_range};
use glam::Vec3;
use rayon::prelude::*;
use view::Hit;

/// The fixed view direction of every fin image (tangent frame, towards the viewer):
/// θ_V = 90°, φ_V = 0°.
pub const FIN_VIEW_DIR: Vec3 = Vec3::X;
/// Largest accepted image width or height, pixels.
pub const MAX_FIN_SIDE: usize = 4096;
/// Largest accepted sub-sample count per pixel side.
pub const MAX_FIN_SUPERSAMPLE: usize = 8;
/// Largest accepted number of sub-samples per image, `width · height · supersample²`
/// (4 Mi; the fixed-view hits then take 112 MiB).
pub const MAX_FIN_SAMPLES: u128 = 1 << 22;
/// Largest accepted number of strand segments in all (2 Mi; 80 MiB of segments).
pub const MAX_FIN_SEGMENTS: u128 = 1 << 21;
/// Largest accepted number of segments per generated strand.
pub const MAX_STRAND_SEGMENTS: usize = 64;
/// Largest accepted absolute coordinate of a caller-supplied strand point, material units.
pub const MAX_STRAND_COORD: f32 = 1.0e4;
/// Largest accepted root radius of a caller-supplied strand, material units.
pub const MAX_STRAND_ROOT_RADIUS: f32 = 0.25;

/// Tuning knobs of [`WoolFins`] (see the [module documentation](self)). Lengths are in
/// material units (one unit = the image width) unless the name says pixels; colours are
/// linear RGB albedos.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WoolFinParams {
    /// Image width in pixels, 1 ..= [`MAX_FIN_SIDE`]: one material unit, one period of the
    /// fin (default 128).
    pub width: usize,
    /// Image height in pixels, 1 ..= [`MAX_FIN_SIDE`] (default 128).
    pub height: usize,
    /// Sub-samples per pixel side, 1 ..= [`MAX_FIN_SUPERSAMPLE`] (default 2).
    pub supersample: usize,
    /// Number of strands, ≥ 1; `strands · segments` ≤ [`MAX_FIN_SEGMENTS`] (default 400:
    /// with the default radius and width the bottom quarter's mean alpha is about 0.9, the
    /// top quarter's about 0.03). Coverage near the base grows with
    /// `strands · root_radius_px / width`: to keep the look at another width, scale
    /// `strands` with it.
    pub strands: usize,
    /// Segments per strand, 1 ..= [`MAX_STRAND_SEGMENTS`] (default 12).
    pub segments: usize,
    /// Depth of the layer of roots behind the fin's front (roots have x ∈ [−depth, 0]),
    /// 0 ..= 4 (default 0.5).
    pub depth: f32,
    /// Shortest strand as a fraction of the image height, 0.05 ..= 1 (default 0.6).
    pub length_min: f32,
    /// Longest strand as a fraction of the image height, `length_min` ..= 1
    /// (default 0.95).
    pub length_max: f32,
    /// Largest tilt of a strand's axis from +z, degrees, 0 ..= 60 (default 20).
    pub max_tilt_deg: f32,
    /// Largest curl amplitude (horizontal part of the direction relative to the axis),
    /// 0 ..= 1 (default 0.15).
    pub curl: f32,
    /// Strand radius at the root in pixel widths, 0.05 ..= 8 (default 0.45).
    pub root_radius_px: f32,
    /// Mean wool albedo ρ, each channel 0 ..= 1 (default (0.80, 0.70, 0.55), cream).
    pub colour: Vec3,
    /// Relative per-strand variation of the albedo, 0 ..= 0.5 (default 0.08).
    pub colour_variation: f32,
    /// Weight k_d of the Kajiya–Kay diffuse term, 0 ..= 1 (default 0.6).
    pub diffuse_weight: f32,
    /// Weight k_f of the forward-scattering lobe, 0 ..= 1 (default 0.4).
    pub forward_weight: f32,
    /// Exponent p of the forward-scattering lobe, 1 ..= 1000 (default 4).
    pub forward_exponent: f32,
    /// Scale σ of the fibre cloud's extinction for self-shadowing, 0 ..= 100: 0 disables
    /// self-shadowing, 1 makes fibres as opaque to the light as they look to the camera
    /// (default 0.5, for wool's translucency).
    pub shadow_sigma: f32,
    /// Seed of the strand geometry and colours (default 11).
    pub seed: u64,
}

impl Default for WoolFinParams {
    fn default() -> Self {
        Self {
            width: 128,
            height: 128,
            supersample: 2,
            strands: 400,
            segments: 12,
            depth: 0.5,
            length_min: 0.6,
            length_max: 0.95,
            max_tilt_deg: 20.0,
            curl: 0.15,
            root_radius_px: 0.45,
            colour: Vec3::new(0.80, 0.70, 0.55),
            colour_variation: 0.08,
            diffuse_weight: 0.6,
            forward_weight: 0.4,
            forward_exponent: 4.0,
            shadow_sigma: 0.5,
            seed: 11,
        }
    }
}

impl WoolFinParams {
    /// Checks every field.
    ///
    /// # Errors
    /// [`SynthError::InvalidParameter`] naming the first offending field, or
    /// [`SynthError::TooLarge`] when `width · height · supersample²` exceeds
    /// [`MAX_FIN_SAMPLES`] or `strands · segments` exceeds [`MAX_FIN_SEGMENTS`].
    pub fn validate(&self) -> Result<()> {
        let counts = [
            (
                "WoolFinParams::width",
                self.width,
                1,
                MAX_FIN_SIDE,
                "1 ..= 4096 pixels",
            ),
            (
                "WoolFinParams::height",
                self.height,
                1,
                MAX_FIN_SIDE,
                "1 ..= 4096 pixels",
            ),
            (
                "WoolFinParams::supersample",
                self.supersample,
                1,
                MAX_FIN_SUPERSAMPLE,
                "1 ..= 8 sub-samples per pixel side",
            ),
            (
                "WoolFinParams::strands",
                self.strands,
                1,
                usize::MAX,
                "at least 1 strand",
            ),
            (
                "WoolFinParams::segments",
                self.segments,
                1,
                MAX_STRAND_SEGMENTS,
                "1 ..= 64 segments per strand",
            ),
        ];
        for (field, value, min, max, expected) in counts {
            if !(min..=max).contains(&value) {
                return Err(SynthError::InvalidParameter {
                    field,
                    value: value as f64,
                    expected,
                });
            }
        }
        let samples = self.width as u128 * self.height as u128 * (self.supersample as u128).pow(2);
        if samples > MAX_FIN_SAMPLES {
            return Err(SynthError::TooLarge {
                field: "WoolFinParams::width · height · supersample²",
                requested: samples,
                maximum: MAX_FIN_SAMPLES,
                unit: "sub-samples",
            });
        }
        let segments = self.strands as u128 * self.segments as u128;
        if segments > MAX_FIN_SEGMENTS {
            return Err(SynthError::TooLarge {
                field: "WoolFinParams::strands · segments",
                requested: segments,
                maximum: MAX_FIN_SEGMENTS,
                unit: "strand segments",
            });
        }
        let ranges = [
            ("WoolFinParams::depth", self.depth, 0.0, 4.0, "0 ..= 4"),
            (
                "WoolFinParams::length_min",
                self.length_min,
                0.05,
                1.0,
                "0.05 ..= 1",
            ),
            (
                "WoolFinParams::length_max",
                self.length_max,
                self.length_min,
                1.0,
                "length_min ..= 1",
            ),
            (
                "WoolFinParams::max_tilt_deg",
                self.max_tilt_deg,
                0.0,
                60.0,
                "0 ..= 60 degrees",
            ),
            ("WoolFinParams::curl", self.curl, 0.0, 1.0, "0 ..= 1"),
            (
                "WoolFinParams::root_radius_px",
                self.root_radius_px,
                0.05,
                8.0,
                "0.05 ..= 8 pixel widths",
            ),
            (
                "WoolFinParams::colour_variation",
                self.colour_variation,
                0.0,
                0.5,
                "0 ..= 0.5",
            ),
            (
                "WoolFinParams::diffuse_weight",
                self.diffuse_weight,
                0.0,
                1.0,
                "0 ..= 1",
            ),
            (
                "WoolFinParams::forward_weight",
                self.forward_weight,
                0.0,
                1.0,
                "0 ..= 1",
            ),
            (
                "WoolFinParams::forward_exponent",
                self.forward_exponent,
                1.0,
                1000.0,
                "1 ..= 1000",
            ),
            (
                "WoolFinParams::shadow_sigma",
                self.shadow_sigma,
                0.0,
                100.0,
                "0 ..= 100",
            ),
        ];
        for (field, value, min, max, expected) in ranges {
            check_range(field, value, min, max, expected)?;
        }
        let fields = [
            "WoolFinParams::colour.x",
            "WoolFinParams::colour.y",
            "WoolFinParams::colour.z",
        ];
        for (value, field) in self.colour.to_array().into_iter().zip(fields) {
            check_range(field, value, 0.0, 1.0, "0 ..= 1")?;
        }
        Ok(())
    }
}

/// One fibre: a polyline from the root to the tip in the tangent frame (material units),
/// a tube whose radius falls linearly with arc length from `root_radius` to 0 at the tip.
#[derive(Debug, Clone, PartialEq)]
pub struct WoolStrand {
    /// The polyline, root first; at least 2 points, coordinates within
    /// ±[`MAX_STRAND_COORD`]. The image shows only what lies above z = 0; y is periodic.
    pub points: Vec<Vec3>,
    /// Radius at the root, 0 ..= [`MAX_STRAND_ROOT_RADIUS`] material units.
    pub root_radius: f32,
    /// Albedo ρ of the strand, each channel 0 ..= 1.
    pub colour: Vec3,
}

/// One fin image: linear RGB premultiplied over black, alpha = fibre coverage.
#[derive(Debug, Clone, PartialEq)]
pub struct FinImage {
    /// Pixels per row.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// `[r, g, b, alpha]` per pixel, row-major, top row (the tips) first: index
    /// `row · width + column`. Alpha ∈ [0, 1]; where alpha is 0, r = g = b = 0.
    pub rgba: Vec<[f32; 4]>,
}

impl FinImage {
    /// The pixel in `column` of `row` (row 0 at the top); `None` outside the image.
    pub fn pixel(&self, column: usize, row: usize) -> Option<[f32; 4]> {
        if column < self.width && row < self.height {
            self.rgba.get(row * self.width + column).copied()
        } else {
            None
        }
    }
}

/// A procedural wool fin BTF (see the [module documentation](self)): build it once, then
/// call [`image`](Self::image) per light direction. Images are deterministic for the
/// parameters, independent of rayon's thread count and of the order of calls.
///
/// # Examples
/// ```
/// use glam::Vec3;
/// use synth::{WoolFinParams, WoolFins};
///
/// let params = WoolFinParams { width: 32, height: 32, strands: 100, ..Default::default() };
/// let fins = WoolFins::new(&params)?;
/// let overhead = fins.image(Vec3::Z);
/// assert_eq!(overhead.rgba.len(), 32 * 32);
/// // The black background stays black.
/// assert!(overhead.rgba.iter().all(|p| p[3] > 0.0 || p[..3] == [0.0; 3]));
/// // Alpha falls off towards the tips (row 0 is the top).
/// let row_alpha = |row| (0..32).map(|i| overhead.pixel(i, row).unwrap()[3]).sum::<f32>();
/// assert!(row_alpha(31) > row_alpha(2));
/// // A light below the horizon gives black colour with the coverage alpha.
/// let below = fins.image(-Vec3::Z);
/// assert!(below.rgba.iter().zip(fins.alpha()).all(|(p, &a)| *p == [0.0, 0.0, 0.0, a]));
/// # Ok::<(), synth::SynthError>(())
/// ```
#[derive(Clone)]
pub struct WoolFins {
    params: WoolFinParams,
    strands: Vec<WoolStrand>,
    /// The nearest fibre point of every sub-sample (see `view::trace` for the order).
    hits: Vec<Hit>,
    /// Coverage per pixel, row-major.
    alpha: Vec<f32>,
    grid: shadow::DensityGrid,
}

impl std::fmt::Debug for WoolFins {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("WoolFins")
            .field("params", &self.params)
            .field("strands", &self.strands.len())
            .finish_non_exhaustive()
    }
}

impl WoolFins {
    /// Validates the parameters, grows the strands, finds the fixed view's hits and builds
    /// the shadow grid.
    ///
    /// # Errors
    /// As [`WoolFinParams::validate`].
    pub fn new(params: &WoolFinParams) -> Result<Self> {
        params.validate()?;
        Ok(Self::build(params, strands::generate(params)))
    }

    /// Like [`new`](Self::new), but with caller-supplied strands instead of generated ones:
    /// only the image fields (`width`, `height`, `supersample`) and the shading fields
    /// (`diffuse_weight`, `forward_weight`, `forward_exponent`, `shadow_sigma`) of `params`
    /// are used, although all of it must be valid. Strand k belongs to shadow group k mod 4
    /// (see "Self-shadowing" in the [module documentation](self)). Any number of strands,
    /// none included. The cost of building grows with the strands' projected area in
    /// sub-samples.
    ///
    /// # Errors
    /// As [`WoolFinParams::validate`]; [`SynthError::InvalidParameter`] naming the
    /// [`WoolStrand`] field for a strand with fewer than 2 points, a coordinate that is not
    /// finite or beyond ±[`MAX_STRAND_COORD`], a root radius outside
    /// 0 ..= [`MAX_STRAND_ROOT_RADIUS`] or a colour channel outside 0 ..= 1;
    /// [`SynthError::TooLarge`] for more than [`MAX_FIN_SEGMENTS`] segments in all.
    pub fn from_strands(params: &WoolFinParams, strands: Vec<WoolStrand>) -> Result<Self> {
        params.validate()?;
        strands::validate(&strands)?;
        Ok(Self::build(params, strands))
    }

    fn build(params: &WoolFinParams, strands: Vec<WoolStrand>) -> Self {
        let segments = strands::segments(&strands);
        let (width, height, n) = (params.width, params.height, params.supersample);
        let hits = view::trace(&segments, width, height, n);
        let per_pixel = 1.0 / (n * n) as f32;
        let alpha = hits
            .chunks_exact(n * n)
            .map(|samples| samples.iter().filter(|h| h.is_fibre()).count() as f32 * per_pixel)
            .collect();
        let grid = shadow::DensityGrid::new(&segments, width);
        Self {
            params: *params,
            strands,
            hits,
            alpha,
            grid,
        }
    }

    /// The parameters this fin was built from.
    pub fn params(&self) -> &WoolFinParams {
        &self.params
    }

    /// The strands, generated or supplied, in order.
    pub fn strands(&self) -> &[WoolStrand] {
        &self.strands
    }

    /// The coverage of every pixel (the alpha of every image), row-major, top row first.
    pub fn alpha(&self) -> &[f32] {
        &self.alpha
    }

    /// The image under a directional light of irradiance π (see the
    /// [module documentation](self)).
    ///
    /// `light_dir_in_tangent` points from the sample towards the light; it is normalised
    /// here. A light at or below the horizon (`z ≤ 0` after normalising), or a direction
    /// that is not finite or has zero length, gives black colour with the coverage alpha
    /// ([`alpha`](Self::alpha)).
    pub fn image(&self, light_dir_in_tangent: Vec3) -> FinImage {
        let (width, height) = (self.params.width, self.params.height);
        let mut rgba: Vec<[f32; 4]> = self.alpha.iter().map(|&a| [0.0, 0.0, 0.0, a]).collect();
        if let Some(light) = light_dir_in_tangent.try_normalize().filter(|l| l.z > 0.0) {
            self.shade(light, &mut rgba);
        }
        FinImage {
            width,
            height,
            rgba,
        }
    }

    /// Fills the colour of `rgba` for the unit light direction `light` (`light.z > 0`).
    fn shade(&self, light: Vec3, rgba: &mut [[f32; 4]]) {
        let params = &self.params;
        let n = params.supersample;
        let per_pixel = n * n;
        let scale = 1.0 / per_pixel as f32;
        let diffuse = params.diffuse_weight;
        // v = +x, so −l·v = −l.x.
        let forward = params.forward_weight * (-light.x).max(0.0).powf(params.forward_exponent);
        let sigma = params.shadow_sigma;
        rgba.par_chunks_mut(params.width)
            .zip(self.hits.par_chunks(params.width * per_pixel))
            .for_each(|(row, hits)| {
                // Per pixel: (strand, sum of its hits' positions, count, transmittance).
                let mut seen: Vec<(u32, Vec3, f32, f32)> = Vec::with_capacity(per_pixel);
                for (pixel, samples) in row.iter_mut().zip(hits.chunks_exact(per_pixel)) {
                    seen.clear();
                    for hit in samples.iter().filter(|h| h.is_fibre()) {
                        match seen.iter_mut().find(|s| s.0 == hit.strand) {
                            Some(entry) => {
                                entry.1 += hit.position;
                                entry.2 += 1.0;
                            }
                            None => seen.push((hit.strand, hit.position, 1.0, 1.0)),
                        }
                    }
                    for entry in &mut seen {
                        let mean = entry.1 / entry.2;
                        entry.3 = self.grid.transmittance(mean, light, entry.0, sigma);
                    }
                    let mut sum = Vec3::ZERO;
                    for hit in samples.iter().filter(|h| h.is_fibre()) {
                        let cos = hit.tangent.dot(light);
                        let kajiya_kay = (1.0 - cos * cos).max(0.0).sqrt();
                        let transmittance =
                            seen.iter().find(|s| s.0 == hit.strand).map_or(1.0, |s| s.3);
                        let albedo = self.strands[hit.strand as usize].colour;
                        sum += transmittance * (diffuse * kajiya_kay + forward) * albedo;
                    }
                    let colour = sum * scale;
                    pixel[..3].copy_from_slice(&colour.to_array());
                }
            });
    }
}
