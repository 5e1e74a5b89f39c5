//! The inputs of a rendering: mesh, light, camera and parameters, and their validation.

use glam::{Mat4, Vec2, Vec3, Vec4};

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

/// A perspective pinhole camera and the image size, shared by the CPU and GPU paths.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// World-space eye position.
    pub eye: Vec3,
    /// World-space point looked at (the image centre).
    pub target: Vec3,
    /// World-space up direction (the image's up, after orthogonalisation).
    pub up: Vec3,
    /// Vertical field of view in degrees, in (0, 180).
    pub fov_y_deg: f32,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Distance of the near clipping plane (> 0).
    pub near: f32,
    /// Distance of the far clipping plane (> near).
    pub far: f32,
}

/// [`Camera::look_at`]'s near plane as a fraction of the eye–target distance.
const NEAR_FRACTION: f32 = 1e-2;
/// [`Camera::look_at`]'s far plane as a multiple of the eye–target distance.
const FAR_MULTIPLE: f32 = 1e2;

impl Camera {
    /// A camera at `eye` looking at `target`, with clipping planes at 1/100 and 100 times the
    /// eye–target distance (set `near`/`far` to change them).
    pub fn look_at(
        eye: Vec3,
        target: Vec3,
        up: Vec3,
        fov_y_deg: f32,
        width: u32,
        height: u32,
    ) -> Self {
        let distance = eye.distance(target);
        Self {
            eye,
            target,
            up,
            fov_y_deg,
            width,
            height,
            near: NEAR_FRACTION * distance,
            far: FAR_MULTIPLE * distance,
        }
    }

    /// `perspective(fov_y, width/height, near, far) · look_at(eye, target, up)` (glam's
    /// right-handed camera with DirectX-style depth): world to wgpu clip space (x, y ∈ [−w, w] left to right and bottom to top, depth z ∈ [0, w]).
    ///
    /// # Errors
    /// [`BtfError::InvalidParameter`] for an empty image, a field of view outside (0°, 180°),
    /// non-finite vectors, eye = target, `up` parallel to the view direction, or clipping
    /// planes not 0 < near < far.
    pub fn clip_from_world(&self) -> Result<Mat4> {
        let bad = |name, value: String, reason| {
            Err(BtfError::InvalidParameter {
                what: "Camera",
                name,
                value,
                reason,
            })
        };
        if self.width == 0 || self.height == 0 {
            let size = format!("{} × {}", self.width, self.height);
            return bad("width × height", size, "the image must not be empty");
        }
        if !(self.fov_y_deg > 0.0 && self.fov_y_deg < 180.0) {
            let fov = self.fov_y_deg.to_string();
            return bad("fov_y_deg", fov, "the field of view must be in (0°, 180°)");
        }
        for (name, v) in [("eye", self.eye), ("target", self.target), ("up", self.up)] {
            if !v.is_finite() {
                return bad(name, v.to_string(), "must be finite");
            }
        }
        let forward = self.target - self.eye;
        if forward.length_squared() == 0.0 {
            return bad(
                "target",
                self.target.to_string(),
                "must differ from the eye",
            );
        }
        if forward.cross(self.up).length_squared() <= f32::EPSILON * forward.length_squared() {
            return bad(
                "up",
                self.up.to_string(),
                "must be non-zero and not parallel to the view direction",
            );
        }
        if !(self.near > 0.0 && self.far > self.near && self.far.is_finite()) {
            let planes = format!("near {} far {}", self.near, self.far);
            return bad(
                "near, far",
                planes,
                "clipping planes need 0 < near < far < ∞",
            );
        }
        let aspect = self.width as f32 / self.height as f32;
        // wgpu clip space: y up, depth 0..1 (the DirectX convention), as in `cloth-vis`.
        let clip_from_view = glam::camera::rh::proj::directx::perspective(
            self.fov_y_deg.to_radians(),
            aspect,
            self.near,
            self.far,
        );
        let view_from_world = glam::camera::rh::view::look_at_mat4(self.eye, self.target, self.up);
        Ok(clip_from_view * view_from_world)
    }
}

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
