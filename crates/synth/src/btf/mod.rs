//! A procedural woven-cloth BTF: the synthetic stand-in for the measured Bonn UBO2003 BTFs
//! (thesis §5.3 "Acquisition"), so the BTF pipeline (per-view PCA §5.4, rendering §5.5)
//! can be tested and demonstrated without the 1.2 GB measured data sets.
//!
//! # What is rendered
//! A tile of plain-weave cloth (warp yarns along x go over one weft and under the next) is
//! modelled as an analytic, periodic height field (`weave.rs`). For one view direction
//! [`WovenBtf::view`] finds, for every sub-sample of every texel, the first point of the
//! surface that the view ray meets; [`ViewHits::shade`] then lights those points from one
//! directional light. 81 views × 81 lights give the 6,561 images of a UBO2003 measurement
//! (Tab. 5.1), at the cost of 81 primary ray marches per sub-sample.
//!
//! The two effects that make a measured BTF worth more than a texture plus a normal map are
//! both present:
//! * **view dependence from parallax and masking**: oblique views see the yarn tops shifted
//!   and the yarn flanks facing the viewer, and the gaps between yarns disappear;
//! * **cast shadows at grazing light**: yarns shadow their neighbours (shadow rays are
//!   traced through the height field), on top of the attached shadow of `n·l ≤ 0`.
//!
//! # Conventions
//! * Tangent frame: z = surface normal of the cloth, x = tangent = warp direction, y =
//!   bitangent = weft direction. A direction d(θ, φ) = (sin θ cos φ, sin θ sin φ, cos θ):
//!   θ from +z, φ from +x towards +y. View and light directions point *away* from the
//!   surface (towards the camera, towards the light).
//! * Registration (thesis §5.3.3: "projecting all sample images onto the plane which is
//!   defined by the frontal view (θ = 0, φ = 0)"): the tile is the unit square, periodic in
//!   x and y. Texel (i, j) of a `res × res` image covers x ∈ [i, i+1)/res, y ∈ [j, j+1)/res;
//!   sub-sample (a, b) of `n × n` sits at `((i + (a+½)/n)/res, (j + (b+½)/n)/res, z_ref)` on
//!   the reference plane `z_ref` = the highest point of the height field. Its ray runs from
//!   there along −view (wrapping periodically in x and y) to the first intersection with the
//!   surface. Images are row-major: index `j·res + i`, row j = y, column i = x.
//! * Sample order of [`ViewHits::hits`]: texel-major, then `b·n + a`.
//!
//! # Reflectance model
//! Radiance (linear RGB) of a sub-sample with unit normal n, lit from unit direction l,
//! seen from unit direction v, with half vector h = (l + v)/|l + v|:
//!
//! ```text
//! L = V · max(n·l, 0) · ( k_d ρ + k_s (e + 8)/8 · max(n·h, 0)^e )
//! ```
//!
//! a Lambertian lobe of albedo ρ (per yarn) plus an energy-normalised Blinn–Phong lobe
//! `(e + 8)/(8π) (n·h)^e`, under a directional light of irradiance π at normal incidence
//! (so a white Lambertian surface facing the light has radiance 1). V ∈ {0, 1} is the
//! shadow-ray visibility. A texel is the mean of its n × n sub-samples. With the defaults
//! the top of a yarn under frontal light and view is ≈ 0.7 in its strongest channel;
//! every value is ≤ `k_d · max ρ + k_s (e + 8)/8` (< 1 with the defaults, glossy peaks
//! included). Nothing is clamped. A light at or below the horizon (`l.z ≤ 0`) gives black.
//!
//! # Deviations
//! The thesis measures real cloth; this is a model with none of the measurement's noise,
//! camera response or registration error, no inter-reflection and no translucency (light
//! through the gaps). The gap floor is a dark backing at `z = −z_ref`.
//!
//! # Cost
//! A view marches one ray per sub-sample through the height field, accelerated by a max
//! pyramid built from exact bounds (`bound.rs`, `march.rs`). Shadow rays are answered from
//! a per-light visibility table swept along the light's azimuth once per distinct light
//! and shared by all views (`shadow.rs`); a hit whose neighbouring table nodes disagree
//! traces its own shadow ray. Measured with `cargo run --release -p synth --example
//! woven_btf -- OUT RES SUPERSAMPLE` (81 × 81 images, default parameters) on the project's
//! 2-core development machine while other jobs kept its load average at 5–6, so each run
//! got about one core: 64² × 2²: 6.4 s (7.1 s of CPU); 256² × 1²: 24 s (24 s of CPU);
//! 256² × 2²: 96 s (94 s of CPU), roughly 20% of it primary rays, 10% building the 81
//! shadow tables, 45% table look-ups and shading, 25% traced shadow rays near shadow
//! edges.

mod bound;
mod lambertian;
mod march;
mod render;
mod shadow;
mod weave;

pub use lambertian::LambertianBtf;
pub use render::ViewHits;

use crate::error::{Result, SynthError, check_finite3, check_range};
use crate::rng::SplitMix64;
use glam::Vec3;
use march::Tracer;
use std::sync::Arc;
use weave::Weave;

/// Largest accepted number of sub-samples per image, `(res · supersample)²` (4 Mi; a
/// [`ViewHits`] then holds 240 MiB).
pub const MAX_WOVEN_SAMPLES: u128 = 1 << 22;
/// Largest accepted sub-sample count per texel side.
pub const MAX_SUPERSAMPLE: usize = 8;
/// Largest accepted number of warp or weft yarns across the tile.
pub const MAX_YARNS: u32 = 256;
/// Lowest accepted view elevation above the surface, degrees. The primary ray's travel
/// grows as 1/tan(elevation); at 1° it can cross 13 tiles.
pub const MIN_VIEW_ELEVATION_DEG: f32 = 1.0;
/// Fine march step in sub-samples: half a sub-sample, so that a ray's first intersection
/// and a shadow's edge are found to within a sub-sample (and the shadow tables, whose node
/// spacing is a whole number of steps, can be this fine).
const STEP_PER_SAMPLE: f32 = 0.5;
/// Fine march step cap in yarn half-widths, so that a coarse image still gets the yarn
/// shapes and the shadows right: a ray grazing a yarn can dip below it for less than a
/// step and miss it. With a sixteenth, a 32² × 2² image disagreed with a brute-force
/// march (step 2·10⁻⁴ tiles) on 1.5% of the hits under an 80° light; with a 32nd, on none.
const STEP_PER_HALF_WIDTH: f32 = 1.0 / 32.0;

/// Tuning knobs of [`WovenBtf`]. Lengths are relative to the yarn pitch, colours are linear
/// RGB albedos.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WovenBtfParams {
    /// Texels per side of every image, ≥ 1 (default 64).
    pub res: usize,
    /// Sub-samples per texel side, 1 ..= [`MAX_SUPERSAMPLE`]; a texel averages
    /// `supersample²` rays (default 2).
    pub supersample: usize,
    /// Warp yarns (running along x) across the tile; even, 2 ..= [`MAX_YARNS`] (default 4).
    pub warp_count: u32,
    /// Weft yarns (running along y) across the tile; even, 2 ..= [`MAX_YARNS`] (default 4).
    pub weft_count: u32,
    /// Fraction of the pitch a yarn covers, 0.05 ..= 1; the rest is the gap (default 0.8).
    pub yarn_width: f32,
    /// Height of a yarn's half-elliptic cross-section over its width, 0.05 ..= 2
    /// (default 0.3).
    pub yarn_height: f32,
    /// Amplitude of the over/under undulation of a yarn's axis over its cross-section
    /// height, 0 ..= 2 (default 0.6; above 0.5 the yarn on top at a crossing clears the
    /// other one completely).
    pub crimp: f32,
    /// Albedo of the warp yarns, each channel 0 ..= 1 (default (0.55, 0.12, 0.08), red).
    pub warp_albedo: Vec3,
    /// Albedo of the weft yarns, each channel 0 ..= 1 (default (0.10, 0.22, 0.55), blue).
    pub weft_albedo: Vec3,
    /// Albedo of the backing seen through the gaps, each channel 0 ..= 1
    /// (default (0.03, 0.03, 0.03)).
    pub gap_albedo: Vec3,
    /// Relative per-yarn variation of the albedo, 0 ..= 0.5: yarn k's albedo is the
    /// family's times `1 + variation · r_k` with r_k uniform in [−1, 1) from `seed`
    /// (default 0.08).
    pub albedo_variation: f32,
    /// Seed of the per-yarn albedo variation (default 7).
    pub seed: u64,
    /// Weight k_d of the Lambertian lobe, 0 ..= 1 (default 1).
    pub diffuse_weight: f32,
    /// Weight k_s of the normalised Blinn–Phong lobe, 0 ..= 1 (default 0.03).
    pub glossy_weight: f32,
    /// Blinn–Phong exponent e, 1 ..= 10⁴ (default 32).
    pub glossy_exponent: f32,
}

impl Default for WovenBtfParams {
    fn default() -> Self {
        Self {
            res: 64,
            supersample: 2,
            warp_count: 4,
            weft_count: 4,
            yarn_width: 0.8,
            yarn_height: 0.3,
            crimp: 0.6,
            warp_albedo: Vec3::new(0.55, 0.12, 0.08),
            weft_albedo: Vec3::new(0.10, 0.22, 0.55),
            gap_albedo: Vec3::splat(0.03),
            albedo_variation: 0.08,
            seed: 7,
            diffuse_weight: 1.0,
            glossy_weight: 0.03,
            glossy_exponent: 32.0,
        }
    }
}

impl WovenBtfParams {
    /// Checks every field.
    ///
    /// # Errors
    /// [`SynthError::InvalidParameter`] naming the first offending field, or
    /// [`SynthError::TooLarge`] when `(res · supersample)²` exceeds [`MAX_WOVEN_SAMPLES`].
    pub fn validate(&self) -> Result<()> {
        if self.res == 0 {
            return Err(SynthError::InvalidParameter {
                field: "WovenBtfParams::res",
                value: 0.0,
                expected: "at least 1 texel",
            });
        }
        if !(1..=MAX_SUPERSAMPLE).contains(&self.supersample) {
            return Err(SynthError::InvalidParameter {
                field: "WovenBtfParams::supersample",
                value: self.supersample as f64,
                expected: "1 ..= 8 sub-samples per texel side",
            });
        }
        let side = self.res as u128 * self.supersample as u128;
        if side * side > MAX_WOVEN_SAMPLES {
            return Err(SynthError::TooLarge {
                field: "WovenBtfParams::(res · supersample)²",
                requested: side * side,
                maximum: MAX_WOVEN_SAMPLES,
                unit: "sub-samples",
            });
        }
        for (field, count) in [
            ("WovenBtfParams::warp_count", self.warp_count),
            ("WovenBtfParams::weft_count", self.weft_count),
        ] {
            if !(2..=MAX_YARNS).contains(&count) || count % 2 != 0 {
                return Err(SynthError::InvalidParameter {
                    field,
                    value: f64::from(count),
                    expected: "an even count 2 ..= 256 (a plain weave repeats every 2 yarns)",
                });
            }
        }
        let ranges = [
            (
                "WovenBtfParams::yarn_width",
                self.yarn_width,
                0.05,
                1.0,
                "0.05 ..= 1",
            ),
            (
                "WovenBtfParams::yarn_height",
                self.yarn_height,
                0.05,
                2.0,
                "0.05 ..= 2",
            ),
            ("WovenBtfParams::crimp", self.crimp, 0.0, 2.0, "0 ..= 2"),
            (
                "WovenBtfParams::albedo_variation",
                self.albedo_variation,
                0.0,
                0.5,
                "0 ..= 0.5",
            ),
            (
                "WovenBtfParams::diffuse_weight",
                self.diffuse_weight,
                0.0,
                1.0,
                "0 ..= 1",
            ),
            (
                "WovenBtfParams::glossy_weight",
                self.glossy_weight,
                0.0,
                1.0,
                "0 ..= 1",
            ),
            (
                "WovenBtfParams::glossy_exponent",
                self.glossy_exponent,
                1.0,
                1.0e4,
                "1 ..= 10000",
            ),
        ];
        for (field, value, min, max, expected) in ranges {
            check_range(field, value, min, max, expected)?;
        }
        let albedos = [
            (
                self.warp_albedo,
                [
                    "WovenBtfParams::warp_albedo.x",
                    "WovenBtfParams::warp_albedo.y",
                    "WovenBtfParams::warp_albedo.z",
                ],
            ),
            (
                self.weft_albedo,
                [
                    "WovenBtfParams::weft_albedo.x",
                    "WovenBtfParams::weft_albedo.y",
                    "WovenBtfParams::weft_albedo.z",
                ],
            ),
            (
                self.gap_albedo,
                [
                    "WovenBtfParams::gap_albedo.x",
                    "WovenBtfParams::gap_albedo.y",
                    "WovenBtfParams::gap_albedo.z",
                ],
            ),
        ];
        for (albedo, fields) in albedos {
            for (value, field) in albedo.to_array().into_iter().zip(fields) {
                check_range(field, value, 0.0, 1.0, "0 ..= 1")?;
            }
        }
        Ok(())
    }
}

/// Which surface piece a point belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Yarn {
    /// Warp yarn k (running along x, axis at y = (k + ½)/warp_count), 0 ≤ k < warp_count.
    Warp(u32),
    /// Weft yarn m (running along y, axis at x = (m + ½)/weft_count), 0 ≤ m < weft_count.
    Weft(u32),
    /// The backing seen through the gaps between yarns.
    Gap,
}

/// A point of the cloth surface in the tangent frame (tile units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfacePoint {
    /// (x, y, z), x and y wrapped into [0, 1). From [`WovenBtf::surface`], z is the height
    /// field at (x, y). In [`ViewHits::hits`], z is where the view ray meets the surface:
    /// the same, except where the ray enters through the vertical face between a yarn's
    /// edge and the floor, where it is lower (x, y then lie just inside the yarn's edge,
    /// whose normal is horizontal, like the face's).
    pub position: Vec3,
    /// Unit normal (z ≥ 0; horizontal on the flank of a yarn's edge).
    pub normal: Vec3,
    /// The yarn the point lies on.
    pub yarn: Yarn,
}

/// A procedural woven-cloth BTF (see the [module documentation](self)): build it once,
/// then call [`view`](Self::view) per view direction and [`ViewHits::shade`] per light
/// direction. Cheap to clone (shared state, including the cache of shadow tables).
///
/// # Examples
/// ```
/// use glam::Vec3;
/// use synth::{WovenBtf, WovenBtfParams};
///
/// let btf = WovenBtf::new(&WovenBtfParams { res: 16, ..Default::default() })?;
/// let hits = btf.view(Vec3::Z)?; // frontal view
/// let frontal = hits.shade(Vec3::Z);
/// assert_eq!(frontal.len(), 16 * 16);
/// // A light below the horizon gives black.
/// assert!(hits.shade(-Vec3::Z).iter().all(|t| *t == [0.0; 3]));
/// // A grazing light darkens the cloth: n·l shrinks and yarns shadow each other.
/// let theta = 80f32.to_radians();
/// let grazing = hits.shade(Vec3::new(theta.sin(), 0.0, theta.cos()));
/// let mean = |image: &[[f32; 3]]| image.iter().map(|t| t[0]).sum::<f32>() / 256.0;
/// assert!(mean(&grazing) < 0.5 * mean(&frontal));
/// # Ok::<(), synth::SynthError>(())
/// ```
#[derive(Clone)]
pub struct WovenBtf {
    inner: Arc<Inner>,
}

impl std::fmt::Debug for WovenBtf {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("WovenBtf")
            .field("params", &self.inner.params)
            .finish_non_exhaustive()
    }
}

/// State shared by a [`WovenBtf`] and its [`ViewHits`].
struct Inner {
    params: WovenBtfParams,
    tracer: Tracer,
    /// Albedo of every warp yarn, then every weft yarn, then the gap.
    albedos: Vec<Vec3>,
    shadows: shadow::ShadowCache,
}

impl Inner {
    /// Where `yarn`'s albedo is in [`albedos`](Self::albedos) (< 2¹⁶: both yarn counts are
    /// ≤ [`MAX_YARNS`]).
    fn albedo_index(&self, yarn: Yarn) -> u16 {
        let index = match yarn {
            Yarn::Warp(k) => k,
            Yarn::Weft(m) => self.params.warp_count + m,
            Yarn::Gap => self.params.warp_count + self.params.weft_count,
        };
        index as u16
    }

    fn albedo(&self, yarn: Yarn) -> Vec3 {
        self.albedos[usize::from(self.albedo_index(yarn))]
    }

    fn surface(&self, x: f32, y: f32) -> SurfacePoint {
        let (x, y) = (x.rem_euclid(1.0), y.rem_euclid(1.0));
        // rem_euclid can round up to exactly 1.0 for tiny negative inputs.
        let wrap = |c: f32| if c >= 1.0 { 0.0 } else { c };
        let (x, y) = (wrap(x), wrap(y));
        let p = self.tracer.weave.point(x, y);
        SurfacePoint {
            position: Vec3::new(x, y, p.height),
            normal: p.normal,
            yarn: p.yarn,
        }
    }
}

impl WovenBtf {
    /// Validates the parameters and prepares the weave.
    ///
    /// # Errors
    /// As [`WovenBtfParams::validate`].
    pub fn new(params: &WovenBtfParams) -> Result<Self> {
        params.validate()?;
        let weave = Weave::new(
            params.warp_count,
            params.weft_count,
            params.yarn_width,
            params.yarn_height,
            params.crimp,
        );
        let mut rng = SplitMix64::new(params.seed);
        let mut vary = |base: Vec3, count: u32| -> Vec<Vec3> {
            (0..count)
                .map(|_| {
                    let factor = 1.0 + params.albedo_variation * rng.next_signed();
                    (base * factor).clamp(Vec3::ZERO, Vec3::ONE)
                })
                .collect()
        };
        let mut albedos = vary(params.warp_albedo, params.warp_count);
        albedos.extend(vary(params.weft_albedo, params.weft_count));
        albedos.push(params.gap_albedo);
        let side = params.res * params.supersample;
        let step =
            (STEP_PER_SAMPLE / side as f32).min(STEP_PER_HALF_WIDTH * weave.min_half_width());
        let inner = Inner {
            params: *params,
            tracer: Tracer::new(weave, step),
            albedos,
            shadows: shadow::ShadowCache::default(),
        };
        Ok(Self {
            inner: Arc::new(inner),
        })
    }

    /// The parameters this BTF was built from.
    pub fn params(&self) -> &WovenBtfParams {
        &self.inner.params
    }

    /// Texels per side of every image.
    pub fn res(&self) -> usize {
        self.inner.params.res
    }

    /// The lowest (the gap floor) and highest point of the surface, tile units; the highest
    /// is the registration plane z_ref.
    pub fn height_range(&self) -> (f32, f32) {
        (
            self.inner.tracer.weave.z_floor,
            self.inner.tracer.weave.z_top,
        )
    }

    /// The surface at (x, y): any real coordinates, the tile repeats with period 1.
    pub fn surface(&self, x: f32, y: f32) -> SurfacePoint {
        self.inner.surface(x, y)
    }

    /// The albedo (linear RGB) of a yarn, including its per-yarn variation; `None` for a
    /// yarn index not below its family's count.
    pub fn albedo(&self, yarn: Yarn) -> Option<Vec3> {
        let p = &self.inner.params;
        match yarn {
            Yarn::Warp(k) if k >= p.warp_count => None,
            Yarn::Weft(m) if m >= p.weft_count => None,
            _ => Some(self.inner.albedo(yarn)),
        }
    }

    /// Casts the primary rays of every sub-sample for one view direction (see the
    /// [module documentation](self) for the registration): the result is lit by
    /// [`ViewHits::shade`] for any number of lights.
    ///
    /// `view_dir_in_tangent` points from the surface towards the viewer; it is normalised
    /// here, so its length does not matter.
    ///
    /// # Errors
    /// [`SynthError::InvalidParameter`] when the direction is not finite, has zero length,
    /// or is less than [`MIN_VIEW_ELEVATION_DEG`] above the surface (a view from below the
    /// cloth is not part of a BTF).
    pub fn view(&self, view_dir_in_tangent: Vec3) -> Result<ViewHits> {
        check_finite3("view_dir_in_tangent", view_dir_in_tangent)?;
        let Some(view) = view_dir_in_tangent.try_normalize() else {
            return Err(SynthError::InvalidParameter {
                field: "view_dir_in_tangent",
                value: f64::from(view_dir_in_tangent.length()),
                expected: "a direction of non-zero length",
            });
        };
        if view.z < MIN_VIEW_ELEVATION_DEG.to_radians().sin() {
            return Err(SynthError::InvalidParameter {
                field: "view_dir_in_tangent.z (normalised)",
                value: f64::from(view.z),
                expected: "≥ sin 1° ≈ 0.0175: a view at least 1° above the surface",
            });
        }
        Ok(ViewHits::trace(Arc::clone(&self.inner), view))
    }
}
