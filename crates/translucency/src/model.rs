//! The model of seed 004 on the CPU, f64: Schlick's transmittance, eq. 12's dipole-inspired
//! attenuation and its clamp, the refraction vector, the accumulation frame with the
//! "blindness" and "shift" fixes, and L^e per point (eq. 12) — the reference the GPU pass is
//! checked against.

use glam::{DVec3, Vec3};
use std::f64::consts::PI;

use crate::error::{TranslucencyError, bad_parameter};
use crate::material::Material;
use crate::sh::Sh9;

/// A light for the thickness d and the lit object's irradiance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// A point light at a world position (may lie inside the object's bounding box).
    Point(DVec3),
    /// A directional light: unit direction *towards* the light.
    Directional(DVec3),
}

impl Light {
    /// `Ok` when the position is finite or the direction finite and non-zero (normalised).
    ///
    /// # Errors
    /// The light, named with its value.
    pub fn validated(self) -> Result<Self, TranslucencyError> {
        match self {
            Light::Point(p) if p.is_finite() => Ok(self),
            Light::Directional(d) if d.is_finite() && d.length() > 0.0 => {
                Ok(Light::Directional(d.normalize()))
            }
            Light::Point(p) => Err(bad_parameter("light position", p, "must be finite")),
            Light::Directional(d) => Err(bad_parameter(
                "light direction",
                d,
                "must be finite and non-zero",
            )),
        }
    }

    /// Distance along the light's ray to `x`: |x − p| for a point light, −x·l for a
    /// directional one (a plane through the origin facing the light). d = dist(x_out) −
    /// dist(x_in) (SEED-NOTES §5.7.7).
    #[must_use]
    pub fn distance(&self, x: DVec3) -> f64 {
        match *self {
            Light::Point(p) => (x - p).length(),
            Light::Directional(l) => -x.dot(l),
        }
    }

    /// Unit direction from `x` towards the light.
    #[must_use]
    pub fn towards(&self, x: DVec3) -> DVec3 {
        match *self {
            Light::Point(p) => (p - x).normalize_or_zero(),
            Light::Directional(l) => l,
        }
    }
}

/// Schlick's Fresnel transmittance F_t = 1 − R0 − (1 − R0)(1 − cos θ)^5 with
/// R0 = ((η − 1)/(η + 1))² (Schlick 1994; SEED-NOTES §5.6). `cos_theta` is clamped to [0, 1].
#[must_use]
pub fn schlick_transmittance(eta: f64, cos_theta: f64) -> f64 {
    let r0 = ((eta - 1.0) / (eta + 1.0)).powi(2);
    let c = cos_theta.clamp(0.0, 1.0);
    1.0 - r0 - (1.0 - r0) * (1.0 - c).powi(5)
}

/// Eq. 12's attenuation A(d) = (σ_tr d + 1) e^{−σ_tr d} / (σ′_t d³), unclamped (diverges as
/// d → 0). `d` in mm, σ in mm⁻¹.
#[must_use]
pub fn attenuation(sigma_tr: f64, sigma_t_prime: f64, d: f64) -> f64 {
    (sigma_tr * d + 1.0) * (-sigma_tr * d).exp() / (sigma_t_prime * d * d * d)
}

/// The clamp of A near d → 0: A is evaluated at max(d, d_min), where it is finite. The
/// material's clamp distance ([`Material::clamp_distance`]) is one transport mean free path
/// of the most weakly scattering channel, 1 / min σ′_t, the same for R, G and B: below it the
/// dipole's point-source picture has no meaning. A per-channel clamp at 1/σ′_t would give
/// A(d_min) = (σ_tr/σ′_t + 1) e^{−σ_tr/σ′_t} σ′_t², largest where σ′_t is — silhouettes and the
/// lit side would turn blue for every measured material, the opposite of the red that
/// scatters furthest.
#[must_use]
pub fn attenuation_clamped(sigma_tr: f64, sigma_t_prime: f64, d: f64, d_min: f64) -> f64 {
    attenuation(sigma_tr, sigma_t_prime, d.max(d_min))
}

/// GLSL's `refract(i, n, eta)`: the refraction of unit `incident` at unit normal `n` (facing
/// against `incident`) with ratio `eta` = n₁/n₂; `None` on total internal reflection.
#[must_use]
pub fn refract(incident: DVec3, n: DVec3, eta: f64) -> Option<DVec3> {
    let ni = n.dot(incident);
    let k = 1.0 - eta * eta * (1.0 - ni * ni);
    (k >= 0.0).then(|| eta * incident - (eta * ni + k.sqrt()) * n)
}

/// The refraction vector of seed 004 (SEED-NOTES §5.7.6): r = refract(−ω_out, n, 1/η), the
/// direction into the object along which the far side's light arrives. Entering a denser
/// medium never reflects totally; for η < 1 a grazing view can, and then −n is used.
#[must_use]
pub fn refraction_vector(n: DVec3, omega_out: DVec3, eta: f64) -> DVec3 {
    refract(-omega_out, n, 1.0 / eta).unwrap_or(-n)
}

/// The single accumulation point's frame (TR 86): the bounding box's centre, and the scale
/// that makes the box a cube (the "blindness" fix, TR 145).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AccumulationFrame {
    /// Centre of the bounding box (world, f64 so a mesh offset by 10⁵ keeps its detail).
    pub centre: DVec3,
    /// Half extents, each at least [`AccumulationFrame::MIN_RELATIVE_EXTENT`] × the largest.
    pub half_extent: DVec3,
}

impl AccumulationFrame {
    /// A degenerate (flat or linear) box is thickened to this fraction of its largest half
    /// extent along its thin axes, so the cube-space scale stays finite.
    pub const MIN_RELATIVE_EXTENT: f64 = 1e-3;

    /// The frame of the points' bounding box.
    ///
    /// # Errors
    /// No points, a non-finite point, or all points equal.
    pub fn of_points(points: impl IntoIterator<Item = DVec3>) -> Result<Self, TranslucencyError> {
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        let mut n = 0usize;
        for (i, p) in points.into_iter().enumerate() {
            if !p.is_finite() {
                return Err(TranslucencyError::Mesh(format!(
                    "vertex {i} = {p} is not finite"
                )));
            }
            lo = lo.min(p);
            hi = hi.max(p);
            n += 1;
        }
        if n == 0 {
            return Err(TranslucencyError::Mesh("no vertices".into()));
        }
        let half = (hi - lo) / 2.0;
        let largest = half.max_element();
        if largest <= 0.0 {
            return Err(TranslucencyError::Mesh(format!(
                "all {n} vertices are the same point {lo}: no bounding box"
            )));
        }
        Ok(Self {
            centre: (lo + hi) / 2.0,
            half_extent: half.max(DVec3::splat(largest * Self::MIN_RELATIVE_EXTENT)),
        })
    }

    /// A world point in cube space ([−1, 1]³ over the box).
    #[must_use]
    pub fn to_cube(&self, x: DVec3) -> DVec3 {
        (x - self.centre) / self.half_extent
    }

    /// A world direction in cube space (normalised).
    #[must_use]
    pub fn direction_to_cube(&self, r: DVec3) -> DVec3 {
        (r / self.half_extent).normalize()
    }

    /// The "shift" fix (TR 143, SEED-NOTES §5.7.8): the SH argument for a point `x` and
    /// refraction direction `r` is the direction from the accumulation point to where the ray
    /// x + t r leaves the box, in cube space. A point just outside the box is clamped onto it.
    #[must_use]
    pub fn shifted_direction(&self, x: DVec3, r: DVec3) -> DVec3 {
        let p = self.to_cube(x).clamp(DVec3::NEG_ONE, DVec3::ONE);
        let d = self.direction_to_cube(r);
        let mut t = f64::INFINITY;
        for a in 0..3 {
            if d[a] != 0.0 {
                t = t.min((d[a].signum() - p[a]) / d[a]);
            }
        }
        let hit = p + t.max(0.0) * d;
        hit.try_normalize().unwrap_or(d)
    }
}

/// Eq. 12 at one point, per channel: L^e = (1/π) F_t(η, n·ω_out) A(d) B(s), with B from the
/// (already windowed) coefficients, clamped at 0, at the shifted direction s of
/// r = refract(−ω_out, n, 1/η); `d` in scene units (converted by the material's scale);
/// `hidden` (behind another front surface, the peeled-layer test) gives 0.
#[must_use]
#[allow(clippy::too_many_arguments)]
pub fn scattered_radiance(
    material: &Material,
    sh: &Sh9,
    frame: &AccumulationFrame,
    x: DVec3,
    n: DVec3,
    omega_out: DVec3,
    d: f64,
    hidden: bool,
) -> [f64; 3] {
    if hidden {
        return [0.0; 3];
    }
    let n = n.normalize();
    let omega_out = omega_out.normalize();
    let r = refraction_vector(n, omega_out, material.eta);
    let b = sh.irradiance_clamped(frame.shifted_direction(x, r));
    let ft = schlick_transmittance(material.eta, n.dot(omega_out));
    let (tr, tp) = (material.sigma_tr(), material.sigma_t_prime());
    let d_mm = d.max(0.0) * material.mm_per_unit;
    let d_min = material.clamp_distance();
    std::array::from_fn(|c| ft / PI * attenuation_clamped(tr[c], tp[c], d_mm, d_min) * b[c])
}

/// The lit object's transmitted irradiance at each vertex under a point or directional light
/// of RGB intensity `intensity` (W/sr for a point, irradiance for a directional light):
/// E_t = F_t(η, n·l) · E · max(0, n·l), with 1/r² for a point light — what the cube map
/// stores (pass 1), as the f32 the GPU takes. `visible(i)` scales vertex i (1 = lit).
#[must_use]
pub fn transmitted_irradiance(
    positions: &[DVec3],
    normals: &[Vec3],
    light: &Light,
    intensity: [f64; 3],
    eta: f64,
    visible: impl Fn(usize) -> f64,
) -> Vec<[f32; 3]> {
    positions
        .iter()
        .zip(normals)
        .enumerate()
        .map(|(i, (&x, &n))| {
            let l = light.towards(x);
            let cos = n.as_dvec3().normalize_or_zero().dot(l).max(0.0);
            let falloff = match *light {
                Light::Point(p) => 1.0 / (p - x).length_squared().max(f64::MIN_POSITIVE),
                Light::Directional(_) => 1.0,
            };
            let s = schlick_transmittance(eta, cos) * cos * falloff * visible(i);
            intensity.map(|v| (v * s) as f32)
        })
        .collect()
}
