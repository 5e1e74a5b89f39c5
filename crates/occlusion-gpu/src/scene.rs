//! Scenes of several meshes with transforms (paper 000 §6 "Dynamic Geometry and Animations",
//! §7 "several objects that occlude each other").
//!
//! Every object's triangles occlude; the vertices of *receiver* objects are the rows of the
//! visibility matrix, in object order and, within an object, in the object's vertex order (so
//! arrays keep the input's vertex order and count). A rigid motion of the whole scene only
//! rotates the look-up; a relative motion or a deformation changes the scene and M must be
//! recomputed.

use std::borrow::Cow;
use std::ops::Range;

use glam::{DMat3, DMat4, DVec3, Mat4, Vec3};

use crate::OcclusionError;

/// The largest vertex or triangle count: the GPU paths index with `u32`.
pub const MAX_ELEMENTS: usize = (u32::MAX / 4) as usize;

/// One triangle mesh placed in the scene.
#[derive(Clone, Debug)]
pub struct SceneObject {
    /// Object-space vertex positions.
    pub positions: Vec<Vec3>,
    /// Object-space vertex normals, one per position; a zero normal marks a vertex used by no
    /// triangle (its matrix row is all zero and its ambient term NaN).
    pub normals: Vec<Vec3>,
    /// Triangles as indices into `positions`.
    pub triangles: Vec<[u32; 3]>,
    /// Placement in the world (transforms read right to left).
    pub world_from_object: Mat4,
    /// Whether this object's vertices are rows of the visibility matrix (`true`), or it only
    /// occludes (`false`).
    pub receiver: bool,
}

impl SceneObject {
    /// A receiver object at the identity placement.
    pub fn new(positions: Vec<Vec3>, normals: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Self {
        Self {
            positions,
            normals,
            triangles,
            world_from_object: Mat4::IDENTITY,
            receiver: true,
        }
    }

    /// The same object placed by `world_from_object`.
    pub fn with_transform(mut self, world_from_object: Mat4) -> Self {
        self.world_from_object = world_from_object;
        self
    }

    /// The same object as a pure occluder: it casts shadows but gets no matrix rows.
    pub fn occluder_only(mut self) -> Self {
        self.receiver = false;
        self
    }
}

/// Several objects that occlude each other.
#[derive(Clone, Debug, Default)]
pub struct Scene {
    objects: Vec<SceneObject>,
}

impl Scene {
    /// An empty scene.
    pub fn new() -> Self {
        Self::default()
    }

    /// A scene of one receiver mesh at the identity placement.
    ///
    /// # Errors
    /// As [`Scene::push`].
    pub fn single(
        positions: Vec<Vec3>,
        normals: Vec<Vec3>,
        triangles: Vec<[u32; 3]>,
    ) -> Result<Self, OcclusionError> {
        let mut scene = Self::new();
        scene.push(SceneObject::new(positions, normals, triangles))?;
        Ok(scene)
    }

    /// Adds an object after validating it; returns its index.
    ///
    /// # Errors
    /// [`OcclusionError::NormalCountMismatch`], [`OcclusionError::IndexOutOfRange`],
    /// [`OcclusionError::NonFinite`] or [`OcclusionError::TooLarge`].
    pub fn push(&mut self, object: SceneObject) -> Result<usize, OcclusionError> {
        let index = self.objects.len();
        validate(index, &object)?;
        let vertices = self.vertex_count() + object.positions.len();
        let triangles = self.triangle_count() + object.triangles.len();
        for (element, value) in [("vertices", vertices), ("triangles", triangles)] {
            if value > MAX_ELEMENTS {
                return Err(OcclusionError::TooLarge {
                    element,
                    value,
                    maximum: MAX_ELEMENTS,
                });
            }
        }
        self.objects.push(object);
        Ok(index)
    }

    /// The objects in insertion order.
    pub fn objects(&self) -> &[SceneObject] {
        &self.objects
    }

    /// Mutable access to an object, e.g. to deform it or move it between frames. Validation
    /// happens again when the scene is prepared.
    pub fn object_mut(&mut self, index: usize) -> Option<&mut SceneObject> {
        self.objects.get_mut(index)
    }

    /// Total number of vertices of all objects.
    pub fn vertex_count(&self) -> usize {
        self.objects.iter().map(|o| o.positions.len()).sum()
    }

    /// Total number of triangles of all objects.
    pub fn triangle_count(&self) -> usize {
        self.objects.iter().map(|o| o.triangles.len()).sum()
    }

    /// Number of matrix rows: the vertices of all receiver objects.
    pub fn receiver_count(&self) -> usize {
        self.objects
            .iter()
            .filter(|o| o.receiver)
            .map(|o| o.positions.len())
            .sum()
    }

    /// The matrix rows of object `index`, or `None` when it is not a receiver (or absent).
    pub fn receiver_rows(&self, index: usize) -> Option<Range<usize>> {
        let object = self.objects.get(index)?;
        if !object.receiver {
            return None;
        }
        let start: usize = self.objects[..index]
            .iter()
            .filter(|o| o.receiver)
            .map(|o| o.positions.len())
            .sum();
        Some(start..start + object.positions.len())
    }
}

fn validate(index: usize, object: &SceneObject) -> Result<(), OcclusionError> {
    if object.normals.len() != object.positions.len() {
        return Err(OcclusionError::NormalCountMismatch {
            object: index,
            positions: object.positions.len(),
            normals: object.normals.len(),
        });
    }
    let vertex_count = object.positions.len();
    for (triangle, corners) in object.triangles.iter().enumerate() {
        if let Some(&bad) = corners.iter().find(|&&c| c as usize >= vertex_count) {
            return Err(OcclusionError::IndexOutOfRange {
                object: index,
                triangle,
                index: bad,
                vertex_count,
            });
        }
    }
    let non_finite = |element, vectors: &[Vec3]| {
        vectors.iter().enumerate().find_map(|(i, v)| {
            v.to_array()
                .into_iter()
                .find(|c| !c.is_finite())
                .map(|value| OcclusionError::NonFinite {
                    object: index,
                    element,
                    index: i,
                    value,
                })
        })
    };
    if let Some(error) = non_finite("position", &object.positions) {
        return Err(error);
    }
    if let Some(error) = non_finite("normal", &object.normals) {
        return Err(error);
    }
    if let Some(&value) = object
        .world_from_object
        .to_cols_array()
        .iter()
        .find(|c| !c.is_finite())
    {
        return Err(OcclusionError::NonFinite {
            object: index,
            element: "world_from_object",
            index: 0,
            value,
        });
    }
    Ok(())
}

/// A receiver vertex in the prepared (centred world) frame.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Receiver {
    /// Position relative to [`Prepared::center`].
    pub position: Vec3,
    /// Unit world normal, or zero for a vertex used by no triangle.
    pub normal: Vec3,
}

/// The scene flattened into one centred world frame: what every backend consumes.
///
/// Coordinates are shifted by the scene's bounding-box centre in f64 before the cast to f32,
/// so a mesh 1e5 away from the origin keeps its full f32 precision.
#[derive(Clone, Debug)]
pub(crate) struct Prepared {
    /// World-space centre of the bounding box (subtracted from every position).
    pub center: DVec3,
    /// Bounding-box diagonal length.
    pub diagonal: f32,
    /// Radius of the bounding sphere around the centre.
    pub radius: f32,
    /// All objects' positions, centred.
    pub positions: Vec<Vec3>,
    /// All triangles, indexing `positions`.
    pub triangles: Vec<[u32; 3]>,
    /// The matrix rows.
    pub receivers: Vec<Receiver>,
}

impl Prepared {
    pub(crate) fn new(scene: &Scene) -> Result<Self, OcclusionError> {
        for (index, object) in scene.objects.iter().enumerate() {
            validate(index, object)?;
        }
        if scene.receiver_count() == 0 {
            return Err(OcclusionError::EmptyScene {
                what: "no receiver vertices",
            });
        }
        let mut world = Vec::with_capacity(scene.vertex_count());
        let mut triangles = Vec::with_capacity(scene.triangle_count());
        let mut world_normals = Vec::with_capacity(scene.receiver_count());
        for object in &scene.objects {
            let base = world.len() as u32;
            let m = object.world_from_object.as_dmat4();
            world.extend(
                object
                    .positions
                    .iter()
                    .map(|p| m.transform_point3(p.as_dvec3())),
            );
            triangles.extend(
                object
                    .triangles
                    .iter()
                    .map(|t| [t[0] + base, t[1] + base, t[2] + base]),
            );
            if object.receiver {
                let normal_from_object = normal_matrix(&m);
                world_normals.extend(object.normals.iter().map(|n| {
                    (normal_from_object * n.as_dvec3())
                        .try_normalize()
                        .unwrap_or(DVec3::ZERO)
                }));
            }
        }
        let (lo, hi) = world.iter().fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(*p), hi.max(*p)),
        );
        let center = 0.5 * (lo + hi);
        let diagonal = (hi - lo).length();
        let radius = world
            .iter()
            .map(|p| p.distance(center))
            .fold(0.0f64, f64::max);
        let positions: Vec<Vec3> = world.iter().map(|p| (*p - center).as_vec3()).collect();
        let mut receivers = Vec::with_capacity(world_normals.len());
        let mut offset = 0usize;
        let mut normals = world_normals.iter();
        for object in &scene.objects {
            if object.receiver {
                for p in &positions[offset..offset + object.positions.len()] {
                    let normal = normals.next().copied().unwrap_or(DVec3::ZERO).as_vec3();
                    receivers.push(Receiver {
                        position: *p,
                        normal,
                    });
                }
            }
            offset += object.positions.len();
        }
        Ok(Self {
            center,
            diagonal: diagonal as f32,
            radius: radius as f32,
            positions,
            triangles,
            receivers,
        })
    }
}

impl Prepared {
    /// The power of two that brings this scene's diagonal into (8, 16] (1 for a scene without
    /// extent): the factor the `cpu` backend's tracers multiply their coordinates by, so that
    /// neither their triple products (coordinates cubed) nor their boxes' areas leave f32's
    /// normal range, whatever the scene's units (a mesh 10⁻²⁰ or 10¹⁵ across). A power of two
    /// commutes with f32 rounding, so every decision is the one in the scene's own units
    /// wherever those are representable.
    pub(crate) fn tracer_scale(&self) -> f32 {
        let diagonal = self.diagonal;
        if diagonal > 0.0 && diagonal.is_finite() {
            power_of_two(4 - diagonal.log2().ceil() as i32)
        } else {
            1.0
        }
    }

    /// This scene with its centred coordinates multiplied by `scale` (positions, receivers'
    /// positions, diagonal, radius; the centre and the normals unchanged); borrowed when
    /// `scale` is 1.
    pub(crate) fn scaled(&self, scale: f32) -> Cow<'_, Self> {
        if scale == 1.0 {
            return Cow::Borrowed(self);
        }
        Cow::Owned(Self {
            center: self.center,
            diagonal: self.diagonal * scale,
            radius: self.radius * scale,
            positions: self.positions.iter().map(|p| *p * scale).collect(),
            triangles: self.triangles.clone(),
            receivers: self
                .receivers
                .iter()
                .map(|r| Receiver {
                    position: r.position * scale,
                    normal: r.normal,
                })
                .collect(),
        })
    }
}

/// 2^`e` as an f32, exactly (`e` clamped to the normal range).
pub(crate) fn power_of_two(e: i32) -> f32 {
    f32::from_bits(((e.clamp(-126, 127) + 127) as u32) << 23)
}

/// A ray's `max_t` multiplied by `scale`: a finite one stays finite (a bound past f32's range
/// still bounds nothing nearer), an infinite one stays infinite.
#[inline(always)]
pub(crate) fn scaled_max_t(max_t: f32, scale: f32) -> f32 {
    if max_t.is_finite() {
        (max_t * scale).min(f32::MAX)
    } else {
        max_t
    }
}

impl Prepared {
    /// The same scene (every triangle still occludes, same centre and bounds, so every backend
    /// computes bit-identical rows) with only the receiver rows `rows` as matrix rows, in the
    /// given order. The caller has checked that every index is in range.
    pub(crate) fn with_receivers(self, rows: &[u32]) -> Self {
        let receivers = rows.iter().map(|&r| self.receivers[r as usize]).collect();
        Self { receivers, ..self }
    }
}

/// Inverse transpose of the upper 3×3 (normals transform with it); falls back to the matrix
/// itself when it is singular (a flattening scale keeps the normals' directions meaningless
/// anyway, and they are renormalised).
fn normal_matrix(world_from_object: &DMat4) -> DMat3 {
    let linear = DMat3::from_mat4(*world_from_object);
    if linear.determinant().abs() > 0.0 {
        linear.inverse().transpose()
    } else {
        linear
    }
}
