//! Self-shadowing: the fibre cloud as a 3-D extinction grid, periodic in y, marched
//! towards the light (see "Self-shadowing" in the [module documentation](super)).

use super::strands::Segment;
use glam::Vec3;
use std::f32::consts::FRAC_PI_4;

/// Strands are dealt into this many groups by index; a point on a strand of group g is
/// shadowed by the other groups only, scaled by `GROUPS / (GROUPS − 1)`, so that a fibre
/// never shadows itself through its own blurred density.
pub(super) const GROUPS: usize = 4;
/// Target cell size in pixel widths.
const CELL_PX: f32 = 2.0;
/// Fewest cells across the unit period in y.
const MIN_CELLS: usize = 4;
/// Most cells along any axis (the grids then hold 4 × 128³ values, 32 MiB).
const MAX_CELLS: usize = 128;
/// Most density splats per segment (a segment is splatted every half cell).
const MAX_SPLATS_PER_SEGMENT: usize = 256;
/// Empty cells padded on each side in x and z of the marched grids.
const PAD: usize = 2;
/// Most steps of one shadow march; the integral ends there.
pub(super) const MAX_MARCH_STEPS: usize = 4096;
/// A march stops once the optical depth exceeds this (transmittance < 10⁻¹³).
const OPAQUE_DEPTH: f32 = 30.0;

/// The extinction coefficient of the fibre cloud (per material unit of path) on a regular
/// grid, trilinearly interpolated between cell centres; zero outside the grid in x and z,
/// periodic in y with period 1.
#[derive(Debug, Clone)]
pub(super) struct DensityGrid {
    /// x of the grid's low face; cell i's centre is at `origin_x + (i + ½)·cell.x`.
    origin_x: f32,
    /// Cell size along x, y, z (material units).
    cell: Vec3,
    inv_cell: Vec3,
    /// Cells along x, y, z.
    dims: [usize; 3],
    /// 1 / (cells along y).
    inv_ny: f32,
    /// March step: the smallest cell side.
    step: f32,
    /// Per strand group, the extinction of the other groups' fibres times
    /// `GROUPS / (GROUPS − 1)`, padded: node (i, j, k) at index
    /// `((k + PAD)·(ny + 1) + j)·(nx + 2·PAD) + i + PAD`, row j = ny repeating row 0.
    excluding: Vec<Vec<f32>>,
}

/// Integer cell below `coordinate` and the weight of the next one, for nodes at cell
/// centres.
#[inline]
fn axis(coordinate: f32, origin: f32, inv_cell: f32) -> (i64, f32) {
    let f = (coordinate - origin) * inv_cell - 0.5;
    let floor = f.floor();
    (floor as i64, f - floor)
}

impl DensityGrid {
    /// Builds the grid from the segments of an image `width` pixels wide (one material
    /// unit), splatting every segment's projected area every half cell.
    pub(super) fn new(segments: &[Segment], width: usize) -> Self {
        let ny = ((width as f32 / CELL_PX).round() as usize).clamp(MIN_CELLS, MAX_CELLS);
        let hy = 1.0 / ny as f32;
        let (mut x_low, mut x_high, mut z_high) = (f32::INFINITY, f32::NEG_INFINITY, 0.0f32);
        for segment in segments {
            let radius = segment.max_radius();
            let b = segment.a + segment.d;
            x_low = x_low.min(segment.a.x.min(b.x) - radius);
            x_high = x_high.max(segment.a.x.max(b.x) + radius);
            z_high = z_high.max(segment.a.z.max(b.z) + radius);
        }
        if segments.is_empty() {
            (x_low, x_high) = (0.0, 0.0);
        }
        let x_extent = (x_high - x_low).max(hy);
        let nx = ((x_extent / hy).ceil() as usize).clamp(1, MAX_CELLS);
        let z_extent = z_high.max(hy);
        let nz = ((z_extent / hy).ceil() as usize).clamp(1, MAX_CELLS);
        let cell = Vec3::new(x_extent / nx as f32, hy, z_extent / nz as f32);
        let mut grid = Self {
            origin_x: x_low,
            cell,
            inv_cell: cell.recip(),
            dims: [nx, ny, nz],
            inv_ny: 1.0 / ny as f32,
            step: cell.min_element(),
            excluding: Vec::new(),
        };

        let cells = nx * ny * nz;
        let mut groups = vec![vec![0.0f32; cells]; GROUPS];
        let volume = cell.x * cell.y * cell.z;
        for segment in segments {
            let length = segment.d.length();
            if length == 0.0 {
                continue;
            }
            let splats =
                ((length / (0.5 * grid.step)).ceil() as usize).clamp(1, MAX_SPLATS_PER_SEGMENT);
            let ds = length / splats as f32;
            let group = &mut groups[segment.strand as usize % GROUPS];
            for j in 0..splats {
                let t = (j as f32 + 0.5) / splats as f32;
                let radius = segment.radius_a + t * (segment.radius_b - segment.radius_a);
                // Mean projected area of a cylinder piece over isotropic directions:
                // 2r·ds·⟨sin⟩ = 2r·ds·π/4.
                let weight = FRAC_PI_4 * 2.0 * radius * ds / volume;
                grid.for_each_node(segment.a + t * segment.d, |index, w| {
                    group[index] += w * weight;
                });
            }
        }
        // Padded copies for the march: two empty cells on each side in x and z and row 0
        // repeated after the last row in y, so that a sample needs no bounds checks.
        let scale = GROUPS as f32 / (GROUPS - 1) as f32;
        let (px, py, pz) = (nx + 2 * PAD, ny + 1, nz + 2 * PAD);
        grid.excluding = (0..GROUPS)
            .map(|g| {
                let mut padded = vec![0.0f32; px * py * pz];
                for k in 0..nz {
                    for j in 0..=ny {
                        let source = (k * ny + j % ny) * nx;
                        let target = ((k + PAD) * py + j) * px + PAD;
                        for i in 0..nx {
                            let others: f32 = (0..GROUPS)
                                .filter(|&h| h != g)
                                .map(|h| groups[h][source + i])
                                .sum();
                            padded[target + i] = scale * others;
                        }
                    }
                }
                padded
            })
            .collect();
        grid
    }

    /// Calls `f(index, weight)` for the (up to 8) grid nodes of the trilinear kernel at `p`.
    #[inline]
    fn for_each_node(&self, p: Vec3, mut f: impl FnMut(usize, f32)) {
        let [nx, ny, nz] = self.dims;
        let (ix, fx) = axis(p.x, self.origin_x, self.inv_cell.x);
        let (iy, fy) = axis(p.y, 0.0, self.inv_cell.y);
        let (iz, fz) = axis(p.z, 0.0, self.inv_cell.z);
        for (k, wz) in [(iz, 1.0 - fz), (iz + 1, fz)] {
            if k < 0 || k >= nz as i64 {
                continue;
            }
            for (j, wy) in [(iy, 1.0 - fy), (iy + 1, fy)] {
                let j = j.rem_euclid(ny as i64) as usize;
                let row = (k as usize * ny + j) * nx;
                for (i, wx) in [(ix, 1.0 - fx), (ix + 1, fx)] {
                    if i >= 0 && i < nx as i64 {
                        f(row + i as usize, wz * wy * wx);
                    }
                }
            }
        }
    }

    /// The extinction coefficient at `p` as seen from a strand of `group`, from the padded
    /// grids (the same trilinear kernel as [`for_each_node`](Self::for_each_node)).
    #[inline]
    fn extinction(&self, group: usize, p: Vec3) -> f32 {
        let [nx, ny, nz] = self.dims;
        let grid = &self.excluding[group];
        // Beyond the grid every node is empty; clamping there keeps both nodes of the kernel
        // in the padding (cells −2, −1 or nx, nx + 1), so the value stays 0.
        let pad = PAD as f32;
        // Shifted by PAD so that the floor is a truncating cast (`f32::floor` is a library
        // call on the baseline x86-64 target and made the march twice as slow).
        let fx =
            ((p.x - self.origin_x) * self.inv_cell.x - 0.5 + pad).clamp(0.0, (nx + PAD) as f32);
        let fz = (p.z * self.inv_cell.z - 0.5 + pad).clamp(0.0, (nz + PAD) as f32);
        let fy = p.y * self.inv_cell.y - 0.5;
        // Wrapped into [0, ny) (rounding can land on either end).
        let turns = fy * self.inv_ny;
        let mut whole = turns as i64 as f32;
        if whole > turns {
            whole -= 1.0;
        }
        let fy = (fy - ny as f32 * whole).max(0.0);
        let fy = if fy >= ny as f32 { fy - ny as f32 } else { fy };
        let (i, j, k) = (fx as usize, fy as usize, fz as usize);
        let (wx, wy, wz) = (fx - i as f32, fy - j as f32, fz - k as f32);
        let j = j.min(ny - 1);
        let (px, py) = (nx + 2 * PAD, ny + 1);
        let base = (k * py + j) * px + i;
        let (sy, sz) = (px, px * py);
        let lerp = |a: f32, b: f32, w: f32| a + w * (b - a);
        let at = |offset: usize| lerp(grid[base + offset], grid[base + offset + 1], wx);
        lerp(lerp(at(0), at(sy), wy), lerp(at(sz), at(sz + sy), wy), wz)
    }

    /// Transmittance `exp(−σ ∫ extinction ds)` from `p` (on a strand of group
    /// `strand % GROUPS`) along the unit direction `light` (`light.z > 0`) until the ray
    /// leaves the grid, by the midpoint rule with a step of one (smallest) cell side. At
    /// most [`MAX_MARCH_STEPS`] steps; stops early once the transmittance is below 10⁻¹³.
    pub(super) fn transmittance(&self, p: Vec3, light: Vec3, strand: u32, sigma: f32) -> f32 {
        if sigma == 0.0 {
            return 1.0;
        }
        let [nx, _, nz] = self.dims;
        // The kernel of the last node reaches half a cell past the grid.
        let z_top = (nz as f32 + 0.5) * self.cell.z;
        let x_low = self.origin_x - 0.5 * self.cell.x;
        let x_high = self.origin_x + (nx as f32 + 0.5) * self.cell.x;
        let mut end = (z_top - p.z) / light.z;
        if light.x > 0.0 {
            end = end.min((x_high - p.x) / light.x);
        } else if light.x < 0.0 {
            end = end.min((x_low - p.x) / light.x);
        }
        if end.is_nan() || end <= 0.0 {
            return 1.0;
        }
        let steps = ((end / self.step).ceil() as usize).min(MAX_MARCH_STEPS);
        let group = strand as usize % GROUPS;
        let limit = OPAQUE_DEPTH / (sigma * self.step);
        let mut sum = 0.0;
        for k in 0..steps {
            sum += self.extinction(group, p + light * ((k as f32 + 0.5) * self.step));
            if sum > limit {
                break;
            }
        }
        (-sigma * self.step * sum).exp()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fins::{WoolFinParams, strands};
    use crate::rng::SplitMix64;

    #[test]
    fn the_padded_look_up_is_the_trilinear_kernel() {
        let params = WoolFinParams {
            width: 40,
            height: 50,
            strands: 120,
            ..Default::default()
        };
        let segments = strands::segments(&strands::generate(&params));
        let grid = DensityGrid::new(&segments, params.width);
        let [nx, ny, nz] = grid.dims;
        assert!(nx > 4 && ny == 20 && nz > 4, "{:?}", grid.dims);
        let node = |g: usize, index: usize| {
            let (i, rest) = (index % nx, index / nx);
            let (j, k) = (rest % ny, rest / ny);
            grid.excluding[g][((k + PAD) * (ny + 1) + j) * (nx + 2 * PAD) + i + PAD]
        };
        let mut rng = SplitMix64::new(3);
        let (mut points, mut positive) = (0, 0);
        for _ in 0..20_000 {
            // Points well beyond the grid on every side, and over several periods in y.
            let p = Vec3::new(
                grid.origin_x - 0.2 + (nx as f32 * grid.cell.x + 0.4) * rng.next_f32(),
                3.0 * rng.next_signed(),
                -0.1 + (nz as f32 * grid.cell.z + 0.2) * rng.next_f32(),
            );
            for g in 0..GROUPS {
                let mut expected = 0.0;
                grid.for_each_node(p, |index, w| expected += w * node(g, index));
                let got = grid.extinction(g, p);
                assert!(
                    (got - expected).abs() <= 1e-4 * (1.0 + expected),
                    "{p} group {g}: {got} vs {expected}"
                );
                if expected > 0.0 {
                    positive += 1;
                }
            }
            points += 1;
        }
        assert!(positive > points, "{positive} of {points}");
        // The groups exclude different strands.
        assert_ne!(grid.excluding[0], grid.excluding[1]);
    }

    #[test]
    fn an_empty_grid_lets_all_light_through() {
        let grid = DensityGrid::new(&[], 64);
        let light = Vec3::new(0.3, 0.2, 0.9).normalize();
        assert_eq!(
            grid.transmittance(Vec3::new(0.0, 0.5, 0.1), light, 0, 5.0),
            1.0
        );
    }
}
