//! The measured directions of a UBO2003 BTF and the interpolation between them
//! (thesis §5.3.2, Table 5.1; §5.5, eqs. 5.3 and 5.5).
//!
//! Both samplings put 81 directions on the upper hemisphere in six rings of constant θ with
//! 1, 6, 12, 18, 20 and 24 directions (Δφ = –, 60°, 30°, 20°, 18°, 15°); H1 has its rings at
//! θ = 0°, 17°, 34°, 51°, 68°, 85°, H2 at θ = 0°, 15°, 30°, 45°, 60°, 75°. In each ring φ starts
//! at 0°. Directions live in the local tangent frame: z is the surface normal, x the tangent,
//! y the bitangent; θ is measured from +z, φ from +x toward +y. Direction indices run ring by
//! ring, φ ascending: index 0 is the pole, 1..7 the 6 directions at θ₁, and so on.
//!
//! Interpolation ("the four nearest measured directions … for bilinear interpolation with the
//! interpolation weights τ_m", §5.5): θ is bracketed between two rings, each ring contributes
//! its two φ neighbours with weights linear in φ (wrapping at 360°), and the two rings are
//! blended linearly in θ. The thesis leaves the edges open; we decide them as follows and test
//! each in `tests/hard_cases.rs`:
//!
//! * **Pole.** The θ = 0 ring has a single direction, so both its φ neighbours are index 0 and
//!   its weights merge. θ = 0 (φ undefined) gives index 0 with weight 1, never NaN.
//! * **Measured directions.** A direction within [`ANGLE_SNAP_DEG`] of a measured one collapses
//!   to that direction with weight 1 (the other three weights are 0).
//! * **Light near the horizon.** The normtextures include the cosine falloff of irradiance, so
//!   radiance tends to 0 at grazing light. Between the last ring's θ and 90° the last ring's
//!   weights fade linearly to 0; at and below the horizon every weight is 0.
//! * **View near the horizon.** A view slot must always be chosen, so views at or beyond the
//!   last ring are clamped to it; view weights (ω_m, eq. 5.5) always sum to 1.

use glam::Vec3;

/// Number of measured directions of either sampling (Table 5.1: 1+6+12+18+20+24).
pub const DIRECTIONS: usize = 81;

/// Number of rings of constant θ.
pub const RINGS: usize = 6;

/// Directions per ring (Table 5.1, "No. of images").
const RING_COUNT: [usize; RINGS] = [1, 6, 12, 18, 20, 24];
/// Index of the first direction of each ring.
const RING_START: [usize; RINGS] = [0, 1, 7, 19, 37, 57];
/// θ of the rings of H1, degrees.
const THETA_H1: [u32; RINGS] = [0, 17, 34, 51, 68, 85];
/// θ of the rings of H2, degrees.
const THETA_H2: [u32; RINGS] = [0, 15, 30, 45, 60, 75];

/// A direction closer than this (in degrees of θ, and of arc along φ per unit Δφ) to a measured
/// ring or φ is snapped onto it. Tuned on f32 round trips: `vector(i)` converted back to angles
/// lands within 2·10⁻⁵° of the measured angles, so 10⁻³° collapses every measured direction
/// while moving no other direction by more than 0.001° (invisible next to Δφ ≥ 15°).
pub const ANGLE_SNAP_DEG: f64 = 1e-3;

/// One of the two direction samplings of the Bonn BTF database (thesis Table 5.1).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Sampling {
    /// Rings at θ = 0°, 17°, 34°, 51°, 68°, 85°.
    H1,
    /// Rings at θ = 0°, 15°, 30°, 45°, 60°, 75°.
    H2,
}

/// Up to four measured directions and their interpolation weights (τ_m of eq. 5.3 or ω_m of
/// eq. 5.5).
///
/// Entries with a non-zero weight come first, sorted by descending weight (ties by index);
/// unused entries have weight 0 and repeat the first index (0 when all weights are 0), so the
/// struct can be uploaded to a GPU as it is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Weights4 {
    /// Direction indices (0..81).
    pub indices: [usize; 4],
    /// Weights, ≥ 0.
    pub weights: [f32; 4],
}

impl Weights4 {
    /// No direction: every weight 0 (a light below the horizon).
    pub const ZERO: Self = Self {
        indices: [0; 4],
        weights: [0.0; 4],
    };

    /// The entries with a non-zero weight, as (direction index, weight).
    pub fn iter(&self) -> impl Iterator<Item = (usize, f32)> + '_ {
        self.indices
            .iter()
            .zip(&self.weights)
            .filter(|(_, w)| **w != 0.0)
            .map(|(i, w)| (*i, *w))
    }

    /// Number of entries with a non-zero weight (0 to 4).
    pub fn len(&self) -> usize {
        self.weights.iter().filter(|w| **w != 0.0).count()
    }

    /// True when every weight is 0.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Σ weights.
    pub fn sum(&self) -> f32 {
        self.weights.iter().sum()
    }

    /// Merges duplicate indices, drops zero weights, sorts and pads.
    fn from_entries(entries: &[(usize, f64)]) -> Self {
        let mut merged: Vec<(usize, f64)> = Vec::with_capacity(4);
        for &(i, w) in entries {
            if w <= 0.0 {
                continue;
            }
            match merged.iter_mut().find(|(j, _)| *j == i) {
                Some((_, acc)) => *acc += w,
                None => merged.push((i, w)),
            }
        }
        merged.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
        let mut out = Self::ZERO;
        let first = merged.first().map_or(0, |e| e.0);
        out.indices = [first; 4];
        for (k, (i, w)) in merged.into_iter().enumerate() {
            out.indices[k] = i;
            out.weights[k] = w as f32;
        }
        out
    }
}

/// What to do beyond the last ring.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Horizon {
    /// Fade to 0 at θ = 90°, 0 below (light).
    Fade,
    /// Clamp to the last ring (view).
    Clamp,
}

impl Sampling {
    /// Both samplings.
    pub const ALL: [Sampling; 2] = [Sampling::H1, Sampling::H2];

    /// "H1" or "H2".
    pub fn name(self) -> &'static str {
        match self {
            Self::H1 => "H1",
            Self::H2 => "H2",
        }
    }

    /// θ of the six rings in degrees (Table 5.1).
    pub fn ring_thetas(self) -> [u32; RINGS] {
        match self {
            Self::H1 => THETA_H1,
            Self::H2 => THETA_H2,
        }
    }

    /// Number of directions in each ring: 1, 6, 12, 18, 20, 24.
    pub fn ring_counts(self) -> [usize; RINGS] {
        RING_COUNT
    }

    /// The ring of direction `i`.
    ///
    /// # Panics
    /// If `i ≥ 81`.
    pub fn ring_of(self, i: usize) -> usize {
        assert!(i < DIRECTIONS, "direction index {i} ≥ {DIRECTIONS}");
        RING_START.iter().rposition(|&s| s <= i).unwrap_or(0)
    }

    /// (θ, φ) of direction `i` in integer degrees.
    ///
    /// # Panics
    /// If `i ≥ 81`.
    pub fn dir_deg_u32(self, i: usize) -> (u32, u32) {
        let r = self.ring_of(i);
        let k = i - RING_START[r];
        let dphi = 360 / RING_COUNT[r] as u32;
        (self.ring_thetas()[r], k as u32 * dphi)
    }

    /// (θ, φ) of direction `i` in degrees: θ from the normal (+z), φ from the tangent (+x)
    /// toward the bitangent (+y).
    ///
    /// # Panics
    /// If `i ≥ 81`.
    pub fn dir(self, i: usize) -> (f32, f32) {
        let (t, p) = self.dir_deg_u32(i);
        (t as f32, p as f32)
    }

    /// Direction `i` as a unit vector in the tangent frame.
    ///
    /// # Panics
    /// If `i ≥ 81`.
    pub fn vector(self, i: usize) -> Vec3 {
        let (t, p) = self.dir_deg_u32(i);
        let (t, p) = (f64::from(t).to_radians(), f64::from(p).to_radians());
        Vec3::new(
            (t.sin() * p.cos()) as f32,
            (t.sin() * p.sin()) as f32,
            t.cos() as f32,
        )
    }

    /// All 81 directions as unit vectors, in index order.
    pub fn directions(self) -> Vec<Vec3> {
        (0..DIRECTIONS).map(|i| self.vector(i)).collect()
    }

    /// The index of the measured direction (θ, φ) given in integer degrees, if there is one
    /// (φ is taken modulo 360; at the pole only φ = 0 is measured).
    pub fn index_of(self, theta_deg: u32, phi_deg: u32) -> Option<usize> {
        let r = self.ring_thetas().iter().position(|&t| t == theta_deg)?;
        let phi = phi_deg % 360;
        let dphi = 360 / RING_COUNT[r] as u32;
        phi.is_multiple_of(dphi)
            .then(|| RING_START[r] + (phi / dphi) as usize)
    }

    /// The four nearest measured light directions and their bilinear weights τ_m (eq. 5.3)
    /// for a light direction in the tangent frame (need not be unit length).
    ///
    /// The weights sum to 1 for θ up to the last ring, fade linearly to 0 between the last
    /// ring and the horizon (the normtextures include the cosine falloff of irradiance), and
    /// are all 0 at or below the horizon and for a zero or non-finite direction. See the module
    /// docs for the pole and for measured directions.
    ///
    /// # Examples
    /// ```
    /// use btf::Sampling;
    /// let w = Sampling::H1.light_weights(Sampling::H1.vector(12));
    /// assert_eq!((w.indices[0], w.weights[0], w.len()), (12, 1.0, 1));
    /// assert!(Sampling::H1.light_weights(glam::Vec3::new(1.0, 0.0, -0.1)).is_empty());
    /// ```
    pub fn light_weights(self, dir_in_tangent: Vec3) -> Weights4 {
        match angles(dir_in_tangent) {
            Some((theta, phi)) => self.weights_deg(theta, phi, Horizon::Fade),
            None => Weights4::ZERO,
        }
    }

    /// [`Sampling::light_weights`] for a direction given as (θ, φ) in degrees (φ any real,
    /// taken modulo 360°). θ ≥ 90° or a non-finite angle gives all weights 0.
    pub fn light_weights_deg(self, theta_deg: f64, phi_deg: f64) -> Weights4 {
        if !theta_deg.is_finite() || !phi_deg.is_finite() {
            return Weights4::ZERO;
        }
        self.weights_deg(theta_deg.abs(), phi_deg, Horizon::Fade)
    }

    /// The four nearest view slots and their bilinear weights ω_m (eq. 5.5) for a view
    /// direction in the tangent frame. Views at or below the last ring (including the horizon
    /// and below it) are clamped to the last ring, so the weights always sum to 1; a zero or
    /// non-finite direction counts as the normal (slot 0).
    ///
    /// # Examples
    /// ```
    /// use btf::Sampling;
    /// let w = Sampling::H2.view_weights(glam::Vec3::Z);
    /// assert_eq!((w.indices[0], w.weights[0]), (0, 1.0));
    /// let grazing = Sampling::H2.view_weights(glam::Vec3::new(1.0, 0.0, -0.5));
    /// assert!((grazing.sum() - 1.0).abs() < 1e-6);
    /// ```
    pub fn view_weights(self, dir_in_tangent: Vec3) -> Weights4 {
        let (theta, phi) = angles(dir_in_tangent).unwrap_or((0.0, 0.0));
        self.weights_deg(theta, phi, Horizon::Clamp)
    }

    /// [`Sampling::view_weights`] for a direction given as (θ, φ) in degrees; a non-finite
    /// angle counts as the normal.
    pub fn view_weights_deg(self, theta_deg: f64, phi_deg: f64) -> Weights4 {
        if !theta_deg.is_finite() || !phi_deg.is_finite() {
            return self.weights_deg(0.0, 0.0, Horizon::Clamp);
        }
        self.weights_deg(theta_deg.abs(), phi_deg, Horizon::Clamp)
    }

    /// Bilinear weights for θ ≥ 0 and finite φ, both in degrees.
    fn weights_deg(self, theta: f64, phi: f64, horizon: Horizon) -> Weights4 {
        let thetas = self.ring_thetas().map(f64::from);
        let last = RINGS - 1;
        // Beyond the last ring: the last ring alone, faded (light) or not (view).
        let mut fade = 1.0;
        let mut theta = theta;
        if theta >= thetas[last] - ANGLE_SNAP_DEG {
            if horizon == Horizon::Fade {
                if theta >= 90.0 {
                    return Weights4::ZERO;
                }
                if theta > thetas[last] + ANGLE_SNAP_DEG {
                    fade = (90.0 - theta) / (90.0 - thetas[last]);
                }
            }
            theta = thetas[last];
        }
        // Bracket θ: thetas[r] ≤ θ < thetas[r + 1], snapping onto a ring.
        let mut r = thetas.iter().rposition(|&t| t <= theta).unwrap_or(0);
        if r < last && thetas[r + 1] - theta <= ANGLE_SNAP_DEG {
            r += 1;
        }
        let t = if r == last || theta - thetas[r] <= ANGLE_SNAP_DEG {
            0.0
        } else {
            (theta - thetas[r]) / (thetas[r + 1] - thetas[r])
        };
        let mut entries = [(0usize, 0.0f64); 4];
        let lo = ring_neighbours(r, phi);
        entries[0] = (lo[0].0, (1.0 - t) * lo[0].1 * fade);
        entries[1] = (lo[1].0, (1.0 - t) * lo[1].1 * fade);
        if t > 0.0 {
            let hi = ring_neighbours(r + 1, phi);
            entries[2] = (hi[0].0, t * hi[0].1 * fade);
            entries[3] = (hi[1].0, t * hi[1].1 * fade);
        }
        Weights4::from_entries(&entries)
    }
}

impl std::fmt::Display for Sampling {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The two φ neighbours in ring `r` with their linear weights (wrapping at 360°); the pole
/// returns index 0 twice.
fn ring_neighbours(r: usize, phi: f64) -> [(usize, f64); 2] {
    let n = RING_COUNT[r];
    if n == 1 {
        return [(RING_START[r], 1.0), (RING_START[r], 0.0)];
    }
    let dphi = 360.0 / n as f64;
    let x = phi.rem_euclid(360.0) / dphi;
    let mut k = x.floor();
    let mut s = x - k;
    // Snap onto a measured φ (in degrees of arc along the ring's φ).
    if s * dphi <= ANGLE_SNAP_DEG {
        s = 0.0;
    } else if (1.0 - s) * dphi <= ANGLE_SNAP_DEG {
        s = 0.0;
        k += 1.0;
    }
    let k0 = (k as usize) % n;
    let k1 = (k0 + 1) % n;
    [(RING_START[r] + k0, 1.0 - s), (RING_START[r] + k1, s)]
}

/// (θ, φ) in degrees of a direction, θ ∈ [0, 180], φ ∈ (−180, 180]; `None` for a zero or
/// non-finite vector. θ uses atan2, which is accurate at every angle (acos is not near 0).
fn angles(dir: Vec3) -> Option<(f64, f64)> {
    let (x, y, z) = (f64::from(dir.x), f64::from(dir.y), f64::from(dir.z));
    if !(x.is_finite() && y.is_finite() && z.is_finite()) || (x == 0.0 && y == 0.0 && z == 0.0) {
        return None;
    }
    let rho = x.hypot(y);
    let theta = rho.atan2(z).to_degrees();
    let phi = if rho == 0.0 {
        0.0
    } else {
        y.atan2(x).to_degrees()
    };
    Some((theta, phi))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_5_1() {
        for s in Sampling::ALL {
            assert_eq!(RING_COUNT.iter().sum::<usize>(), DIRECTIONS);
            for i in 0..DIRECTIONS {
                let (t, p) = s.dir_deg_u32(i);
                assert_eq!(s.index_of(t, p), Some(i));
            }
        }
        assert_eq!(Sampling::H1.dir(1), (17.0, 0.0));
        assert_eq!(Sampling::H1.dir(2), (17.0, 60.0));
        assert_eq!(Sampling::H2.dir(80), (75.0, 345.0));
        assert_eq!(Sampling::H2.dir(57), (75.0, 0.0));
    }

    #[test]
    fn vectors_round_trip_to_angles() {
        for s in Sampling::ALL {
            for i in 0..DIRECTIONS {
                let (t, p) = angles(s.vector(i)).unwrap();
                let (t0, p0) = s.dir(i);
                assert!((t - f64::from(t0)).abs() < 2e-5, "{i}: {t} vs {t0}");
                if t0 > 0.0 {
                    let dp = (p - f64::from(p0)).rem_euclid(360.0);
                    assert!(dp.min(360.0 - dp) < 2e-5, "{i}: {p} vs {p0}");
                }
            }
        }
    }
}
