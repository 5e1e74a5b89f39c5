//! A receiver plane y = Y sampled on an N × N grid, and its exact shadow mask by rays through
//! occlusion-gpu's BVH (the CPU twin of the stencil mask).

use glam::{DVec3, Vec3};
use rayon::prelude::*;

use crate::error::bad_parameter;
use crate::{Light, ShadowError};

/// Largest grid side: 8192² cells of f32 are 256 MiB.
pub const MAX_GRID: usize = 8192;

/// How far [`GroundGrid::around_shadow`] reaches from the mesh's centre, in the mesh's largest
/// extents: a sun 3.6° above the horizon casts the shadow of a mesh as tall as it is wide 16
/// widths long.
pub const MAX_SHADOW_REACH: f64 = 16.0;

/// The receiver plane and its sampling: row j ↔ z_j = z0 + (j + ½)(z1 − z0)/N ascending,
/// column i ↔ x_i = x0 + (i + ½)(x1 − x0)/N ascending.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GroundGrid {
    /// Height of the plane.
    pub y: f64,
    /// (x0, z0, x1, z1).
    pub extent: [f64; 4],
    /// Cells per side.
    pub n: usize,
}

impl GroundGrid {
    /// A validated grid.
    ///
    /// # Errors
    /// [`ShadowError::Parameter`] for a non-finite height or extent, x1 ≤ x0 or z1 ≤ z0, or a
    /// side outside 1 ..= [`MAX_GRID`].
    pub fn new(y: f64, extent: [f64; 4], n: usize) -> Result<Self, ShadowError> {
        if !y.is_finite() {
            return Err(bad_parameter(
                "ground",
                y,
                "the plane's height must be finite",
            ));
        }
        let [x0, z0, x1, z1] = extent;
        if !(extent.iter().all(|v| v.is_finite()) && x1 > x0 && z1 > z0) {
            return Err(bad_parameter(
                "ground extent",
                format!("{x0},{z0},{x1},{z1}"),
                "needs finite X0,Z0,X1,Z1 with X1 > X0 and Z1 > Z0",
            ));
        }
        if !(1..=MAX_GRID).contains(&n) {
            return Err(bad_parameter(
                "grid",
                n,
                "cells per side must be in 1 ..= 8192",
            ));
        }
        Ok(Self { y, extent, n })
    }

    /// The default extent: the mesh's x/z bounding box scaled ×3 about its centre (a square
    /// grid needs no square extent; cells follow the extent's aspect). Along x or z, a mesh
    /// under a third of its largest extent wide (a vertical sheet: zero) gets a half-width of
    /// half that largest extent instead (the sheet's shadow leaves its plane); an empty mesh,
    /// or a single point, a unit square.
    ///
    /// # Errors
    /// As [`GroundGrid::new`].
    pub fn around(positions: &[Vec3], y: f64, n: usize) -> Result<Self, ShadowError> {
        let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for p in positions {
            lo = lo.min(p.as_dvec3());
            hi = hi.max(p.as_dvec3());
        }
        if positions.is_empty() {
            (lo, hi) = (DVec3::ZERO, DVec3::ZERO);
        }
        let centre = (lo + hi) / 2.0;
        // Relative, not absolute: a floor of 0.5 units once widened the grid of every mesh
        // under a third of a unit across (the Stanford bunny, in metres, 2.2×) and hid a
        // mesh 10⁻²⁰ across in one cell.
        let largest = (hi - lo).max_element();
        let floor = if largest > 0.0 { 0.5 * largest } else { 0.5 };
        let half = ((hi - lo) * 1.5).max(DVec3::splat(floor));
        Self::new(
            y,
            [
                centre.x - half.x,
                centre.z - half.z,
                centre.x + half.x,
                centre.z + half.z,
            ],
            n,
        )
    }

    /// [`GroundGrid::around`] grown to hold the mesh's whole shadow under `light`: the part of
    /// the mesh's bounding box above the plane, projected from the light onto it (a mesh's
    /// shadow lies in its box's, the hull of the corners' projections), with a margin of 5 % of
    /// that footprint — reaching at most [`MAX_SHADOW_REACH`] × the mesh's largest extent from
    /// its centre (a light level with the mesh's top casts a shadow without end). Where nothing
    /// can cast (the mesh or the light at or below the plane), the box of [`GroundGrid::around`].
    ///
    /// # Errors
    /// As [`GroundGrid::new`]; [`ShadowError::Light`] for an invalid light.
    pub fn around_shadow(
        positions: &[Vec3],
        light: &Light,
        y: f64,
        n: usize,
    ) -> Result<Self, ShadowError> {
        let base = Self::around(positions, y, n)?;
        let light = light.validated()?;
        let (mut lo, hi) = positions
            .iter()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p.as_dvec3()), hi.max(p.as_dvec3()))
            });
        let largest = (hi - lo).max_element();
        if positions.is_empty() || hi.y <= y || !largest.is_finite() || largest <= 0.0 {
            return Ok(base);
        }
        lo.y = lo.y.max(y);
        let centre = (lo + hi) / 2.0;
        let reach = MAX_SHADOW_REACH * largest;
        let (mut f_lo, mut f_hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for k in 0..8 {
            let c = DVec3::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            );
            let onto = match light {
                Light::Directional(d) if d.y > 0.0 => c - d * ((c.y - y) / d.y),
                Light::Point(l) if l.y > c.y => l + (c - l) * ((l.y - y) / (l.y - c.y)),
                // A corner level with or above a point light: its shadow runs to the horizon,
                // away from the light (everywhere, for a corner straight above it).
                Light::Point(l) if l.y > y => {
                    let away = DVec3::new(c.x - l.x, 0.0, c.z - l.z).normalize_or_zero();
                    if away == DVec3::ZERO {
                        let all = DVec3::new(reach, 0.0, reach);
                        (f_lo, f_hi) = (f_lo.min(centre - all), f_hi.max(centre + all));
                    }
                    c + away * (2.0 * reach)
                }
                _ => return Ok(base),
            };
            (f_lo, f_hi) = (f_lo.min(onto), f_hi.max(onto));
        }
        let margin = 0.05 * (f_hi - f_lo).max_element();
        let [x0, z0, x1, z1] = base.extent;
        let clamp = |v: f64, c: f64| v.clamp(c - reach, c + reach);
        let extent = [
            clamp((f_lo.x - margin).min(x0), centre.x),
            clamp((f_lo.z - margin).min(z0), centre.z),
            clamp((f_hi.x + margin).max(x1), centre.x),
            clamp((f_hi.z + margin).max(z1), centre.z),
        ];
        Self::new(y, extent, n)
    }

    /// World position of cell (i = column, j = row).
    pub fn cell_centre(&self, i: usize, j: usize) -> DVec3 {
        let [x0, z0, x1, z1] = self.extent;
        let f = |k: usize, a: f64, b: f64| a + (k as f64 + 0.5) * (b - a) / self.n as f64;
        DVec3::new(f(i, x0, x1), self.y, f(j, z0, z1))
    }

    /// Centre of the extent on the plane.
    pub fn centre(&self) -> DVec3 {
        let [x0, z0, x1, z1] = self.extent;
        DVec3::new((x0 + x1) / 2.0, self.y, (z0 + z1) / 2.0)
    }
}

/// The finite extrusion a ground mask needs: twice the diagonal of the box around the caster
/// and the ground's extent. A grid point in shadow lies on the ray from a caster point away
/// from the light, and both lie in that box, so every volume reaches past the plane wherever
/// the grid can see it, wherever the light is.
///
/// The light's position stays out of the box on purpose: a point light 1e7 away made the
/// volume 1e7 long, and its f32 vertices and the mask's depth range (which spans them) lost
/// the caster's scale — the mask emptied (the `a_distant_point_light` hard case).
pub fn ground_extrusion(positions: &[Vec3], grid: &GroundGrid) -> f64 {
    let [x0, z0, x1, z1] = grid.extent;
    let mut lo = DVec3::new(x0, grid.y, z0);
    let mut hi = DVec3::new(x1, grid.y, z1);
    for p in positions {
        lo = lo.min(p.as_dvec3());
        hi = hi.max(p.as_dvec3());
    }
    // The grid's extent is validated non-empty, so the box has a length (a floor of 1e-9 units
    // here made the volumes of a caster 10⁻²¹ across 10¹² times too long).
    2.0 * (hi - lo).length()
}

/// The exact mask of `grid` (row-major, N × N, 1 = the cell centre's segment to the light
/// meets a caster triangle, 0 = lit), by one ray per cell through occlusion-gpu's BVH.
///
/// Rays start a hair towards the light (occlusion-gpu's relative offset times the caster's
/// diagonal), so a caster face lying in the ground plane does not shadow the plane — the rule
/// the stencil path follows by pushing volumes back.
///
/// # Errors
/// [`ShadowError::Rays`] for a caster the BVH cannot take (no triangles, non-finite values);
/// [`ShadowError::Light`] for an invalid light.
pub fn exact_ground_mask(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    light: &Light,
    grid: &GroundGrid,
) -> Result<Vec<f32>, ShadowError> {
    let light = light.validated()?;
    let (caster, offset) = ray_caster(positions, triangles)?;
    let n = grid.n;
    let mut mask = vec![0.0f32; n * n];
    mask.par_chunks_mut(n).enumerate().for_each(|(j, row)| {
        let mut cache = Default::default();
        for (i, cell) in row.iter_mut().enumerate() {
            let p = grid.cell_centre(i, j);
            let towards = light.towards(p);
            let origin = p + towards * offset;
            let blocked = match light {
                Light::Point(l) => {
                    let d = l - origin;
                    d.dot(towards) > 0.0
                        && caster.occluded(caster.centred(origin), d.as_vec3(), 1.0, &mut cache)
                }
                Light::Directional(d) => caster.occluded(
                    caster.centred(origin),
                    d.as_vec3(),
                    f32::INFINITY,
                    &mut cache,
                ),
            };
            *cell = f32::from(u8::from(blocked));
        }
    });
    Ok(mask)
}

/// The BVH of a caster for exact rays (every triangle occludes, both faces), and the distance
/// a ray starts off its surface (occlusion-gpu's relative offset times the scene's diagonal).
pub(crate) fn ray_caster(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
) -> Result<(occlusion_gpu::RayCaster, f64), ShadowError> {
    let scene = occlusion_gpu::Scene::single(
        positions.to_vec(),
        vec![Vec3::Y; positions.len()],
        triangles.to_vec(),
    )?;
    let caster = occlusion_gpu::RayCaster::new(&scene)?;
    let offset = f64::from(occlusion_gpu::DEFAULT_OFFSET_RELATIVE * caster.diagonal());
    Ok((caster, offset))
}
