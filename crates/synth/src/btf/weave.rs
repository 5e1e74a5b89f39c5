//! The mesostructure: an analytic, tileable height field of a plain weave.
//!
//! Geometry, in tile units (the tile is the unit square, periodic in x and y):
//! * `N_w` warp yarns run along x; warp k has its axis at y_k = (k + ½)/N_w.
//! * `N_f` weft yarns run along y; weft m has its axis at x_m = (m + ½)/N_f.
//! * A yarn of family F has half-width `hw = width · pitch / 2` (pitch = 1/N_F), a
//!   half-ellipse cross-section of height `A = yarn_height · 2hw` and an axis that undulates
//!   by `U = crimp · A`: warp k at `U (−1)^k sin(π N_f x)`, weft m at
//!   `−U (−1)^m sin(π N_w y)`. At the crossing of warp k and weft m the warp is up (+U) and
//!   the weft down exactly when k + m is even: a plain weave, periodic because both counts
//!   are even.
//! * The surface of yarn k at distance d from its axis (|d| ≤ hw) is
//!   `z = axis(along) + A √(1 − (d/hw)²)`; the height field is the maximum of the yarns
//!   covering a point and the floor `z_floor = −z_top` (the gaps between yarns), where
//!   `z_top = max_F (U_F + A_F)` is the highest point of the tile.
//!
//! Every yarn height is a function of `along` plus a function of `across`, so the maximum
//! over an axis-aligned rectangle is the sum of two 1D maxima, computed exactly in
//! [`Weave::max_height_in_rect`]. The ray marcher uses it to skip empty space.

use super::Yarn;
use glam::Vec3;
use std::f32::consts::{FRAC_PI_2, PI, TAU};

/// Added to every rectangle bound so that f32 rounding of the yarn index and the sine never
/// makes the bound smaller than a height the point evaluation returns (tile units; heights
/// are ~0.1, their rounding error ~10⁻⁸).
const BOUND_MARGIN: f32 = 1e-6;

/// One family of parallel yarns (all warps or all wefts).
#[derive(Debug, Clone, Copy)]
struct Family {
    /// Yarns of this family across the tile (even).
    count: f32,
    /// π × yarns of the other family across the tile: the angular frequency of the
    /// undulation along the yarn.
    undulation_freq: f32,
    /// Half the yarn width, tile units.
    half_width: f32,
    /// Height A of the cross-section above its axis, tile units.
    amplitude: f32,
    /// Undulation amplitude U of the axis, tile units.
    crimp: f32,
    /// +1 for the warp (yarn 0 starts upwards), −1 for the weft.
    sign: f32,
}

/// A point on one yarn of a family.
#[derive(Debug, Clone, Copy)]
struct FamilyPoint {
    height: f32,
    /// Unwrapped yarn index (any integer; the yarn is `index mod count`).
    index: i64,
    /// Unnormalised normal in the family's (along, across, z) frame, multiplied by
    /// `√(1 − (d/hw)²)` so that it stays finite at the yarn's edge.
    normal: Vec3,
}

impl Family {
    /// Sign of the undulation of yarn `index`.
    #[inline]
    fn yarn_sign(&self, index: i64) -> f32 {
        if index & 1 == 0 {
            self.sign
        } else {
            -self.sign
        }
    }

    /// The yarn nearest to `across`, its distance over the half-width and its index.
    #[inline]
    fn nearest(&self, across: f32) -> (f32, i64) {
        let u = across * self.count - 0.5;
        let k = floor_i32(u + 0.5);
        (
            (u - k as f32) / (self.count * self.half_width),
            i64::from(k),
        )
    }

    /// Height of the yarn covering (along, across), if any.
    #[inline]
    fn height(&self, along: f32, across: f32) -> Option<f32> {
        let (t, k) = self.nearest(across);
        if t.abs() > 1.0 {
            return None;
        }
        let profile = (1.0 - t * t).max(0.0).sqrt();
        let axis = self.crimp * self.yarn_sign(k) * sin(self.undulation_freq * along);
        Some(axis + self.amplitude * profile)
    }

    /// Height and normal of the yarn covering (along, across), if any.
    fn point(&self, along: f32, across: f32) -> Option<FamilyPoint> {
        let (t, k) = self.nearest(across);
        if t.abs() > 1.0 {
            return None;
        }
        let q = (1.0 - t * t).max(0.0).sqrt();
        let s = self.yarn_sign(k);
        let phase = self.undulation_freq * along;
        let (sin, cos) = (sin(phase), sin(phase + FRAC_PI_2));
        let dh_dalong = self.crimp * s * self.undulation_freq * cos;
        // n ∝ (−∂h/∂along, −∂h/∂across, 1) · q with ∂h/∂across = −A t / (hw q).
        let normal = Vec3::new(-dh_dalong * q, self.amplitude * t / self.half_width, q);
        Some(FamilyPoint {
            height: self.crimp * s * sin + self.amplitude * q,
            index: k,
            normal,
        })
    }

    /// Largest height of this family's yarns over `along ∈ [a0, a1]`, `across ∈ [c0, c1]`
    /// (−∞ when no yarn reaches the rectangle). The yarns differ only in the sign of their
    /// undulation, so its range is computed once for both signs.
    #[inline]
    fn max_in_rect(&self, (a0, a1): (f32, f32), (c0, c1): (f32, f32)) -> f32 {
        let reach = self.half_width;
        // Every yarn whose strip can reach [c0, c1], and one more on each side for rounding.
        let first = floor_i32((c0 - reach) * self.count - 0.5);
        let last = floor_i32((c1 + reach) * self.count - 0.5) + 1;
        // The largest cross-section height reached, per undulation sign (+, −).
        let mut profile = [f32::NEG_INFINITY; 2];
        for k in first..=last {
            let axis = (k as f32 + 0.5) / self.count;
            let d = (c0 - axis).max(axis - c1).max(0.0);
            let t = d / reach;
            if t <= 1.0 {
                let slot = usize::from(self.yarn_sign(i64::from(k)) < 0.0);
                profile[slot] = profile[slot].max(self.amplitude * (1.0 - t * t).max(0.0).sqrt());
            }
        }
        if profile == [f32::NEG_INFINITY; 2] {
            return f32::NEG_INFINITY;
        }
        let (low, high) = sin_range(self.undulation_freq * a0, self.undulation_freq * a1);
        (profile[0] + self.crimp * high).max(profile[1] - self.crimp * low)
    }
}

/// (min, max) of [`sin`] t over t ∈ [a, b] (a ≤ b).
#[inline]
fn sin_range(a: f32, b: f32) -> (f32, f32) {
    if b - a >= TAU {
        return (-1.0, 1.0);
    }
    // Whether the first extremum `at + 2πn` at or after a is at or before b.
    let reaches = |at: f32| at + TAU * -floor_i32((at - a) / TAU) as f32 <= b;
    let (sa, sb) = (sin(a), sin(b));
    let high = if reaches(FRAC_PI_2) { 1.0 } else { sa.max(sb) };
    let low = if reaches(-FRAC_PI_2) {
        -1.0
    } else {
        sa.min(sb)
    };
    (low, high)
}

/// ⌊x⌋ for |x| < 2³¹, without the library call `f32::floor` becomes on x86-64 targets
/// without SSE4.1 (it showed up at 4% of a BTF's time).
#[inline]
pub(crate) fn floor_i32(x: f32) -> i32 {
    let t = x as i32;
    t - i32::from(x < t as f32)
}

/// sin x, absolute error < 3·10⁻⁷ for |x| < 10⁴ (tested; the marcher's phases stay below
/// 5·10³), growing in proportion to |x| beyond, where the f32 argument itself is already
/// that uncertain:
/// reduction to r = x − kπ ∈ [−π/2, π/2] in two steps (π = PI_HEAD + PI_TAIL, PI_HEAD with
/// 8 significant bits so that k·PI_HEAD is exact), then the Taylor polynomial of degree 11
/// (remainder ≤ (π/2)¹³/13! < 6·10⁻⁸). Replaces `f32::sin`, a library call that was 5% of
/// a BTF's time; deterministic on every platform.
#[inline]
fn sin(x: f32) -> f32 {
    const PI_HEAD: f32 = 3.140625;
    const PI_TAIL: f32 = 9.676_536e-4;
    let k = floor_i32(x * std::f32::consts::FRAC_1_PI + 0.5);
    let kf = k as f32;
    let r = (x - kf * PI_HEAD) - kf * PI_TAIL;
    let r2 = r * r;
    let p = r
        * (1.0
            + r2 * (-1.0 / 6.0
                + r2 * (1.0 / 120.0
                    + r2 * (-1.0 / 5040.0 + r2 * (1.0 / 362_880.0 + r2 * (-1.0 / 39_916_800.0))))));
    if k & 1 == 0 { p } else { -p }
}

/// Shape of the weave, derived once from the parameters.
#[derive(Debug, Clone)]
pub(crate) struct Weave {
    warp: Family,
    weft: Family,
    warp_count: u32,
    weft_count: u32,
    /// Height of the floor between the yarns.
    pub(crate) z_floor: f32,
    /// The highest point of the tile: the registration plane z_ref.
    pub(crate) z_top: f32,
}

/// A point of the surface.
#[derive(Debug, Clone, Copy)]
pub(crate) struct WeavePoint {
    pub(crate) height: f32,
    pub(crate) normal: Vec3,
    pub(crate) yarn: Yarn,
}

impl Weave {
    /// The weave of `warp_count × weft_count` yarns (both even, validated by the caller);
    /// `width` is the fraction of the pitch a yarn covers, `height` the cross-section height
    /// over the yarn width, `crimp` the undulation over the cross-section height.
    pub(crate) fn new(
        warp_count: u32,
        weft_count: u32,
        width: f32,
        height: f32,
        crimp: f32,
    ) -> Self {
        let family = |count: u32, other: u32, sign: f32| {
            let half_width = 0.5 * width / count as f32;
            let amplitude = height * 2.0 * half_width;
            Family {
                count: count as f32,
                undulation_freq: PI * other as f32,
                half_width,
                amplitude,
                crimp: crimp * amplitude,
                sign,
            }
        };
        let warp = family(warp_count, weft_count, 1.0);
        let weft = family(weft_count, warp_count, -1.0);
        let z_top = (warp.crimp + warp.amplitude).max(weft.crimp + weft.amplitude);
        Self {
            warp,
            weft,
            warp_count,
            weft_count,
            z_floor: -z_top,
            z_top,
        }
    }

    /// The smaller of the two yarn half-widths (tile units), the finest feature.
    pub(crate) fn min_half_width(&self) -> f32 {
        self.warp.half_width.min(self.weft.half_width)
    }

    /// Height of the surface at (x, y) (any real coordinates; the tile repeats).
    #[inline]
    pub(crate) fn height(&self, x: f32, y: f32) -> f32 {
        let warp = self.warp.height(x, y).unwrap_or(f32::NEG_INFINITY);
        let weft = self.weft.height(y, x).unwrap_or(f32::NEG_INFINITY);
        warp.max(weft).max(self.z_floor)
    }

    /// Height, unit normal and yarn at (x, y). Where a warp and a weft have equal height
    /// the warp wins; the floor only where no yarn covers the point.
    pub(crate) fn point(&self, x: f32, y: f32) -> WeavePoint {
        let warp = self.warp.point(x, y);
        let weft = self.weft.point(y, x);
        let warp_height = warp.map_or(f32::NEG_INFINITY, |p| p.height);
        let weft_height = weft.map_or(f32::NEG_INFINITY, |p| p.height);
        let floor = WeavePoint {
            height: self.z_floor,
            normal: Vec3::Z,
            yarn: Yarn::Gap,
        };
        let best = warp_height.max(weft_height);
        if best < self.z_floor {
            return floor;
        }
        if let Some(p) = warp.filter(|_| warp_height >= weft_height) {
            // Family frame (along, across, z) = (x, y, z).
            WeavePoint {
                height: p.height,
                normal: p.normal.normalize(),
                yarn: Yarn::Warp(p.index.rem_euclid(i64::from(self.warp_count)) as u32),
            }
        } else if let Some(p) = weft {
            // Family frame (along, across, z) = (y, x, z).
            WeavePoint {
                height: p.height,
                normal: Vec3::new(p.normal.y, p.normal.x, p.normal.z).normalize(),
                yarn: Yarn::Weft(p.index.rem_euclid(i64::from(self.weft_count)) as u32),
            }
        } else {
            floor
        }
    }

    /// An upper bound (exact up to [`BOUND_MARGIN`]) of the height over the rectangle
    /// `[x0, x1] × [y0, y1]` (x0 ≤ x1, y0 ≤ y1, any real coordinates).
    #[inline]
    pub(crate) fn max_height_in_rect(&self, x: (f32, f32), y: (f32, f32)) -> f32 {
        let warp = self.warp.max_in_rect(x, y);
        let weft = self.weft.max_in_rect(y, x);
        warp.max(weft).max(self.z_floor) + BOUND_MARGIN
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SplitMix64;

    fn default_weave() -> Weave {
        Weave::new(4, 6, 0.8, 0.3, 0.6)
    }

    #[test]
    fn fast_sin_and_floor_are_accurate() {
        let mut rng = SplitMix64::new(1);
        for _ in 0..100_000 {
            let x = 1.0e4 * rng.next_signed();
            let error = (f64::from(sin(x)) - f64::from(x).sin()).abs();
            assert!(error < 3e-7, "sin({x}) off by {error}");
            assert_eq!(floor_i32(x), x.floor() as i32, "floor({x})");
            let small = rng.next_signed();
            assert_eq!(floor_i32(small), small.floor() as i32, "floor({small})");
        }
        for x in [-2.0f32, -1.0, -0.0, 0.0, 1.0, 7.0] {
            assert_eq!(floor_i32(x), x as i32);
        }
    }

    #[test]
    fn sin_range_matches_dense_sampling() {
        let mut rng = SplitMix64::new(3);
        for _ in 0..2000 {
            let a = 20.0 * rng.next_signed();
            let b = a + 8.0 * rng.next_f32();
            let samples = (0..=4000).map(|i| sin(a + (b - a) * i as f32 / 4000.0));
            let high = samples.clone().fold(f32::NEG_INFINITY, f32::max);
            let low = samples.fold(f32::INFINITY, f32::min);
            let (lo, hi) = sin_range(a, b);
            assert!(
                hi >= high - 1e-6 && hi <= high + 1e-5,
                "[{a}, {b}]: max {hi} vs {high}"
            );
            assert!(
                lo <= low + 1e-6 && lo >= low - 1e-5,
                "[{a}, {b}]: min {lo} vs {low}"
            );
        }
    }

    #[test]
    fn rect_bound_is_tight_and_conservative() {
        let weave = default_weave();
        let mut rng = SplitMix64::new(11);
        for _ in 0..500 {
            let x0 = 3.0 * rng.next_signed();
            let y0 = 3.0 * rng.next_signed();
            let (w, h) = (0.05 * rng.next_f32(), 0.05 * rng.next_f32());
            let bound = weave.max_height_in_rect((x0, x0 + w), (y0, y0 + h));
            let n = 64;
            let mut dense = f32::NEG_INFINITY;
            for i in 0..=n {
                for j in 0..=n {
                    let x = x0 + w * i as f32 / n as f32;
                    let y = y0 + h * j as f32 / n as f32;
                    dense = dense.max(weave.height(x, y));
                }
            }
            assert!(bound >= dense, "bound {bound} below sampled max {dense}");
            // Tight: the sampled maximum converges to the bound (grid error only).
            assert!(bound - dense < 5e-3, "bound {bound} far above {dense}");
        }
    }

    #[test]
    fn point_normal_matches_finite_differences() {
        let weave = default_weave();
        let mut rng = SplitMix64::new(5);
        let eps = 1e-4;
        let mut checked = 0;
        for _ in 0..2000 {
            let (x, y) = (rng.next_f32(), rng.next_f32());
            let p = weave.point(x, y);
            // Stay away from yarn edges and creases, where the height is not differentiable.
            let around = [(eps, 0.0), (-eps, 0.0), (0.0, eps), (0.0, -eps)]
                .map(|(dx, dy)| weave.point(x + dx, y + dy));
            if around.iter().any(|q| q.yarn != p.yarn) || p.normal.z < 0.3 {
                continue;
            }
            let hx = (around[0].height - around[1].height) / (2.0 * eps);
            let hy = (around[2].height - around[3].height) / (2.0 * eps);
            let fd = Vec3::new(-hx, -hy, 1.0).normalize();
            assert!(fd.dot(p.normal) > 0.999, "({x}, {y}): {fd} vs {}", p.normal);
            assert!((weave.height(x, y) - p.height).abs() < 1e-7);
            checked += 1;
        }
        assert!(checked > 1000, "only {checked} smooth points");
    }
}
