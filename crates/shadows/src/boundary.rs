//! The smooth shadow boundary of thesis §5.5.1 (T 7394–7462, SEED-NOTES §3.3–§3.4).
//!
//! A shadow volume's boundary on the caster itself follows its silhouette edges as seen from
//! the light: a zig-zag along the triangles that jumps when the light moves. Eq. 5.6 gives each
//! vertex a 1-D texture coordinate from the angle between its normal and its light vector,
//!
//! > u_V = (1 + cos(α + ∠(n̂_V, l̂_V))) / 2        (eq. 5.6)
//!
//! interpolated across the triangle and looked up in a texture that is black below u = ½ and
//! white above ([`BoundaryTexture`], 1,024 texels as in the thesis). The u = ½ iso-line lies at
//! ∠ = 90° − α, so with α = 15° (the thesis's value for its trousers) the smooth terminator
//! sits 15° inside the lit side and the silhouette zig-zag falls in the black band.
//!
//! **Decisions** (the seed is silent, SEED-NOTES §3.4): black is the low half; ∠ =
//! acos(clamp(n̂·l̂, −1, 1)) with l̂ per vertex (a point light) or constant (directional);
//! the light's visibility at a pixel is `(stencil = 0) × tex(u)` — shadowed where any volume
//! covers it, otherwise the boundary texture; [`BoundaryMode::AngleLinear`] is the prose's
//! "proportion of the angles", u = clamp(1 − (α + ∠)/π, 0, 1), which places the same iso-line
//! but interpolates angles rather than cosines along an edge. A blurred texture
//! ([`BoundaryTexture::blurred`]) softens the boundary; it is blurred over u, so eq. 5.6's
//! non-monotonic tail (u rises again for ∠ > 180° − α) can leak light only with a blur wider
//! than that tail (u ≤ (1 − cos α)/2 ≈ 0.017 at α = 15°), which [`BoundaryTexture::blurred`]
//! avoids by clamping texels below that value to black.

use glam::{DVec3, Vec3};

use crate::{Light, ShadowError};

/// The thesis's α for its high-resolution trousers (T 7455–7456).
pub const DEFAULT_ALPHA_DEG: f64 = 15.0;
/// Texels of the thesis's boundary texture (T 7451).
pub const TEXTURE_TEXELS: usize = 1024;

/// Which formula maps the angle to u.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BoundaryMode {
    /// Eq. 5.6 as printed: u = (1 + cos(α + ∠))/2.
    #[default]
    Cosine,
    /// The prose's angle proportion: u = clamp(1 − (α + ∠)/π, 0, 1).
    AngleLinear,
}

/// The 1-D texture coordinate of one vertex (normal and light vector need not be unit;
/// a zero vector gives u = the value at ∠ = 90°).
pub fn boundary_u(normal: DVec3, to_light: DVec3, alpha_rad: f64, mode: BoundaryMode) -> f64 {
    let (n, l) = (normal.normalize_or_zero(), to_light.normalize_or_zero());
    let angle = n.dot(l).clamp(-1.0, 1.0).acos();
    match mode {
        BoundaryMode::Cosine => (1.0 + (alpha_rad + angle).cos()) / 2.0,
        BoundaryMode::AngleLinear => {
            (1.0 - (alpha_rad + angle) / std::f64::consts::PI).clamp(0.0, 1.0)
        }
    }
}

/// The boundary coordinates of every vertex of a mesh for `light`, into `out` (reused).
///
/// # Errors
/// [`ShadowError::Parameter`] when α is outside [0°, 90°) or the slices differ in length.
pub fn boundary_coordinates(
    positions: &[Vec3],
    normals: &[Vec3],
    light: &Light,
    alpha_deg: f64,
    mode: BoundaryMode,
    out: &mut Vec<f32>,
) -> Result<(), ShadowError> {
    check_alpha(alpha_deg)?;
    if positions.len() != normals.len() {
        return Err(crate::error::bad_parameter(
            "normals",
            normals.len(),
            "need one normal per position",
        ));
    }
    let light = light.validated()?;
    let alpha = alpha_deg.to_radians();
    out.clear();
    out.extend(
        positions.iter().zip(normals).map(|(p, n)| {
            boundary_u(n.as_dvec3(), light.to_light(p.as_dvec3()), alpha, mode) as f32
        }),
    );
    Ok(())
}

/// α must be in [0°, 90°): at 90° the whole lit side would be black.
pub(crate) fn check_alpha(alpha_deg: f64) -> Result<(), ShadowError> {
    if (0.0..90.0).contains(&alpha_deg) {
        Ok(())
    } else {
        Err(crate::error::bad_parameter(
            "alpha",
            format!("{alpha_deg}°"),
            "the boundary offset must be in [0°, 90°)",
        ))
    }
}

/// The 1-D boundary texture: texel i covers u ∈ [i/n, (i+1)/n).
#[derive(Clone, Debug, PartialEq)]
pub struct BoundaryTexture {
    texels: Vec<f32>,
}

impl BoundaryTexture {
    /// Half black, half white (the thesis's texture): texel centres below ½ are 0.
    pub fn step(texels: usize) -> Self {
        let texels = texels.max(2);
        Self {
            texels: (0..texels)
                .map(|i| {
                    if (i as f64 + 0.5) / texels as f64 >= 0.5 {
                        1.0
                    } else {
                        0.0
                    }
                })
                .collect(),
        }
    }

    /// The step blurred by a box of `width` in u (a linear ramp from ½ − width/2 to ½ + width/2),
    /// with texels under eq. 5.6's tail value for `alpha_deg` forced to black (see the module).
    ///
    /// # Errors
    /// [`ShadowError::Parameter`] when `width` is not in [0, 1] or α is out of range.
    pub fn blurred(texels: usize, width: f64, alpha_deg: f64) -> Result<Self, ShadowError> {
        check_alpha(alpha_deg)?;
        if !(0.0..=1.0).contains(&width) {
            return Err(crate::error::bad_parameter(
                "blur width",
                width,
                "must be in [0, 1] (a fraction of the texture)",
            ));
        }
        let texels = texels.max(2);
        let tail = (1.0 - alpha_deg.to_radians().cos()) / 2.0;
        Ok(Self {
            texels: (0..texels)
                .map(|i| {
                    let u = (i as f64 + 0.5) / texels as f64;
                    let ramp = if width == 0.0 {
                        f64::from(u >= 0.5)
                    } else {
                        ((u - 0.5) / width + 0.5).clamp(0.0, 1.0)
                    };
                    if u <= tail { 0.0 } else { ramp as f32 }
                })
                .collect(),
        })
    }

    /// The texels, u ascending.
    pub fn texels(&self) -> &[f32] {
        &self.texels
    }

    /// Nearest-texel look-up (what the GPU's non-filtering sampler returns); u is clamped.
    pub fn sample(&self, u: f64) -> f32 {
        let n = self.texels.len();
        let i = ((u.clamp(0.0, 1.0) * n as f64) as usize).min(n - 1);
        self.texels[i]
    }
}

/// Where the interpolated coordinate crosses `level` on the mesh's edges: for each edge whose
/// end points lie on opposite sides, the point at t* = (u₁ − level)/(u₁ − u₂) from the first
/// (SEED-NOTES §3.3). These points trace the smooth boundary (the u = ½ iso-line for the
/// step texture), against which the terminator's analytic position is measured.
pub fn contour_points(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    u: &[f32],
    level: f32,
) -> Vec<DVec3> {
    let mut edges: Vec<(u32, u32)> = triangles
        .iter()
        .flat_map(|t| (0..3).map(move |k| (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]))))
        .collect();
    edges.sort_unstable();
    edges.dedup();
    edges
        .into_iter()
        .filter_map(|(a, b)| {
            let (ua, ub) = (f64::from(u[a as usize]), f64::from(u[b as usize]));
            let level = f64::from(level);
            ((ua - level) * (ub - level) < 0.0).then(|| {
                let t = (ua - level) / (ua - ub);
                let (pa, pb) = (
                    positions[a as usize].as_dvec3(),
                    positions[b as usize].as_dvec3(),
                );
                pa + (pb - pa) * t
            })
        })
        .collect()
}
