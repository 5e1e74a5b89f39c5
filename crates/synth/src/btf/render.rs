//! One view of the BTF: the primary hits of every sub-sample, and their shading under one
//! directional light (the model in the [module documentation](super)).

use super::{Inner, SurfacePoint};
use glam::{Vec2, Vec3};
use rayon::prelude::*;
use std::sync::Arc;

/// The surface points seen by every sub-sample for one view direction, made by
/// [`WovenBtf::view`](super::WovenBtf::view). Shading them for a light is cheap compared
/// with finding them, so a full BTF costs one `view` per view direction and one
/// [`shade`](Self::shade) per (view, light) pair.
#[derive(Clone)]
pub struct ViewHits {
    inner: Arc<Inner>,
    view: Vec3,
    hits: Vec<SurfacePoint>,
    /// What shading reads of each hit, in the same order.
    samples: Vec<Sample>,
}

/// A hit as the shading loop reads it (28 bytes; shading streams every sample once per
/// light): the yarn resolved once per view to its index in `Inner::albedos` and its
/// shadow-table class.
#[derive(Debug, Clone, Copy)]
struct Sample {
    position: Vec3,
    normal: Vec3,
    albedo: u16,
    class: u8,
}

impl std::fmt::Debug for ViewHits {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ViewHits")
            .field("res", &self.res())
            .field("view_dir", &self.view)
            .finish_non_exhaustive()
    }
}

impl ViewHits {
    /// Marches the primary ray of every sub-sample (rayon over texels).
    pub(super) fn trace(inner: Arc<Inner>, view: Vec3) -> Self {
        let res = inner.params.res;
        let n = inner.params.supersample;
        let mut hits = vec![
            SurfacePoint {
                position: Vec3::ZERO,
                normal: Vec3::Z,
                yarn: super::Yarn::Gap,
            };
            res * res * n * n
        ];
        hits.par_chunks_mut(n * n)
            .enumerate()
            .for_each(|(texel, samples)| {
                let (i, j) = (texel % res, texel / res);
                for (k, sample) in samples.iter_mut().enumerate() {
                    let (a, b) = (k % n, k / n);
                    let origin = Vec2::new(
                        (i as f32 + (a as f32 + 0.5) / n as f32) / res as f32,
                        (j as f32 + (b as f32 + 0.5) / n as f32) / res as f32,
                    );
                    let hit = inner.tracer.primary_hit(origin, view);
                    *sample = inner.surface(hit.x, hit.y);
                    sample.position.z = hit.z;
                }
            });
        let samples = hits
            .iter()
            .map(|hit| Sample {
                position: hit.position,
                normal: hit.normal,
                albedo: inner.albedo_index(hit.yarn),
                class: inner.shadow_class(hit),
            })
            .collect();
        Self {
            inner,
            view,
            hits,
            samples,
        }
    }

    /// Texels per image side.
    pub fn res(&self) -> usize {
        self.inner.params.res
    }

    /// Sub-samples per texel side.
    pub fn supersample(&self) -> usize {
        self.inner.params.supersample
    }

    /// The normalised view direction (tangent frame, towards the viewer).
    pub fn view_dir(&self) -> Vec3 {
        self.view
    }

    /// The surface point each sub-sample sees, `res² · supersample²` of them: texel-major
    /// (`j·res + i`), then sub-sample `b·supersample + a` (see the
    /// [module documentation](super) for where sub-sample (a, b) of texel (i, j) lies).
    pub fn hits(&self) -> &[SurfacePoint] {
        &self.hits
    }

    /// The image under a directional light: `res × res` linear RGB radiances, row-major
    /// (index `j·res + i`), each the mean of the texel's sub-samples. Values are ≥ 0 and
    /// ≤ `k_d · max ρ + k_s (e + 8)/8` (see the [module documentation](super)); nothing is
    /// clamped.
    ///
    /// `light_dir_in_tangent` points from the surface towards the light; it is normalised
    /// here. A light at or below the horizon (`z ≤ 0` after normalising), or a direction
    /// that is not finite or has zero length, gives a black image.
    ///
    /// The first call for a light direction builds its shadow table (shared by every view
    /// of the same [`WovenBtf`](super::WovenBtf)); later calls only look it up.
    pub fn shade(&self, light_dir_in_tangent: Vec3) -> Vec<[f32; 3]> {
        let res = self.res();
        let Some(light) = light_above_horizon(light_dir_in_tangent) else {
            return vec![[0.0; 3]; res * res];
        };
        let inner = &*self.inner;
        let table = inner.shadow_table(light);
        let half = (light + self.view).normalize();
        let params = &inner.params;
        let glossy_scale = params.glossy_weight * (params.glossy_exponent + 8.0) / 8.0;
        let glossy = Glossy::new(params.glossy_exponent);
        let diffuse = params.diffuse_weight;
        let n = params.supersample;
        let per_texel = n * n;
        let per_sample = 1.0 / per_texel as f32;
        let mut image = vec![[0.0; 3]; res * res];
        image
            .par_chunks_mut(res)
            .zip(self.samples.par_chunks(res * per_texel))
            .for_each(|(row, samples)| {
                for (texel, samples) in row.iter_mut().zip(samples.chunks_exact(per_texel)) {
                    let mut sum = Vec3::ZERO;
                    for sample in samples {
                        let cos_light = sample.normal.dot(light);
                        if cos_light <= 0.0
                            || inner.in_shadow(&table, sample.position, sample.class, light)
                        {
                            continue;
                        }
                        let cos_half = sample.normal.dot(half).max(0.0);
                        let specular = glossy_scale * glossy.eval(cos_half);
                        let albedo = diffuse * inner.albedos[usize::from(sample.albedo)];
                        sum += cos_light * (albedo + Vec3::splat(specular));
                    }
                    *texel = (sum * per_sample).to_array();
                }
            });
        image
    }

    /// Which sub-samples (in the order of [`hits`](Self::hits)) lie in a cast shadow of
    /// the light: they face it (`n·l > 0`) but another part of the surface blocks it. The
    /// same test [`shade`](Self::shade) uses; all `false` for a light at or below the
    /// horizon.
    pub fn cast_shadows(&self, light_dir_in_tangent: Vec3) -> Vec<bool> {
        let Some(light) = light_above_horizon(light_dir_in_tangent) else {
            return vec![false; self.hits.len()];
        };
        let inner = &*self.inner;
        let table = inner.shadow_table(light);
        self.hits
            .par_iter()
            .map(|hit| {
                hit.normal.dot(light) > 0.0
                    && inner.in_shadow(&table, hit.position, inner.shadow_class(hit), light)
            })
            .collect()
    }
}

/// The normalised light direction, or `None` when it is at or below the horizon or not a
/// direction at all.
fn light_above_horizon(light: Vec3) -> Option<Vec3> {
    light.try_normalize().filter(|l| l.z > 0.0)
}

/// x^e of the Blinn–Phong lobe, set to 0 where it is below [`LOBE_CUTOFF`] (a change of at
/// most 2⁻⁶⁰ of the lobe's peak). An integral exponent (the default) is evaluated by
/// repeated squaring inline: `powf` was 13% of a BTF's time, the library `powi` 5%.
#[derive(Debug, Clone, Copy)]
struct Glossy {
    /// Below this x, x^e < [`LOBE_CUTOFF`].
    threshold: f32,
    exponent: Exponent,
}

/// The lobe's floor: without it, x^e of a small x is a denormal number, and multiplying
/// denormals made the shading loop three times slower.
const LOBE_CUTOFF: f32 = 8.673_617e-19; // 2⁻⁶⁰

#[derive(Debug, Clone, Copy)]
enum Exponent {
    Integral(u32),
    Real(f32),
}

impl Glossy {
    fn new(exponent: f32) -> Self {
        let threshold = LOBE_CUTOFF.powf(1.0 / exponent);
        let exponent = if exponent.fract() == 0.0 {
            Exponent::Integral(exponent as u32)
        } else {
            Exponent::Real(exponent)
        };
        Self {
            threshold,
            exponent,
        }
    }

    #[inline]
    fn eval(self, x: f32) -> f32 {
        if x < self.threshold {
            return 0.0;
        }
        match self.exponent {
            Exponent::Integral(mut e) => {
                let (mut base, mut result) = (x, 1.0);
                while e > 0 {
                    if e & 1 == 1 {
                        result *= base;
                    }
                    base *= base;
                    e >>= 1;
                }
                result
            }
            Exponent::Real(e) => x.powf(e),
        }
    }
}
