//! The lightsphere: nested octahedral light directions l_j with solid-angle weights ω_j
//! (paper 000 §3.4 and §4.2, thesis §4.4.3).

pub(crate) mod delaunay;
mod locate;
pub(crate) mod subdivision;
pub(crate) mod voronoi;

use crate::LightsphereError;
use glam::{DQuat, DVec3, Quat, Vec3};
use std::sync::{Arc, OnceLock};

/// Highest supported subdivision level: k(8) = 262 146 directions, about 100 MB with the
/// nearest-direction grid and about 1.5 s to build (level 7: 65 538 directions, 0.3–0.4 s;
/// level 6: 16 386 directions, under 0.1 s). Level 9 would have a million directions, far
/// beyond what a visibility matrix N × k can hold.
pub const MAX_LEVEL: u32 = 8;

/// Levels up to this one are built once per process and shared (level 6: about 2 MB).
const CACHED_MAX_LEVEL: u32 = 6;

/// Number of directions at subdivision level `level`: k(s) = 2 + 4^(s+1) (paper 000 §3.4),
/// i.e. 6, 18, 66, 258, 1026, 4098, 16386 for s = 0..=6. Saturates at `usize::MAX` for
/// levels whose count does not fit.
///
/// # Examples
/// ```
/// assert_eq!(lightsphere::direction_count(3), 258);
/// ```
#[must_use]
pub const fn direction_count(level: u32) -> usize {
    let exponent = level.saturating_add(1);
    match 4usize.checked_pow(exponent) {
        Some(p) => p.saturating_add(2),
        None => usize::MAX,
    }
}

/// The level-dependent data shared by every rotation of a lightsphere.
struct Base {
    level: u32,
    directions: Vec<Vec3>,
    directions_f64: Vec<DVec3>,
    solid_angles: Vec<f64>,
    triangles: Vec<[u32; 3]>,
    delaunay_triangles: Vec<[u32; 3]>,
    delaunay_flips: usize,
    locator: locate::Locator,
}

impl Base {
    fn build(level: u32) -> Self {
        let sub = subdivision::subdivide(level);
        let mut mesh = delaunay::Triangulation::new(sub.triangles.clone());
        delaunay::make_delaunay(&sub.directions, &mut mesh);
        let cells = voronoi::voronoi_cells(&sub.directions, &mesh);
        let adjacency = locate::Adjacency::new(sub.directions.len(), &mesh);
        let locator = locate::Locator::new(&sub.directions, &adjacency, &cells.radii);
        Self {
            level,
            directions: sub.directions.iter().map(|d| d.as_vec3()).collect(),
            directions_f64: sub.directions,
            solid_angles: cells.areas,
            triangles: sub.triangles,
            delaunay_triangles: mesh.triangles,
            delaunay_flips: mesh.flips,
            locator,
        }
    }

    fn shared(level: u32) -> Arc<Self> {
        static CACHE: [OnceLock<Arc<Base>>; CACHED_MAX_LEVEL as usize + 1] =
            [const { OnceLock::new() }; CACHED_MAX_LEVEL as usize + 1];
        match CACHE.get(level as usize) {
            Some(slot) => Arc::clone(slot.get_or_init(|| Arc::new(Self::build(level)))),
            None => Arc::new(Self::build(level)),
        }
    }
}

/// A set of k = 2 + 4^(s+1) unit light directions from octahedron subdivision level s, with
/// the solid angle ω_j of each direction's spherical Voronoi cell.
///
/// Directions are nested: the first `direction_count(s)` directions of level s+1 are level
/// s's, in the same order (so a visibility column computed at a coarse level is reused at a
/// finer one, paper 000 §4.2). A rotated lightsphere ([`Lightsphere::rotated`]) keeps the
/// order, the weights and the triangles.
///
/// Cloning is cheap: the level's data is shared.
///
/// # Examples
/// ```
/// use lightsphere::Lightsphere;
/// let sphere = Lightsphere::new(2)?;
/// assert_eq!(sphere.len(), 66);
/// let total: f64 = sphere.solid_angles().iter().sum();
/// assert!((total - 4.0 * std::f64::consts::PI).abs() < 1e-9);
/// let j = sphere.nearest(glam::Vec3::new(0.1, 1.0, 0.0));
/// assert_eq!(j, 2); // +Y
/// # Ok::<(), lightsphere::LightsphereError>(())
/// ```
#[derive(Clone)]
pub struct Lightsphere {
    base: Arc<Base>,
    /// `sphere_from_base`, unit.
    rotation: DQuat,
    /// Rotated directions; `None` when the rotation is the identity.
    rotated: Option<Arc<(Vec<Vec3>, Vec<DVec3>)>>,
}

impl std::fmt::Debug for Lightsphere {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Lightsphere")
            .field("level", &self.base.level)
            .field("len", &self.len())
            .field("rotation", &self.rotation)
            .finish_non_exhaustive()
    }
}

impl Lightsphere {
    /// The lightsphere of subdivision level `level` (0 = octahedron).
    ///
    /// Levels up to 6 are built once per process and shared; level 6 (16 386 directions)
    /// takes well under 0.1 s, levels 7 and 8 are rebuilt on every call (see [`MAX_LEVEL`]).
    ///
    /// # Errors
    /// [`LightsphereError::LevelTooHigh`] when `level > MAX_LEVEL`.
    pub fn new(level: u32) -> Result<Self, LightsphereError> {
        if level > MAX_LEVEL {
            return Err(LightsphereError::LevelTooHigh {
                requested: level,
                maximum: MAX_LEVEL,
            });
        }
        Ok(Self {
            base: Base::shared(level),
            rotation: DQuat::IDENTITY,
            rotated: None,
        })
    }

    /// Subdivision level s.
    #[must_use]
    pub fn level(&self) -> u32 {
        self.base.level
    }

    /// Number of directions k = 2 + 4^(s+1).
    #[must_use]
    pub fn len(&self) -> usize {
        self.base.directions.len()
    }

    /// Always false: even level 0 has six directions.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.base.directions.is_empty()
    }

    /// Unit light directions l_j (f32, in the nested order, rotated if this is a rotated set).
    #[must_use]
    pub fn directions(&self) -> &[Vec3] {
        match &self.rotated {
            Some(r) => &r.0,
            None => &self.base.directions,
        }
    }

    /// The same directions in f64 (what [`Lightsphere::nearest`] compares against).
    #[must_use]
    pub fn directions_f64(&self) -> &[DVec3] {
        match &self.rotated {
            Some(r) => &r.1,
            None => &self.base.directions_f64,
        }
    }

    /// Solid angle ω_j (steradians) of each direction's spherical Voronoi cell; all positive,
    /// summing to 4π.
    #[must_use]
    pub fn solid_angles(&self) -> &[f64] {
        &self.base.solid_angles
    }

    /// The subdivision triangles of this level (counter-clockwise seen from outside), for
    /// drawing the lightsphere. 2·4^(s+1) of them.
    #[must_use]
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.base.triangles
    }

    /// The spherical Delaunay triangulation the Voronoi cells are dual to (counter-clockwise
    /// from outside). It equals [`Lightsphere::triangles`] up to flips of co-circular quads.
    #[must_use]
    pub fn delaunay_triangles(&self) -> &[[u32; 3]] {
        &self.base.delaunay_triangles
    }

    /// How many edge flips turned the subdivision into the Delaunay triangulation.
    #[must_use]
    pub fn delaunay_flips(&self) -> usize {
        self.base.delaunay_flips
    }

    /// The rotation applied to the level's canonical directions (`sphere_from_base`).
    #[must_use]
    pub fn rotation(&self) -> Quat {
        self.rotation.as_quat()
    }

    /// Mean length of the nearest-direction candidate lists (a cost indicator).
    #[must_use]
    pub fn mean_candidates_per_query(&self) -> f64 {
        self.base.locator.mean_candidates()
    }

    /// Index of the direction nearest to `dir` (largest `l_j · dir`), ties to the lowest
    /// index. `dir` need not be unit length. Identical to [`Lightsphere::nearest_linear`] but
    /// O(1): about four candidates are compared.
    ///
    /// A zero or non-finite `dir` gives 0 (see [`Lightsphere::try_nearest`]).
    #[must_use]
    pub fn nearest(&self, dir: Vec3) -> usize {
        self.nearest_f64(dir.as_dvec3())
    }

    /// [`Lightsphere::nearest`], returning `None` for a zero or non-finite `dir`.
    #[must_use]
    pub fn try_nearest(&self, dir: Vec3) -> Option<usize> {
        prepare_query(dir.as_dvec3()).map(|q| self.nearest_prepared(q))
    }

    /// [`Lightsphere::nearest`] for an f64 direction.
    #[must_use]
    pub fn nearest_f64(&self, dir: DVec3) -> usize {
        prepare_query(dir).map_or(0, |q| self.nearest_prepared(q))
    }

    fn nearest_prepared(&self, q: DVec3) -> usize {
        let q_in_base = match self.rotated {
            Some(_) => self.rotation.inverse() * q,
            None => q,
        };
        let directions = self.directions_f64();
        let mut best = usize::MAX;
        let mut best_dot = f64::NEG_INFINITY;
        for &j in self.base.locator.candidates(q_in_base) {
            let d = dot(directions[j as usize], q);
            if d > best_dot {
                best_dot = d;
                best = j as usize;
            }
        }
        assert!(best != usize::MAX, "empty candidate list");
        best
    }

    /// Reference linear scan for [`Lightsphere::nearest`]: arg-max of `l_j · dir` over all j,
    /// ties to the lowest index; 0 for a zero or non-finite `dir`. O(k).
    #[must_use]
    pub fn nearest_linear(&self, dir: Vec3) -> usize {
        self.nearest_linear_f64(dir.as_dvec3())
    }

    /// [`Lightsphere::nearest_linear`] for an f64 direction.
    #[must_use]
    pub fn nearest_linear_f64(&self, dir: DVec3) -> usize {
        let Some(q) = prepare_query(dir) else {
            return 0;
        };
        let mut best = 0;
        let mut best_dot = f64::NEG_INFINITY;
        for (j, &l) in self.directions_f64().iter().enumerate() {
            let d = dot(l, q);
            if d > best_dot {
                best_dot = d;
                best = j;
            }
        }
        best
    }

    /// The whole set rotated by `rotation` (`new_from_this`): directions are rotated, order,
    /// solid angles and triangles are kept. Rotations compose: `a.rotated(q1).rotated(q2)`
    /// equals `a.rotated(q2 * q1)`. The quaternion is normalised first.
    ///
    /// # Panics
    /// When `rotation` has zero length or non-finite components (a programming error); see
    /// [`Lightsphere::try_rotated`] for a fallible version.
    #[must_use]
    pub fn rotated(&self, rotation: Quat) -> Self {
        match self.try_rotated(rotation) {
            Ok(s) => s,
            Err(e) => panic!("{e}"),
        }
    }

    /// [`Lightsphere::rotated`], returning an error for a quaternion that cannot be normalised.
    ///
    /// # Errors
    /// [`LightsphereError::InvalidRotation`].
    pub fn try_rotated(&self, rotation: Quat) -> Result<Self, LightsphereError> {
        let q = unit_quat(rotation)?;
        let total = (q * self.rotation).normalize();
        let f64s: Vec<DVec3> = self
            .base
            .directions_f64
            .iter()
            .map(|&d| total * d)
            .collect();
        let f32s = f64s.iter().map(|d| d.as_vec3()).collect();
        Ok(Self {
            base: Arc::clone(&self.base),
            rotation: total,
            rotated: Some(Arc::new((f32s, f64s))),
        })
    }

    /// The light term I_j·ω_j per direction. The seed renders c_i = Σ_j M_ij I_j with
    /// M_ij = n_i·l_j when vertex i sees direction j (paper 000 §3.2–3.3); passing I_j·ω_j
    /// instead of I_j makes c_i the irradiance at vertex i (divide by π for the radiance of a
    /// white Lambertian surface), independent of k: an unoccluded vertex under a constant
    /// environment L gets Σ_j max(0, n·l_j) ω_j L ≈ πL.
    ///
    /// # Errors
    /// [`LightsphereError::RadianceCount`] when `radiance.len() != self.len()`.
    pub fn light_weights(&self, radiance: &[Vec3]) -> Result<Vec<Vec3>, LightsphereError> {
        if radiance.len() != self.len() {
            return Err(LightsphereError::RadianceCount {
                expected: self.len(),
                actual: radiance.len(),
            });
        }
        Ok(radiance
            .iter()
            .zip(self.solid_angles())
            .map(|(&i, &w)| (i.as_dvec3() * w).as_vec3())
            .collect())
    }

    /// Σ_j I_j·ω_j per channel (f64): the power a per-direction radiance represents.
    ///
    /// # Errors
    /// [`LightsphereError::RadianceCount`] when `radiance.len() != self.len()`.
    pub fn power(&self, radiance: &[Vec3]) -> Result<[f64; 3], LightsphereError> {
        if radiance.len() != self.len() {
            return Err(LightsphereError::RadianceCount {
                expected: self.len(),
                actual: radiance.len(),
            });
        }
        let mut sum = [0.0f64; 3];
        for (i, w) in radiance.iter().zip(self.solid_angles()) {
            for (s, v) in sum.iter_mut().zip(i.to_array()) {
                *s += f64::from(v) * w;
            }
        }
        Ok(sum)
    }
}

/// The dot product both nearest searches use (one definition, so they agree bit for bit).
#[inline]
fn dot(a: DVec3, b: DVec3) -> f64 {
    a.x * b.x + a.y * b.y + a.z * b.z
}

/// Scale a query so that its largest component has magnitude 1 (no overflow or underflow in
/// the dot products); `None` for zero or non-finite input.
fn prepare_query(dir: DVec3) -> Option<DVec3> {
    if !dir.is_finite() {
        return None;
    }
    let m = dir.abs().max_element();
    if m == 0.0 {
        return None;
    }
    Some(dir / m)
}

/// Normalise a user quaternion in f64.
pub(crate) fn unit_quat(rotation: Quat) -> Result<DQuat, LightsphereError> {
    let q = rotation.as_dquat();
    let length = q.length();
    if !q.is_finite() || !length.is_finite() || length < 1e-30 {
        return Err(LightsphereError::InvalidRotation {
            value: rotation.to_array(),
        });
    }
    Ok(q / length)
}
