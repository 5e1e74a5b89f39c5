//! One object of a scene in world space: geometry, material, its animation when it has one,
//! and its lighting once computed. Shared by the stages (`run`, `shadowing`, `btf_stage`).

use std::sync::Arc;

use glam::{Mat4, Vec2, Vec3};

/// One object in world space, with its lighting once computed.
#[derive(Clone, Debug)]
pub struct WorldObject {
    /// Object name.
    pub name: String,
    /// World-space positions of the current frame.
    pub positions: Vec<Vec3>,
    /// World-space unit normals (zero for unreferenced vertices).
    pub normals: Vec<Vec3>,
    /// Triangles.
    pub triangles: Vec<[u32; 3]>,
    /// Texture coordinates, one per position, when the source has them (the synthetic cloth
    /// and meshes with per-vertex UVs); the `btf` effect needs them.
    pub uvs: Option<Vec<Vec2>>,
    /// Albedo ρ.
    pub albedo: Vec3,
    /// Lit on both sides.
    pub two_sided: bool,
    /// Radiance towards the front side, once the lighting stage ran.
    pub front: Option<Vec<Vec3>>,
    /// Radiance towards the back side, once the lighting stage ran.
    pub back: Option<Vec<Vec3>>,
    /// The object-space frames of an animated source, and the transform to world space.
    pub animation: Option<Animation>,
}

impl WorldObject {
    /// A static, white, two-sided object with texture coordinates (what a BTF is drawn on),
    /// not yet lit.
    pub fn textured(
        name: impl Into<String>,
        positions: Vec<Vec3>,
        normals: Vec<Vec3>,
        triangles: Vec<[u32; 3]>,
        uvs: Option<Vec<Vec2>>,
    ) -> Self {
        Self {
            name: name.into(),
            positions,
            normals,
            triangles,
            uvs,
            albedo: Vec3::ONE,
            two_sided: true,
            front: None,
            back: None,
            animation: None,
        }
    }
}

/// The frames of an animated object, in object space.
#[derive(Clone, Debug)]
pub struct Animation {
    /// Positions per frame.
    pub frames: Arc<Vec<Vec<Vec3>>>,
    /// `world_from_object` of the object.
    pub world_from_object: Mat4,
}

impl WorldObject {
    /// Number of animation frames (1 for a static object).
    pub fn frame_count(&self) -> usize {
        self.animation.as_ref().map_or(1, |a| a.frames.len())
    }

    /// Pose an animated object at `frame` (world positions and normals; lighting cleared).
    /// Static objects are left as they are. Returns whether anything moved.
    pub fn pose(&mut self, frame: usize) -> bool {
        let Some(anim) = &self.animation else {
            return false;
        };
        if frame >= anim.frames.len() {
            return false;
        }
        let (frames, world) = (Arc::clone(&anim.frames), anim.world_from_object);
        self.pose_positions(&frames[frame], world);
        true
    }

    /// Pose the object at object-space `source` positions placed by `world_from_object`
    /// (a frame from elsewhere: a jump map's player, a GPU decoder), normals recomputed and
    /// lighting cleared. `source` must have the object's vertex count.
    pub fn pose_positions(&mut self, source: &[Vec3], world_from_object: Mat4) {
        self.positions.clear();
        self.positions.extend(
            source
                .iter()
                .map(|p| world_from_object.transform_point3(*p)),
        );
        // In world space from the transformed positions, so any transform (including
        // mirroring scales) keeps normals consistent with the winding.
        self.normals = meshio::compute_normals(
            &self.positions,
            &self.triangles,
            meshio::NormalWeighting::Angle,
        );
        self.front = None;
        self.back = None;
    }

    /// Indices of the vertices some triangle uses, ascending (out-of-range indices, which
    /// the loaders refuse, are ignored).
    pub fn used_vertices(&self) -> Vec<usize> {
        let mut used = vec![false; self.positions.len()];
        for &i in self.triangles.iter().flatten() {
            if let Some(u) = used.get_mut(i as usize) {
                *u = true;
            }
        }
        (0..used.len()).filter(|&i| used[i]).collect()
    }

    /// The world positions of every frame (for framing a camera over a whole sequence).
    pub fn all_world_positions(&self) -> Vec<Vec3> {
        match &self.animation {
            None => self.positions.clone(),
            Some(anim) => anim
                .frames
                .iter()
                .flatten()
                .map(|p| anim.world_from_object.transform_point3(*p))
                .collect(),
        }
    }
}

/// A unit UV sphere with texture coordinates (the sphere of the thesis's Fig. 5.23):
/// positions, triangles and UVs (u around the axis, v from the top pole, each 0..1) of
/// `rings` × `segments` quads (`rings, segments ≥ 2`); the positions are also the normals.
/// The seam column (u = 1) and each pole ring repeat their vertices for the UVs, at exactly
/// the same positions, so a position weld closes the surface.
///
/// ```
/// let (p, t, uv) = cloth_vis::object::uv_sphere(8, 16);
/// assert_eq!((p.len(), uv.len(), t.len()), (9 * 17, 9 * 17, 2 * 8 * 16 - 2 * 16));
/// assert!(p.iter().all(|p| (p.length() - 1.0).abs() < 1e-6));
/// ```
pub fn uv_sphere(rings: u32, segments: u32) -> (Vec<Vec3>, Vec<[u32; 3]>, Vec<Vec2>) {
    let (rings, segments) = (rings.max(2), segments.max(2));
    let mut positions = Vec::new();
    let mut uvs = Vec::new();
    for r in 0..=rings {
        let v = r as f32 / rings as f32;
        let theta = v * std::f32::consts::PI;
        for s in 0..=segments {
            let u = s as f32 / segments as f32;
            // The seam column repeats column 0 and the poles are exact, bit for bit, so the
            // fins see one closed surface (`fins_stage::welded_triangles`).
            let phi = (s % segments) as f32 / segments as f32 * std::f32::consts::TAU;
            let (sin_t, cos_t) = match r {
                0 => (0.0, 1.0),
                _ if r == rings => (0.0, -1.0),
                _ => (theta.sin(), theta.cos()),
            };
            positions.push(Vec3::new(sin_t * phi.cos(), cos_t, -sin_t * phi.sin()));
            uvs.push(Vec2::new(u, v));
        }
    }
    let row = segments + 1;
    let mut triangles = Vec::new();
    for r in 0..rings {
        for s in 0..segments {
            let (a, b) = (r * row + s, r * row + s + 1);
            let (c, d) = (a + row, b + row);
            if r > 0 {
                triangles.push([a, c, b]);
            }
            if r + 1 < rings {
                triangles.push([b, c, d]);
            }
        }
    }
    (positions, triangles, uvs)
}
