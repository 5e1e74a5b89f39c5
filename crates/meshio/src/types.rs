//! The plain-data results: [`Mesh`] and [`Animation`].

use glam::{Vec2, Vec3};

use crate::{NormalWeighting, compute_normals};

/// A triangle mesh with one normal (and optionally one texture coordinate) per vertex.
///
/// Invariants established by the loaders: every index is `< positions.len()`, positions,
/// normals and UVs are finite, `normals.len() == positions.len()`, and `uvs` (when present)
/// has one entry per vertex. Normals are unit length or exactly zero (see
/// [`compute_normals`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Vertex normals, one per position.
    pub normals: Vec<Vec3>,
    /// Texture coordinates, one per position, when the file has consistent per-vertex UVs.
    pub uvs: Option<Vec<Vec2>>,
    /// Triangles as vertex indices, counter-clockwise seen from the front.
    pub triangles: Vec<[u32; 3]>,
}

impl Mesh {
    /// A mesh with angle-weighted normals computed from the positions and no UVs.
    pub fn from_triangles(positions: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Self {
        let normals = compute_normals(&positions, &triangles, NormalWeighting::Angle);
        Self {
            positions,
            normals,
            uvs: None,
            triangles,
        }
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Axis-aligned bounding box `(min, max)` of the positions; `None` for an empty mesh.
    pub fn bounding_box(&self) -> Option<(Vec3, Vec3)> {
        bounding_box(&self.positions)
    }
}

/// Axis-aligned bounding box of a point set; `None` when it is empty.
pub(crate) fn bounding_box(points: &[Vec3]) -> Option<(Vec3, Vec3)> {
    let first = *points.first()?;
    Some(
        points
            .iter()
            .fold((first, first), |(lo, hi), p| (lo.min(*p), hi.max(*p))),
    )
}

/// A deforming triangle mesh: one connectivity, one position array per frame.
///
/// Invariants established by the loaders: every frame has the same number of finite
/// positions, every index is `< vertex_count()`, `uvs` has one entry per vertex. Normals are
/// not stored; compute them per frame with [`Animation::normals_for_frame`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Animation {
    /// Triangles shared by all frames (empty for a `.npy` loaded without topology).
    pub triangles: Vec<[u32; 3]>,
    /// Vertex positions per frame: `frames[f][v]`.
    pub frames: Vec<Vec<Vec3>>,
    /// Frames per second.
    pub frame_rate: f32,
    /// Texture coordinates, one per vertex, when the source has them.
    pub uvs: Option<Vec<Vec2>>,
}

impl Animation {
    /// Number of frames.
    pub fn frame_count(&self) -> usize {
        self.frames.len()
    }

    /// Number of vertices per frame (0 when there are no frames).
    pub fn vertex_count(&self) -> usize {
        self.frames.first().map_or(0, Vec::len)
    }

    /// Time of frame `i` in seconds from frame 0.
    pub fn frame_time_s(&self, i: usize) -> f32 {
        i as f32 / self.frame_rate
    }

    /// Duration from the first to the last frame, in seconds.
    pub fn duration_s(&self) -> f32 {
        self.frame_time_s(self.frame_count().saturating_sub(1))
    }

    /// Frame `i` as a [`Mesh`] with angle-weighted normals.
    ///
    /// # Panics
    /// If `i >= frame_count()`.
    pub fn frame_mesh(&self, i: usize) -> Mesh {
        Mesh {
            positions: self.frames[i].clone(),
            normals: self.normals_for_frame(i),
            uvs: self.uvs.clone(),
            triangles: self.triangles.clone(),
        }
    }

    /// Angle-weighted vertex normals of frame `i` (see [`compute_normals`]).
    ///
    /// # Panics
    /// If `i >= frame_count()`.
    pub fn normals_for_frame(&self, i: usize) -> Vec<Vec3> {
        self.normals_for_frame_weighted(i, NormalWeighting::Angle)
    }

    /// Vertex normals of frame `i` with the given weighting.
    ///
    /// # Panics
    /// If `i >= frame_count()`.
    pub fn normals_for_frame_weighted(&self, i: usize, weighting: NormalWeighting) -> Vec<Vec3> {
        compute_normals(&self.frames[i], &self.triangles, weighting)
    }

    /// Bounding box over all frames; `None` when there are no vertices.
    pub fn bounding_box(&self) -> Option<(Vec3, Vec3)> {
        self.frames
            .iter()
            .filter_map(|frame| bounding_box(frame))
            .reduce(|(lo, hi), (l, h)| (lo.min(l), hi.max(h)))
    }
}
