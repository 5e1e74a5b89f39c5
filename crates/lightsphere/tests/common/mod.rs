//! Shared test helpers: tolerance asserts, deterministic random directions, independent
//! reference implementations (clip-based Voronoi areas, O(N²) f64 prefilter).
#![allow(dead_code)]

use glam::{DMat3, DVec3, Vec3};
use lightsphere::{Environment, latlong};
use std::f64::consts::{PI, TAU};

/// Assert |actual − expected| ≤ tolerance.
#[track_caller]
pub fn assert_close(actual: f64, expected: f64, tolerance: f64, what: &str) {
    assert!(
        (actual - expected).abs() <= tolerance,
        "{what}: got {actual}, expected {expected} ± {tolerance} (off by {})",
        (actual - expected).abs()
    );
}

/// Assert |actual − expected| ≤ rel · |expected| per channel.
#[track_caller]
pub fn assert_rel3(actual: [f64; 3], expected: [f64; 3], rel: f64, what: &str) {
    for c in 0..3 {
        let tol = rel * expected[c].abs();
        assert!(
            (actual[c] - expected[c]).abs() <= tol,
            "{what}: channel {c}: got {}, expected {} (relative error {:.3e} > {rel:.1e})",
            actual[c],
            expected[c],
            (actual[c] - expected[c]).abs() / expected[c].abs()
        );
    }
}

/// Deterministic splitmix64 stream of uniform f64 in [0, 1).
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    pub fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform unit direction.
    pub fn unit(&mut self) -> DVec3 {
        let z = 2.0 * self.uniform() - 1.0;
        let phi = TAU * self.uniform();
        let r = (1.0 - z * z).max(0.0).sqrt();
        DVec3::new(r * phi.cos(), z, r * phi.sin())
    }
}

/// The 48 signed permutation matrices (the octahedral symmetry group).
pub fn octahedral_symmetries() -> Vec<DMat3> {
    let perms = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    let mut out = Vec::new();
    for p in perms {
        for signs in 0..8 {
            let mut cols = [DVec3::ZERO; 3];
            for (i, col) in cols.iter_mut().enumerate() {
                let s = if signs >> i & 1 == 1 { -1.0 } else { 1.0 };
                let mut v = DVec3::ZERO;
                v[p[i]] = s;
                *col = v;
            }
            out.push(DMat3::from_cols(cols[0], cols[1], cols[2]));
        }
    }
    out
}

/// Area of the spherical polygon with unit vertices `poly` (counter-clockwise from outside)
/// by Girard's theorem: angle sum − (n − 2)π.
pub fn girard_area(poly: &[DVec3]) -> f64 {
    let n = poly.len();
    let mut angle_sum = 0.0;
    for i in 0..n {
        let (prev, v, next) = (poly[(i + n - 1) % n], poly[i], poly[(i + 1) % n]);
        // Tangent directions at v towards prev and next.
        let t1 = (prev - v * v.dot(prev)).normalize();
        let t2 = (next - v * v.dot(next)).normalize();
        // Interior angle measured counter-clockwise from t2 to t1 around v.
        let angle = t2.cross(t1).dot(v).atan2(t2.dot(t1));
        angle_sum += if angle < 0.0 { angle + TAU } else { angle };
    }
    angle_sum - (n as f64 - 2.0) * PI
}

/// Spherical Voronoi cell of `points[i]` by clipping a large spherical square around it with
/// the bisector half-spaces of all other points (O(k) per cell, independent of any
/// triangulation). Returns the cell's vertices counter-clockwise from outside.
pub fn clipped_voronoi_cell(points: &[DVec3], i: usize) -> Vec<DVec3> {
    let p = points[i];
    let helper = if p.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
    let e1 = p.cross(helper).normalize();
    let e2 = p.cross(e1);
    // Square of circumradius 80° around p (inradius 76° > any cell radius for k ≥ 6).
    let r = 80f64.to_radians();
    let mut poly: Vec<DVec3> = (0..4)
        .map(|k| {
            let a = std::f64::consts::FRAC_PI_2 * k as f64;
            p * r.cos() + (e1 * a.cos() + e2 * a.sin()) * r.sin()
        })
        .collect();
    // Make it counter-clockwise seen from outside.
    if (poly[1] - poly[0]).cross(poly[2] - poly[0]).dot(p) < 0.0 {
        poly.reverse();
    }
    for (j, &q) in points.iter().enumerate() {
        if j == i {
            continue;
        }
        let m = p - q; // keep x·m ≥ 0
        let mut out = Vec::with_capacity(poly.len() + 1);
        for k in 0..poly.len() {
            let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
            let (sa, sb) = (a.dot(m), b.dot(m));
            if sa >= 0.0 {
                out.push(a);
            }
            if (sa >= 0.0) != (sb >= 0.0) {
                let t = sa / (sa - sb);
                out.push((a + (b - a) * t).normalize());
            }
        }
        poly = out;
    }
    poly
}

/// O(N_out · N_in) f64 spherical Gaussian prefilter at the texel centres of an
/// `out_w × out_h` map, truncated at `truncation_sigmas`·σ.
pub fn brute_force_prefilter(
    env: &Environment,
    sigma_deg: f64,
    truncation_sigmas: f64,
    out_w: usize,
    out_h: usize,
) -> Vec<[f64; 3]> {
    let (w, h) = (env.width(), env.height());
    let sigma = sigma_deg.to_radians();
    let cutoff = truncation_sigmas * sigma;
    let sources: Vec<(DVec3, f64, [f32; 3])> = (0..h)
        .flat_map(|r| (0..w).map(move |c| (r, c)))
        .map(|(r, c)| {
            (
                latlong::texel_direction(r, c, w, h),
                latlong::texel_solid_angle(r, w, h),
                env.texels()[r * w + c],
            )
        })
        .collect();
    let mut out = Vec::with_capacity(out_w * out_h);
    for r in 0..out_h {
        for c in 0..out_w {
            let d = latlong::texel_direction(r, c, out_w, out_h);
            let mut sum = [0.0f64; 3];
            let mut z = 0.0f64;
            for &(s, omega, t) in &sources {
                let gamma = d.cross(s).length().atan2(d.dot(s));
                if gamma > cutoff {
                    continue;
                }
                let wgt = (-gamma * gamma / (2.0 * sigma * sigma)).exp() * omega;
                z += wgt;
                for ch in 0..3 {
                    sum[ch] += wgt * f64::from(t[ch]);
                }
            }
            out.push(sum.map(|v| v / z));
        }
    }
    out
}

/// A deterministic smooth-plus-noise test map with values in [0.1, 3].
pub fn test_map(width: usize, height: usize, seed: u64) -> Environment {
    let mut rng = Rng::new(seed);
    let texels = (0..width * height)
        .map(|i| {
            let (r, c) = (i / width, i % width);
            let theta = latlong::row_theta(r, height);
            let phi = latlong::col_phi(c, width);
            let base = 1.0 + 0.5 * theta.cos() + 0.3 * (2.0 * phi).sin() * theta.sin();
            [0, 1, 2].map(|k| (base + 0.5 * rng.uniform() + 0.1 * k as f64) as f32)
        })
        .collect();
    Environment::from_latlong(width, height, texels).expect("valid test map")
}

/// Sum over texels of radiance × exact solid angle, written independently of the library.
pub fn texel_power(env: &Environment) -> [f64; 3] {
    let (w, h) = (env.width(), env.height());
    let mut total = [0.0f64; 3];
    for r in 0..h {
        let top = PI * r as f64 / h as f64;
        let bottom = PI * (r + 1) as f64 / h as f64;
        let omega = TAU / w as f64 * (top.cos() - bottom.cos());
        for c in 0..w {
            let t = env.texels()[r * w + c];
            for ch in 0..3 {
                total[ch] += f64::from(t[ch]) * omega;
            }
        }
    }
    total
}

/// ∫ of the bilinearly interpolated map by an s × s supersampled midpoint rule in (θ, φ)
/// with exact band solid angles.
pub fn bilinear_power(env: &Environment, s: usize) -> [f64; 3] {
    let (w, h) = (env.width() * s, env.height() * s);
    let mut total = [0.0f64; 3];
    for r in 0..h {
        let omega = latlong::texel_solid_angle(r, w, h);
        for c in 0..w {
            let v: Vec3 = env.radiance_f64(
                env.world_from_env().as_dquat() * latlong::texel_direction(r, c, w, h),
            );
            for ch in 0..3 {
                total[ch] += f64::from(v[ch]) * omega;
            }
        }
    }
    total
}
