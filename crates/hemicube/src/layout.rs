//! The three visibility-map models of thesis §4.3.4 and their pixels: direction in the
//! vertex's frame, delta form factor ΔF and solid angle Δω.
//!
//! The vertex frame is right-handed with z = the vertex normal n (x, y span the tangent plane;
//! [`crate::VertexFrame`]). Every planar model is a set of [`Face`]s: a plane at unit distance
//! along `forward`, a window `[u0, u1] × [v0, v1]` in its `(right, up)` coordinates and a pixel
//! grid; pixel `(i, j)` has its centre at `u = u0 + (i + ½)·Δu`, `v = v1 − (j + ½)·Δv` (row 0 at
//! the top, as a framebuffer stores it, so the GPU atlas copies rows without flipping).
//!
//! * **HC** (hemicube, Cohen & Greenberg 1985): top `n × n` on z = 1 over `[−1, 1]²`; four sides
//!   `n × n/2` on x = ±1, y = ±1 over the upper half `v ∈ [0, 1]`.
//! * **SP** (single plane, Cohen & Wallace 1993): one `n × n` face on z = 1 over `[−a, a]²`,
//!   `a = tan(A/2)` for the aperture A (default [`DEFAULT_APERTURE_DEG`]). Directions outside
//!   the aperture are not in the map: they neither light nor shade (the seed's model, which
//!   "may miss small folds", T 6152–6154); an unoccluded vertex sums to F(A), not 1.
//! * **HS** (hemisphere grid, T 5972–5974): θ rings × φ bins in spherical coordinates about n.
//!   The seed leaves the layout open; [`RingSpacing::EqualTheta`] spaces θ uniformly over
//!   [0°, 90°] (the seed's "rectangular grid in spherical coordinates"), [`RingSpacing::EqualSolidAngle`]
//!   spaces cos θ uniformly so every cell subtends the same solid angle. A cell's direction is
//!   its centre in θ and φ.
//!
//! **Delta form factors.** The thesis (eq. 4.7, T 6283–6290) points to Cohen & Greenberg for the
//! per-pixel ΔF = G/π ΔA and prints no formula. The standard *midpoint* formulas
//! (SEED-NOTES §1.4: top ΔA/(π(x²+y²+1)²), side zΔA/(π(x²+z²+1)²)) evaluate the kernel at the
//! pixel centre; their sum overshoots the closed forms (HC 8×8: 1.008569, SP 8×8 at 170°:
//! 0.4719 against 0.993777). [`FormFactorRule::Exact`], the default, integrates the kernel
//! over each pixel instead: the form factor from a differential area to a polygon is
//! (1/2π) Σ_edges γ_e (n · ĝ_e) (Lambert's contour formula; γ_e the angle the edge subtends,
//! ĝ_e the unit normal of the plane through the eye and the edge), evaluated in f64. Exact ΔF
//! sum to the closed forms to ~1e-15 (HC 1, SP (4/π) sin(A/2) atan(sin(A/2)), HS rings
//! (Δφ/2π)(sin²θ₂ − sin²θ₁)), so **no renormalisation is applied to either rule**: an open
//! vertex reads 1 with exact ΔF, and the midpoint rule's error stays visible (`repro hemicube`).
//! Pixel solid angles are exact too (Van Oosterom & Strackee's triangle formula, two triangles
//! per pixel; HS cells Δφ (cos θ₁ − cos θ₂)).

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use glam::{DVec3, Vec3};

use crate::HemicubeError;

/// Default single-plane aperture A in degrees: F(150°) = 0.944612 of the cosine-weighted
/// hemisphere is seen; a wider window gains little (F(170°) = 0.993777) while its centre
/// pixels grow coarse (the window's side grows as tan(A/2): 3.7 at 150°, 11.4 at 170°).
pub const DEFAULT_APERTURE_DEG: f64 = 150.0;

/// Largest planar resolution n (the seed's 24-bit code stops at 256; the bit maps do not, but
/// one HC map of 1024² is already 3 Mi pixels).
pub const MAX_RESOLUTION: u32 = 1024;

/// Largest number of HS rings or φ bins.
pub const MAX_HEMISPHERE_BINS: u32 = 2048;

/// How θ is divided into rings in the HS model.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum RingSpacing {
    /// Rings of equal Δθ over [0°, 90°] (the default).
    #[default]
    EqualTheta,
    /// Rings of equal solid angle (cos θ uniform).
    EqualSolidAngle,
}

/// A visibility-map model of §4.3.4 with its resolution.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Model {
    /// Hemicube: top `res × res`, four sides `res × res/2` (`res` even, 2..=[`MAX_RESOLUTION`]).
    Hemicube {
        /// Side of the top face in pixels.
        res: u32,
    },
    /// Single plane: one `res × res` face seeing the cone of half-angle `aperture_deg / 2`.
    SinglePlane {
        /// Side in pixels.
        res: u32,
        /// Full aperture A in degrees, (0, 180).
        aperture_deg: f64,
    },
    /// Hemisphere grid: `phi` bins in φ times `theta` rings in θ.
    Hemisphere {
        /// Bins in φ.
        phi: u32,
        /// Rings in θ.
        theta: u32,
        /// How the rings divide θ.
        spacing: RingSpacing,
    },
}

impl Model {
    /// The short name used on the command line and in reports: `hc`, `sp`, `hs`.
    pub fn short_name(&self) -> &'static str {
        match self {
            Model::Hemicube { .. } => "hc",
            Model::SinglePlane { .. } => "sp",
            Model::Hemisphere { .. } => "hs",
        }
    }

    /// The model and resolution as Table 4.1 writes them: `HC 16x16`, `SP 8x8`, `HS 16x4`.
    pub fn label(&self) -> String {
        match *self {
            Model::Hemicube { res } => format!("HC {res}x{res}"),
            Model::SinglePlane { res, .. } => format!("SP {res}x{res}"),
            Model::Hemisphere { phi, theta, .. } => format!("HS {phi}x{theta}"),
        }
    }

    /// Checks the resolution and aperture.
    ///
    /// # Errors
    /// [`HemicubeError::Model`] naming the value.
    pub fn validate(&self) -> Result<(), HemicubeError> {
        let bad = |what: String| Err(HemicubeError::Model(what));
        match *self {
            Model::Hemicube { res } => {
                if !(2..=MAX_RESOLUTION).contains(&res) || res % 2 != 0 {
                    return bad(format!(
                        "hemicube resolution {res} must be even and within 2..={MAX_RESOLUTION} \
                         (the sides are res x res/2)"
                    ));
                }
            }
            Model::SinglePlane { res, aperture_deg } => {
                if res == 0 || res > MAX_RESOLUTION {
                    return bad(format!(
                        "single-plane resolution {res} must be within 1..={MAX_RESOLUTION}"
                    ));
                }
                if !(aperture_deg > 0.0 && aperture_deg < 180.0) {
                    return bad(format!(
                        "single-plane aperture {aperture_deg}° must be within (0, 180) degrees"
                    ));
                }
            }
            Model::Hemisphere { phi, theta, .. } => {
                if phi == 0
                    || theta == 0
                    || phi > MAX_HEMISPHERE_BINS
                    || theta > MAX_HEMISPHERE_BINS
                {
                    return bad(format!(
                        "hemisphere grid {phi}x{theta} (phi x theta) must have 1..={MAX_HEMISPHERE_BINS} bins each way"
                    ));
                }
            }
        }
        Ok(())
    }

    /// Pixels per map.
    pub fn pixel_count(&self) -> usize {
        match *self {
            Model::Hemicube { res } => 3 * res as usize * res as usize,
            Model::SinglePlane { res, .. } => res as usize * res as usize,
            Model::Hemisphere { phi, theta, .. } => phi as usize * theta as usize,
        }
    }

    /// Whether a pinhole camera can rasterise the model (HC and SP; HS needs rays, §4.3.4).
    pub fn is_planar(&self) -> bool {
        !matches!(self, Model::Hemisphere { .. })
    }
}

/// How the per-pixel delta form factors are computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum FormFactorRule {
    /// The kernel integrated over the pixel (contour formula, f64): sums equal the closed forms.
    #[default]
    Exact,
    /// The kernel at the pixel centre times the pixel area (Cohen & Greenberg's formulas).
    Midpoint,
}

/// One planar face of a model: the plane at unit distance along `forward`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Face {
    /// Unit normal of the plane, pointing away from the eye (vertex frame).
    pub forward: DVec3,
    /// The plane's u axis (vertex frame).
    pub right: DVec3,
    /// The plane's v axis (vertex frame); `right × up = forward`.
    pub up: DVec3,
    /// `[u0, u1, v0, v1]`.
    pub window: [f64; 4],
    /// Pixels along u.
    pub width: u32,
    /// Pixels along v.
    pub height: u32,
    /// Index of the face's first pixel in the map.
    pub first_pixel: usize,
}

impl Face {
    fn pixel_size(&self) -> (f64, f64) {
        let [u0, u1, v0, v1] = self.window;
        (
            (u1 - u0) / f64::from(self.width),
            (v1 - v0) / f64::from(self.height),
        )
    }

    /// Point on the plane (vertex frame) at window coordinates (u, v).
    fn point(&self, u: f64, v: f64) -> DVec3 {
        self.forward + u * self.right + v * self.up
    }

    /// The four corners of pixel (i, j), counter-clockwise seen from the eye.
    fn corners(&self, i: u32, j: u32) -> [DVec3; 4] {
        let (du, dv) = self.pixel_size();
        let [u0, _, _, v1] = self.window;
        let (ua, ub) = (u0 + f64::from(i) * du, u0 + f64::from(i + 1) * du);
        let (va, vb) = (v1 - f64::from(j + 1) * dv, v1 - f64::from(j) * dv);
        [
            self.point(ua, va),
            self.point(ub, va),
            self.point(ub, vb),
            self.point(ua, vb),
        ]
    }

    /// The pixel containing the direction `d` (vertex frame) if it passes through the face's
    /// window (edges clamp into the window).
    pub fn pixel_of(&self, d: DVec3) -> Option<usize> {
        let depth = d.dot(self.forward);
        if depth <= 0.0 {
            return None;
        }
        let (u, v) = (d.dot(self.right) / depth, d.dot(self.up) / depth);
        let [u0, u1, v0, v1] = self.window;
        if !(u >= u0 && u <= u1 && v >= v0 && v <= v1) {
            return None;
        }
        let (du, dv) = self.pixel_size();
        let i = (((u - u0) / du) as u32).min(self.width - 1);
        let j = (((v1 - v) / dv) as u32).min(self.height - 1);
        Some(self.first_pixel + (j * self.width + i) as usize)
    }
}

/// The pixels of one model: shared by every vertex's map (ΔF "computed once, reused for every
/// vertex", T 6308–6309).
#[derive(Clone, Debug)]
pub struct PixelLayout {
    model: Model,
    rule: FormFactorRule,
    faces: Vec<Face>,
    /// HS ring boundaries θ_0 = 0 < … < θ_m = π/2 (empty for planar models).
    ring_bounds: Vec<f64>,
    directions: Vec<Vec3>,
    form_factors: Vec<f32>,
    solid_angles: Vec<f32>,
    form_factor_sum: f64,
    solid_angle_sum: f64,
}

impl PixelLayout {
    /// The layout of `model` with ΔF by `rule`.
    ///
    /// # Errors
    /// [`HemicubeError::Model`] for a resolution or aperture out of range.
    pub fn new(model: Model, rule: FormFactorRule) -> Result<Self, HemicubeError> {
        model.validate()?;
        let faces = faces_of(&model);
        let mut ring_bounds = Vec::new();
        let count = model.pixel_count();
        let mut directions = Vec::with_capacity(count);
        let mut ff = Vec::with_capacity(count);
        let mut sa = Vec::with_capacity(count);
        if let Model::Hemisphere {
            phi,
            theta,
            spacing,
        } = model
        {
            ring_bounds = (0..=theta)
                .map(|r| {
                    let f = f64::from(r) / f64::from(theta);
                    match spacing {
                        RingSpacing::EqualTheta => f * FRAC_PI_2,
                        RingSpacing::EqualSolidAngle => (1.0 - f).clamp(0.0, 1.0).acos(),
                    }
                })
                .collect();
            let dphi = TAU / f64::from(phi);
            for r in 0..theta as usize {
                let (t1, t2) = (ring_bounds[r], ring_bounds[r + 1]);
                let tc = 0.5 * (t1 + t2);
                let ring_ff = (dphi / TAU) * (t2.sin().powi(2) - t1.sin().powi(2));
                let ring_sa = dphi * (t1.cos() - t2.cos());
                for k in 0..phi {
                    let pc = (f64::from(k) + 0.5) * dphi;
                    directions.push(
                        DVec3::new(tc.sin() * pc.cos(), tc.sin() * pc.sin(), tc.cos()).as_vec3(),
                    );
                    let f = match rule {
                        FormFactorRule::Exact => ring_ff,
                        // The kernel cos θ/π at the cell centre times the cell's solid angle.
                        FormFactorRule::Midpoint => tc.cos() / PI * ring_sa,
                    };
                    ff.push(f);
                    sa.push(ring_sa);
                }
            }
        } else {
            for face in &faces {
                let (du, dv) = face.pixel_size();
                let [u0, _, _, v1] = face.window;
                for j in 0..face.height {
                    for i in 0..face.width {
                        let u = u0 + (f64::from(i) + 0.5) * du;
                        let v = v1 - (f64::from(j) + 0.5) * dv;
                        let d = face.point(u, v);
                        directions.push(d.normalize().as_vec3());
                        let corners = face.corners(i, j);
                        let f = match rule {
                            FormFactorRule::Exact => polygon_form_factor(&corners),
                            FormFactorRule::Midpoint => {
                                d.z * du * dv / (PI * d.length_squared().powi(2))
                            }
                        };
                        ff.push(f);
                        sa.push(
                            triangle_solid_angle(corners[0], corners[1], corners[2])
                                + triangle_solid_angle(corners[0], corners[2], corners[3]),
                        );
                    }
                }
            }
        }
        let form_factor_sum = ff.iter().sum();
        let solid_angle_sum = sa.iter().sum();
        Ok(Self {
            model,
            rule,
            faces,
            ring_bounds,
            directions,
            form_factors: ff.into_iter().map(|f| f as f32).collect(),
            solid_angles: sa.into_iter().map(|s| s as f32).collect(),
            form_factor_sum,
            solid_angle_sum,
        })
    }

    /// The model.
    pub fn model(&self) -> Model {
        self.model
    }

    /// The ΔF rule.
    pub fn rule(&self) -> FormFactorRule {
        self.rule
    }

    /// The planar faces (empty for HS).
    pub fn faces(&self) -> &[Face] {
        &self.faces
    }

    /// Pixels per map.
    pub fn len(&self) -> usize {
        self.directions.len()
    }

    /// Whether the map has no pixels (never for a valid model).
    pub fn is_empty(&self) -> bool {
        self.directions.is_empty()
    }

    /// Unit direction of every pixel's centre in the vertex frame (z = normal).
    pub fn directions(&self) -> &[Vec3] {
        &self.directions
    }

    /// ΔF of every pixel.
    pub fn form_factors(&self) -> &[f32] {
        &self.form_factors
    }

    /// Δω of every pixel (steradians).
    pub fn solid_angles(&self) -> &[f32] {
        &self.solid_angles
    }

    /// Σ ΔF accumulated in f64 (1 for HC and HS with exact ΔF; F(A) for SP).
    pub fn form_factor_sum(&self) -> f64 {
        self.form_factor_sum
    }

    /// Σ Δω accumulated in f64 (2π for HC and HS).
    pub fn solid_angle_sum(&self) -> f64 {
        self.solid_angle_sum
    }

    /// The pixel that sees direction `d` (vertex frame, any length > 0), or `None` below the
    /// tangent plane (z < 0) or outside an SP window. Directions in the tangent plane (z = 0)
    /// fall into the lowest row of HC sides and HS's last ring.
    pub fn pixel_of(&self, d: Vec3) -> Option<usize> {
        let d = d.as_dvec3();
        if !d.is_finite() || d.z < 0.0 || d == DVec3::ZERO {
            return None;
        }
        match self.model {
            Model::Hemisphere { phi, theta, .. } => {
                let t = (d.z / d.length()).clamp(0.0, 1.0).acos();
                let ring = self
                    .ring_bounds
                    .partition_point(|&b| b <= t)
                    .saturating_sub(1)
                    .min(theta as usize - 1);
                let p = d.y.atan2(d.x).rem_euclid(TAU);
                let bin = ((p / TAU * f64::from(phi)) as u32).min(phi - 1);
                Some(ring * phi as usize + bin as usize)
            }
            Model::SinglePlane { .. } => self.faces[0].pixel_of(d),
            Model::Hemicube { .. } => {
                // The face of the largest coordinate (z only over the upper half).
                let (ax, ay) = (d.x.abs(), d.y.abs());
                let face = if d.z >= ax && d.z >= ay {
                    0
                } else if ax >= ay {
                    if d.x > 0.0 { 1 } else { 3 }
                } else if d.y > 0.0 {
                    2
                } else {
                    4
                };
                self.faces[face].pixel_of(d)
            }
        }
    }
}

/// The faces of a planar model (none for HS).
fn faces_of(model: &Model) -> Vec<Face> {
    let face = |forward: DVec3, right: DVec3, up: DVec3, window, width, height, first| Face {
        forward,
        right,
        up,
        window,
        width,
        height,
        first_pixel: first,
    };
    match *model {
        Model::Hemicube { res } => {
            let top = (res * res) as usize;
            let side = (res * res / 2) as usize;
            let w = [-1.0, 1.0, 0.0, 1.0];
            vec![
                face(
                    DVec3::Z,
                    DVec3::X,
                    DVec3::Y,
                    [-1.0, 1.0, -1.0, 1.0],
                    res,
                    res,
                    0,
                ),
                face(DVec3::X, DVec3::Y, DVec3::Z, w, res, res / 2, top),
                face(DVec3::Y, -DVec3::X, DVec3::Z, w, res, res / 2, top + side),
                face(
                    DVec3::NEG_X,
                    DVec3::NEG_Y,
                    DVec3::Z,
                    w,
                    res,
                    res / 2,
                    top + 2 * side,
                ),
                face(
                    DVec3::NEG_Y,
                    DVec3::X,
                    DVec3::Z,
                    w,
                    res,
                    res / 2,
                    top + 3 * side,
                ),
            ]
        }
        Model::SinglePlane { res, aperture_deg } => {
            let a = (aperture_deg.to_radians() / 2.0).tan();
            vec![face(
                DVec3::Z,
                DVec3::X,
                DVec3::Y,
                [-a, a, -a, a],
                res,
                res,
                0,
            )]
        }
        Model::Hemisphere { .. } => Vec::new(),
    }
}

/// Form factor from a differential area at the origin with normal +z to a convex polygon
/// above the tangent plane (Lambert's contour formula).
pub fn polygon_form_factor(corners: &[DVec3]) -> f64 {
    let mut sum = 0.0;
    for (k, a) in corners.iter().enumerate() {
        let b = corners[(k + 1) % corners.len()];
        let c = a.cross(b);
        let len = c.length();
        if len == 0.0 {
            continue;
        }
        let gamma = len.atan2(a.dot(b));
        sum += gamma * c.z / len;
    }
    (sum / TAU).abs()
}

/// Solid angle of the triangle (a, b, c) seen from the origin (Van Oosterom & Strackee 1983).
pub fn triangle_solid_angle(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let (la, lb, lc) = (a.length(), b.length(), c.length());
    let numerator = a.dot(b.cross(c)).abs();
    let denominator = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
    2.0 * numerator.atan2(denominator)
}

/// Closed-form form factor of the hemicube's top face (1/√2 · 4/π · atan(1/√2) = 0.554126).
pub fn hemicube_top_closed_form() -> f64 {
    single_plane_closed_form(90.0)
}

/// Closed-form form factor of one hemicube side: (1 − top)/4 = 0.111468.
pub fn hemicube_side_closed_form() -> f64 {
    (1.0 - hemicube_top_closed_form()) / 4.0
}

/// Closed-form coverage of a single plane of aperture A: (4/π) sin(A/2) atan(sin(A/2)).
pub fn single_plane_closed_form(aperture_deg: f64) -> f64 {
    let b = (aperture_deg.to_radians() / 2.0).sin();
    4.0 / PI * b * b.atan()
}
