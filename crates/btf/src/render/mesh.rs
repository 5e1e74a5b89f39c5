//! The inputs of a rendering: mesh, light, camera and parameters, and their validation.

use glam::{Vec2, Vec3, Vec4};

use crate::error::{BtfError, Result};

/// A normal shorter than this (before normalisation) is degenerate. Meshes store unit
/// normals; 10⁻⁶ only rejects zero and underflowed vectors.
pub(crate) const MIN_NORMAL_LENGTH: f32 = 1e-6;

/// A tangent whose component perpendicular to the normal is shorter than this fraction of its
/// length is (anti)parallel to the normal: the frame is degenerate. 10⁻³ (0.06°) is far below
/// any tangent of a real mesh and far above f32 rounding of unit vectors.
const MIN_TANGENT_SINE: f32 = 1e-3;

/// A triangle mesh with what the BTF needs per vertex: UVs and a tangent frame.
///
/// All per-vertex slices have one entry per position. Borrowed, so a caller's own buffers
/// (e.g. a `meshio` mesh plus [`tangent_frames`](super::tangent_frames)) render without a copy.
#[derive(Clone, Copy, Debug)]
pub struct BtfMesh<'a> {
    /// World-space positions.
    pub positions: &'a [Vec3],
    /// Normals (need not be unit length; normalised per vertex).
    pub normals: &'a [Vec3],
    /// Tangents: xyz the tangent ∂P/∂u (orthonormalised against the normal per vertex), w the
    /// handedness (w < 0 flips the bitangent = w · normal × tangent).
    pub tangents: &'a [Vec4],
    /// Texture coordinates; u runs along a normtexture row, v down the rows.
    pub uvs: &'a [Vec2],
    /// Triangles as indices into the per-vertex slices.
    pub triangles: &'a [[u32; 3]],
}

/// An orthonormal tangent frame: tangent (x), bitangent (y), normal (z), all world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Frame {
    pub(crate) tangent: Vec3,
    pub(crate) bitangent: Vec3,
    pub(crate) normal: Vec3,
}

impl Frame {
    /// A world-space direction in the frame.
    pub(crate) fn in_frame(self, dir_world: Vec3) -> Vec3 {
        Vec3::new(
            dir_world.dot(self.tangent),
            dir_world.dot(self.bitangent),
            dir_world.dot(self.normal),
        )
    }
}

/// `BtfError::NonFinite` for the first non-finite component of `values`, if any.
fn check_finite<const N: usize>(what: &str, values: impl Iterator<Item = [f32; N]>) -> Result<()> {
    for (index, v) in values.enumerate() {
        if let Some(&value) = v.iter().find(|x| !x.is_finite()) {
            return Err(BtfError::NonFinite {
                what: format!("BtfMesh {what} (vertex {index})"),
                index,
                value,
            });
        }
    }
    Ok(())
}

/// Checks that every per-vertex slice has one entry per position.
pub(crate) fn check_lengths(
    vertices: usize,
    lengths: &[(&'static str, usize, &'static str)],
) -> Result<()> {
    for &(what, found, hint) in lengths {
        if found != vertices {
            return Err(BtfError::LengthMismatch {
                what,
                expected: vertices,
                found,
                hint,
            });
        }
    }
    Ok(())
}

/// Checks that every triangle indexes an existing vertex.
pub(crate) fn check_triangles(triangles: &[[u32; 3]], vertices: usize) -> Result<()> {
    for (t, tri) in triangles.iter().enumerate() {
        if tri.iter().any(|&i| i as usize >= vertices) {
            return Err(BtfError::InvalidParameter {
                what: "BtfMesh",
                name: "triangles",
                value: format!("triangle {t} = {tri:?} with {vertices} vertices"),
                reason: "every vertex index must be below the vertex count",
            });
        }
    }
    Ok(())
}

impl BtfMesh<'_> {
    /// Checks the mesh as both renderers do before drawing.
    ///
    /// # Errors
    /// [`BtfError::LengthMismatch`] naming the slice (`"BtfMesh uvs"`, …) whose length differs
    /// from the vertex count (e.g. a mesh without UVs or tangents);
    /// [`BtfError::InvalidParameter`] for a triangle with an index out of range, a zero
    /// normal or a tangent parallel to its normal (the value names the vertex);
    /// [`BtfError::NonFinite`] for a NaN or infinite value.
    pub fn validate(&self) -> Result<()> {
        self.frames().map(|_| ())
    }

    /// Checks the mesh ([`BtfMesh::validate`]) and returns the orthonormal frame of every
    /// vertex.
    pub(crate) fn frames(&self) -> Result<Vec<Frame>> {
        let n = self.positions.len();
        check_lengths(
            n,
            &[
                (
                    "BtfMesh normals",
                    self.normals.len(),
                    "give one normal per vertex",
                ),
                (
                    "BtfMesh uvs",
                    self.uvs.len(),
                    "give one texture coordinate per vertex; a BTF needs a UV mapping",
                ),
                (
                    "BtfMesh tangents",
                    self.tangents.len(),
                    "give one tangent per vertex, e.g. from btf::render::tangent_frames",
                ),
            ],
        )?;
        check_triangles(self.triangles, n)?;
        check_finite("positions", self.positions.iter().map(|p| p.to_array()))?;
        check_finite("normals", self.normals.iter().map(|p| p.to_array()))?;
        check_finite("uvs", self.uvs.iter().map(|p| p.to_array()))?;
        check_finite("tangents", self.tangents.iter().map(|p| p.to_array()))?;
        self.normals
            .iter()
            .zip(self.tangents)
            .enumerate()
            .map(|(i, (&normal, &tangent))| frame(i, normal, tangent))
            .collect()
    }
}

/// The orthonormal frame of vertex `i` (Gram–Schmidt of the tangent against the normal).
fn frame(i: usize, normal: Vec3, tangent: Vec4) -> Result<Frame> {
    let len = normal.length();
    if len < MIN_NORMAL_LENGTH {
        return Err(BtfError::InvalidParameter {
            what: "BtfMesh",
            name: "normals",
            value: format!("vertex {i}: {normal}"),
            reason: "a normal must have non-zero length",
        });
    }
    let normal = normal / len;
    let t = tangent.truncate();
    let perpendicular = t - normal * normal.dot(t);
    let t_len = t.length();
    let p_len = perpendicular.length();
    if t_len == 0.0 || p_len < MIN_TANGENT_SINE * t_len {
        return Err(BtfError::InvalidParameter {
            what: "BtfMesh",
            name: "tangents",
            value: format!("vertex {i}: tangent {t} with normal {normal}"),
            reason: "the tangent is zero or (anti)parallel to the normal, so the tangent \
                     frame is degenerate; compute tangents with btf::render::tangent_frames",
        });
    }
    let tangent_unit = perpendicular / p_len;
    let handedness = if tangent.w < 0.0 { -1.0 } else { 1.0 };
    Ok(Frame {
        tangent: tangent_unit,
        bitangent: handedness * normal.cross(tangent_unit),
        normal,
    })
}

/// The one light of a rendering (thesis §5.5: "a single point or directional light source").
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// Light from a fixed direction.
    Directional {
        /// World-space direction from the surface toward the light (need not be unit length).
        dir_to_light_world: Vec3,
        /// RGB radiance g (eq. 5.4), linear.
        radiance: Vec3,
    },
    /// Light from a point; the direction is taken per vertex, from the vertex to the light.
    /// No distance falloff: g applies as given at every distance (see the
    /// [module docs](super)).
    Point {
        /// World-space position of the light.
        position_world: Vec3,
        /// RGB radiance g (eq. 5.4), linear.
        radiance: Vec3,
    },
}

impl Light {
    /// The RGB radiance g.
    pub fn radiance(&self) -> Vec3 {
        match *self {
            Self::Directional { radiance, .. } | Self::Point { radiance, .. } => radiance,
        }
    }

    /// World-space direction from `position_world` toward the light (not normalised; zero
    /// for a point light at the position itself, which lights nothing).
    pub fn dir_to_light_world(&self, position_world: Vec3) -> Vec3 {
        match *self {
            Self::Directional {
                dir_to_light_world, ..
            } => dir_to_light_world,
            Self::Point {
                position_world: p, ..
            } => p - position_world,
        }
    }

    pub(crate) fn validate(&self) -> Result<()> {
        let (name, v) = match *self {
            Self::Directional {
                dir_to_light_world, ..
            } => ("dir_to_light_world", dir_to_light_world),
            Self::Point { position_world, .. } => ("position_world", position_world),
        };
        let bad = |name, value: Vec3, reason| BtfError::InvalidParameter {
            what: "Light",
            name,
            value: format!("{value}"),
            reason,
        };
        if !v.is_finite() {
            return Err(bad(name, v, "must be finite"));
        }
        if matches!(self, Self::Directional { .. }) && v.length_squared() == 0.0 {
            return Err(bad(name, v, "a light direction must be non-zero"));
        }
        if !self.radiance().is_finite() {
            return Err(bad("radiance", self.radiance(), "must be finite"));
        }
        Ok(())
    }
}

/// The workspace's one camera (crate `render`): a perspective pinhole and the image size,
/// shared by the CPU and GPU paths and by every other pass of the frame.
pub use ::render::Camera;

/// Knobs of a rendering.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct RenderParams {
    /// Linear RGB of pixels no triangle covers.
    pub background: Vec3,
    /// Texture coordinates are multiplied by this before the lookup (> 1 repeats the BTF
    /// sample over the mesh).
    pub uv_scale: Vec2,
}

impl Default for RenderParams {
    fn default() -> Self {
        Self {
            background: Vec3::ZERO,
            uv_scale: Vec2::ONE,
        }
    }
}

impl RenderParams {
    pub(crate) fn validate(&self) -> Result<()> {
        if !self.background.is_finite() || !self.uv_scale.is_finite() {
            return Err(BtfError::InvalidParameter {
                what: "RenderParams",
                name: "background, uv_scale",
                value: format!("{} {}", self.background, self.uv_scale),
                reason: "must be finite",
            });
        }
        Ok(())
    }
}
