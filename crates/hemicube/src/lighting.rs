//! Runtime radiance from visibility maps (thesis §4.3.6, eqs. 4.4–4.7; SEED-NOTES §1.5).
//!
//! For a Lambertian vertex of albedo ρ under environment radiance L_env,
//!
//! > L_o(v) = ρ · Σ_p V_p · ΔF_p · L_env(dir_p)
//!
//! (a uniform L over an open hemisphere gives ρL; the seed's remark that real-world maps need
//! no ΔF, T 6296–6298, is an error: ΔF is applied always). dir_p is the pixel's direction turned
//! into the world by the vertex frame, so rotating or exchanging the environment re-reads
//! radiance and never rebuilds a map.
//!
//! Two look-ups ([`EnvLookup`]):
//! * [`EnvLookup::CubeMap`] (default), the seed's: a cube map of the environment whose texel
//!   holds the power that falls into it over its solid angle (latitude–longitude sub-texels
//!   binned by direction, so Σ L Ω is conserved to rounding; [`CubeMap::from_environment`]),
//!   looked up at the nearest texel, its side half the map's ([`matched_cube_resolution`]; the
//!   seed matches 1 texel to 1 pixel, T 6172–6175). A small bright sun keeps its power instead
//!   of being hit or missed by a pixel centre.
//! * [`EnvLookup::Exact`]: the environment's bilinear radiance at the exact pixel direction:
//!   exact directions, but point samples alias on sources smaller than a pixel.
//!
//! Point lights (T 6002–6005, 6312–6313) add (ρ/π) · V · I · max(0, n·l) / r² with V looked up
//! in the map at the light's direction ([`PointVisibility::Map`], the seed's) or by an exact
//! ray to the light ([`PointVisibility::Ray`]). The map records visibility *of the environment*:
//! a light between the vertex and an occluder is wrongly reported occluded by the map; the ray
//! stops at the light and is right.

use glam::{DVec3, Vec3};
use lightsphere::{Environment, latlong};
use occlusion_gpu::{RayCache, RayCaster};
use rayon::prelude::*;

use crate::maps::VisibilityMaps;

/// How environment radiance is read for a pixel direction.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum EnvLookup {
    /// A power-conserving cube map matched to the map's resolution (the seed's).
    #[default]
    CubeMap,
    /// The environment's bilinear radiance at the exact direction.
    Exact,
}

/// A cube map of an environment's radiance with texels holding the mean over the texel.
#[derive(Clone, Debug)]
pub struct CubeMap {
    res: usize,
    texels: Vec<Vec3>,
}

/// Face of the cube (in the wgpu order +X, −X, +Y, −Y, +Z, −Z) and the texel coordinates
/// (s, t) ∈ [0, 1)² of a direction.
fn cube_coordinates(d: DVec3) -> (usize, f64, f64) {
    let a = d.abs();
    let (face, ma, s, t) = if a.x >= a.y && a.x >= a.z {
        if d.x > 0.0 {
            (0, a.x, -d.z, -d.y)
        } else {
            (1, a.x, d.z, -d.y)
        }
    } else if a.y >= a.z {
        if d.y > 0.0 {
            (2, a.y, d.x, d.z)
        } else {
            (3, a.y, d.x, -d.z)
        }
    } else if d.z > 0.0 {
        (4, a.z, d.x, -d.y)
    } else {
        (5, a.z, -d.x, -d.y)
    };
    (face, 0.5 * (s / ma + 1.0), 0.5 * (t / ma + 1.0))
}

impl CubeMap {
    /// The cube map of side `res` of `env` (in the world, i.e. with the environment's rotation).
    ///
    /// Every latitude–longitude texel is split into s × s sub-texels (s chosen so that a cube
    /// texel spans ≥ 16 sub-texels along θ), each carrying its exact share L·Ω of the power to
    /// the cube texel its centre falls in; a cube texel's radiance is the power it received over
    /// its exact solid angle. Σ L Ω over the cube equals the environment's to rounding.
    ///
    /// # Panics
    /// If `res` is 0.
    pub fn from_environment(env: &Environment, res: usize) -> Self {
        assert!(res > 0, "cube map side must be > 0");
        let (w, h) = (env.width(), env.height());
        let s = (32 * res).div_ceil(h).max(1);
        let rotation = env.world_from_env().as_dquat();
        let (sub_h, sub_w) = (h * s, w * s);
        let dphi = std::f64::consts::TAU / sub_w as f64;
        let phis: Vec<(f64, f64)> = (0..sub_w)
            .map(|c| latlong::col_phi(c, sub_w).sin_cos())
            .collect();
        let mut power = vec![[0.0f64; 3]; 6 * res * res];
        for sub_row in 0..sub_h {
            let (top, bottom) = latlong::row_theta_bounds(sub_row, sub_h);
            let omega = latlong::band_solid_angle(top, bottom, dphi);
            let (sin_t, cos_t) = latlong::row_theta(sub_row, sub_h).sin_cos();
            for (sub_col, &(sin_p, cos_p)) in phis.iter().enumerate() {
                let d = rotation * DVec3::new(sin_t * cos_p, cos_t, sin_t * sin_p);
                let l = env.texel(sub_row / s, sub_col / s);
                let texel = &mut power[Self::index(res, d)];
                for c in 0..3 {
                    texel[c] += f64::from(l[c]) * omega;
                }
            }
        }
        let texels = power
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let rest = i % (res * res);
                let omega = cube_texel_solid_angle(res, rest % res, rest / res);
                Vec3::new(
                    (p[0] / omega) as f32,
                    (p[1] / omega) as f32,
                    (p[2] / omega) as f32,
                )
            })
            .collect();
        Self { res, texels }
    }

    fn index(res: usize, d: DVec3) -> usize {
        let (face, s, t) = cube_coordinates(d);
        let x = ((s * res as f64) as usize).min(res - 1);
        let y = ((t * res as f64) as usize).min(res - 1);
        (face * res + y) * res + x
    }

    /// Side in texels.
    pub fn resolution(&self) -> usize {
        self.res
    }

    /// The texel a world direction falls in.
    pub fn lookup(&self, d: Vec3) -> Vec3 {
        self.texels[Self::index(self.res, d.as_dvec3())]
    }

    /// Σ L Ω over the texels (f64), for checking power conservation.
    pub fn power(&self) -> [f64; 3] {
        let mut p = [0.0; 3];
        for (i, l) in self.texels.iter().enumerate() {
            let rest = i % (self.res * self.res);
            let omega = cube_texel_solid_angle(self.res, rest % self.res, rest / self.res);
            for c in 0..3 {
                p[c] += f64::from(l[c]) * omega;
            }
        }
        p
    }
}

/// Solid angle of texel (x, y) of a cube face of side `res` (exact).
fn cube_texel_solid_angle(res: usize, x: usize, y: usize) -> f64 {
    let e = |i: usize| 2.0 * i as f64 / res as f64 - 1.0;
    let corners = [
        DVec3::new(e(x), e(y), 1.0),
        DVec3::new(e(x + 1), e(y), 1.0),
        DVec3::new(e(x + 1), e(y + 1), 1.0),
        DVec3::new(e(x), e(y + 1), 1.0),
    ];
    crate::layout::triangle_solid_angle(corners[0], corners[1], corners[2])
        + crate::layout::triangle_solid_angle(corners[0], corners[2], corners[3])
}

/// The cube side used for a map: half the HC's n (SP: n scaled to a full 90° face, halved; HS:
/// φ bins / 8). Measured on the dress under `venice_sunset_1k.hdr` against HC 128² maps through
/// a 512² cube (`cargo xtask repro hemicube`, section 6): at HC 16²/32²/64² the relative RMS of
/// luminance is 2.2/2.1/1.9 % with side n/2, 2.7/2.0/1.8 % with n/4, 2.6/2.5/2.3 % with side n
/// and 6.8/5.7/4.6 % with 2n: n/2 is never more than 7 % from the best. The seed matches 1 texel to 1 pixel (T 6172–6175), but a
/// texel a little larger than a pixel is hit by the centre of every pixel it covers, so its
/// power reaches the vertex through their form factors instead of aliasing.
pub fn matched_cube_resolution(maps: &VisibilityMaps) -> usize {
    use crate::layout::Model;
    match maps.layout().model() {
        Model::Hemicube { res } => (res as usize / 2).max(1),
        Model::SinglePlane { res, aperture_deg } => {
            let a = (aperture_deg.to_radians() / 2.0).tan();
            ((f64::from(res) / (2.0 * a)).round() as usize).max(1)
        }
        Model::Hemisphere { phi, .. } => (phi as usize / 8).max(1),
    }
}

/// L_o = ρ Σ_p V_p ΔF_p L(dir_p) for every vertex, with `radiance` giving L for a world
/// direction; accumulated in f64; NaN for a vertex used by no triangle.
pub fn radiance_from<F>(maps: &VisibilityMaps, albedo: Vec3, radiance: F) -> Vec<Vec3>
where
    F: Fn(Vec3) -> Vec3 + Sync,
{
    let ff = maps.layout().form_factors();
    let dirs = maps.layout().directions();
    (0..maps.len())
        .into_par_iter()
        .map(|i| {
            let Some(frame) = maps.frame(i) else {
                return Vec3::NAN;
            };
            let m = glam::Mat3::from_quat(frame.rotation);
            let mut sum = DVec3::ZERO;
            for p in maps.open_pixels(i) {
                sum += f64::from(ff[p]) * radiance(m * dirs[p]).as_dvec3();
            }
            albedo * sum.as_vec3()
        })
        .collect()
}

/// Vertex radiance under an environment (already rotated as wanted, see
/// `Environment::with_rotation`) by the chosen look-up.
pub fn environment_radiance(
    maps: &VisibilityMaps,
    env: &Environment,
    albedo: Vec3,
    lookup: EnvLookup,
) -> Vec<Vec3> {
    match lookup {
        EnvLookup::Exact => radiance_from(maps, albedo, |d| env.radiance(d)),
        EnvLookup::CubeMap => {
            let cube = CubeMap::from_environment(env, matched_cube_resolution(maps));
            radiance_from(maps, albedo, |d| cube.lookup(d))
        }
    }
}

/// A point light: position (world) and radiant intensity per channel (W/sr).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointLight {
    /// World position.
    pub position: Vec3,
    /// Intensity I (RGB).
    pub intensity: Vec3,
}

/// How a point light's visibility is decided.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum PointVisibility {
    /// The map's pixel in the light's direction (the seed's; wrong for a light closer than the
    /// occluder).
    #[default]
    Map,
    /// An exact ray from the vertex to the light.
    Ray,
}

/// Point lights and how their visibility is decided.
#[derive(Clone, Copy)]
pub struct PointLighting<'a> {
    /// The lights.
    pub lights: &'a [PointLight],
    /// Map look-up or exact ray.
    pub visibility: PointVisibility,
    /// The scene's BVH, needed for [`PointVisibility::Ray`] (its receivers must be the maps'
    /// vertices).
    pub caster: Option<&'a RayCaster>,
    /// Ray origin offset along the normal × the scene diagonal (the builders' offset).
    pub offset_relative: f32,
}

/// Adds every point light's direct term (ρ/π) V I max(0, n·l) / r² to `radiance` (vertices
/// with NaN radiance stay NaN). `positions` are the vertices' world positions.
///
/// A light in the tangent plane (n·l = 0) adds nothing; a light at the vertex adds nothing.
/// [`PointVisibility::Ray`] without a caster falls back to the map.
pub fn add_point_lights(
    radiance: &mut [Vec3],
    maps: &VisibilityMaps,
    positions: &[Vec3],
    albedo: Vec3,
    lighting: &PointLighting<'_>,
) {
    let caster = lighting.caster;
    let offset = caster.map_or(0.0, |c| c.diagonal() * lighting.offset_relative);
    radiance.par_iter_mut().enumerate().for_each(|(i, out)| {
        let Some(frame) = maps.frame(i) else { return };
        let n = frame.normal();
        let mut cache = RayCache::default();
        let mut sum = Vec3::ZERO;
        for light in lighting.lights {
            let to = light.position.as_dvec3() - positions[i].as_dvec3();
            let r2 = to.length_squared();
            if r2 == 0.0 || !r2.is_finite() {
                continue;
            }
            let l = (to / r2.sqrt()).as_vec3();
            let cos = n.dot(l);
            if cos <= 0.0 {
                continue;
            }
            let visible = match (lighting.visibility, caster) {
                (PointVisibility::Ray, Some(c)) => {
                    let origin = c.centred(positions[i].as_dvec3()) + n * offset;
                    let target = c.centred(light.position.as_dvec3());
                    !c.occluded(origin, target - origin, 1.0, &mut cache)
                }
                _ => maps
                    .layout()
                    .pixel_of(frame.to_local(l))
                    .is_some_and(|p| maps.is_open(i, p)),
            };
            if visible {
                sum += light.intensity * (cos / (std::f32::consts::PI * r2 as f32));
            }
        }
        *out += albedo * sum;
    });
}
