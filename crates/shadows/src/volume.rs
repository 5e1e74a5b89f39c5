//! Shadow volumes of a caster (thesis §2.4.1; the formulas the seed cites from Everitt &
//! Kilgard 2002, SEED-NOTES §3.2), rebuilt per frame for deforming meshes.
//!
//! **Construction.** Every face that casts (see [`Sides`]) contributes a *prism*: the face
//! itself wound towards the light (the front cap), the same face pushed away from the light
//! with the opposite winding (the back cap), and one quad per edge joining them. Neighbouring
//! prisms share their inner quads with opposite windings, so only the edges where the signed
//! count of casting faces does not cancel are emitted — the silhouette edges with respect to
//! the light, border edges of open meshes included (§2.2.3, T 2854–2861):
//!
//! > c(e) = Σ_f o_f · s_f(e), with o_f = ±1 the face's orientation towards the light and
//! > s_f(e) = ±1 whether its winding runs along e; |c(e)| quads are emitted, wound by sign.
//!
//! On a closed one-sided mesh this is exactly the classic silhouette (one light-facing and one
//! back-facing neighbour). Unlike the classic construction (front cap = light-facing faces,
//! back cap = back-facing faces at infinity) it stays a union of closed prisms on open and
//! non-manifold meshes, so the stencil count of a point is the number of casting faces between
//! it and the light: 0 exactly when it is lit. With [`Sides::Two`] every face casts, turned
//! towards the light (cloth has no inside); a fold then puts two layers in front of what is
//! behind it and its edge gets two quads.
//!
//! **Extrusion** to infinity ([`Extrusion::Infinite`]: v∞ = (v − L, 0) for a point light,
//! (−d, 0) for a directional one) for a perspective frame with an infinite far plane; or to a
//! finite distance ([`Extrusion::Finite`], w = 1) where the projection cannot take points at
//! infinity (an orthographic view) or where a CPU check needs a bounded volume.
//!
//! **Precision.** Facing tests run in f64 on the f32 positions; output vertices are relative to
//! [`VolumeParams::origin`] (subtracted in f64), so a caster 1e5 from the world origin keeps
//! its digits when the frame is rendered camera-relative.
//!
//! **Rules for the hard cases.** A face whose light vector lies in its plane (n·l = 0, within
//! 1e-12 relative) or that has zero area casts nothing (its prism has no volume); a face with
//! a vertex at a point light casts nothing (the extrusion direction is undefined); duplicated
//! faces cast twice (the count is still 0 only where lit); edges of a triangle that names a
//! vertex twice are ignored.

use glam::{DVec3, Vec3};

use crate::{Light, ShadowError};

/// Whether back faces cast.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Sides {
    /// Only faces whose counter-clockwise side faces the light cast: closed, consistently
    /// wound solids (the bunny).
    #[default]
    One,
    /// Every face casts, turned towards the light: cloth and other open two-sided sheets.
    Two,
}

/// How far volumes reach.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Extrusion {
    /// To infinity (w = 0): a perspective frame with an infinite far plane.
    Infinite,
    /// To this distance from each vertex along the light direction (w = 1). It must exceed the
    /// distance from the caster to anything that can receive its shadow.
    Finite(f64),
}

/// Parameters of [`ShadowVolume::build`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VolumeParams {
    /// Which faces cast.
    pub sides: Sides,
    /// How far the volume reaches.
    pub extrusion: Extrusion,
    /// Subtracted (in f64) from every output vertex: the camera-relative origin.
    pub origin: DVec3,
    /// Each caster vertex moves this far along its normal before extrusion (≥ 0): inwards for
    /// [`Sides::One`], away from the light's side for [`Sides::Two`]. The offset rule that keeps
    /// a coarse caster from shadowing the fine surface it approximates: its backward Hausdorff
    /// distance ([`crate::LodLevel::receiver_offset`]), the farthest the coarse surface stands
    /// out of the fine one. Moving along the light instead would not do: on a slope the gap
    /// measured along the light is the Hausdorff distance divided by cos(n, l). 0 for a full
    /// caster.
    pub offset: f64,
}

impl Default for VolumeParams {
    fn default() -> Self {
        Self {
            sides: Sides::One,
            extrusion: Extrusion::Infinite,
            origin: DVec3::ZERO,
            offset: 0.0,
        }
    }
}

/// One use of an edge by a face.
#[derive(Clone, Copy, Debug)]
struct EdgeUse {
    face: u32,
    /// The face's winding runs from the lower vertex index to the higher.
    forward: bool,
}

/// The edge structure of a caster, built once per topology (a deforming mesh keeps it).
#[derive(Clone, Debug)]
pub struct CasterTopology {
    vertex_count: usize,
    triangles: Vec<[u32; 3]>,
    /// Undirected edges as (lower, higher) vertex index.
    edges: Vec<[u32; 2]>,
    /// `uses[offsets[e]..offsets[e + 1]]` are the faces of edge `e`.
    offsets: Vec<u32>,
    uses: Vec<EdgeUse>,
    /// Vertices some triangle uses, ascending.
    used: Vec<u32>,
}

impl CasterTopology {
    /// Index the edges of `triangles` over `vertex_count` vertices.
    ///
    /// # Errors
    /// [`ShadowError::Mesh`] when a triangle names a vertex ≥ `vertex_count` or there are more
    /// than 2³¹ triangles.
    pub fn new(vertex_count: usize, triangles: &[[u32; 3]]) -> Result<Self, ShadowError> {
        if triangles.len() > (i32::MAX as usize) / 3 {
            return Err(ShadowError::Mesh(format!(
                "{} triangles: at most {} are supported",
                triangles.len(),
                i32::MAX / 3
            )));
        }
        if let Some((t, tri)) = triangles
            .iter()
            .enumerate()
            .find(|(_, t)| t.iter().any(|&v| v as usize >= vertex_count))
        {
            return Err(ShadowError::Mesh(format!(
                "triangle {t} = {tri:?} names a vertex ≥ {vertex_count}"
            )));
        }
        let mut directed: Vec<(u32, u32, u32, bool)> = Vec::with_capacity(triangles.len() * 3);
        for (f, t) in triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                if a != b {
                    directed.push((a.min(b), a.max(b), f as u32, a < b));
                }
            }
        }
        directed.sort_unstable_by_key(|&(lo, hi, f, _)| (lo, hi, f));
        let mut edges = Vec::new();
        let mut offsets = Vec::new();
        let mut uses = Vec::with_capacity(directed.len());
        for (i, &(lo, hi, face, forward)) in directed.iter().enumerate() {
            if i == 0 || (directed[i - 1].0, directed[i - 1].1) != (lo, hi) {
                edges.push([lo, hi]);
                offsets.push(uses.len() as u32);
            }
            uses.push(EdgeUse { face, forward });
        }
        offsets.push(uses.len() as u32);
        let mut used: Vec<u32> = triangles.iter().flatten().copied().collect();
        used.sort_unstable();
        used.dedup();
        Ok(Self {
            used,
            vertex_count,
            triangles: triangles.to_vec(),
            edges,
            offsets,
            uses,
        })
    }

    /// Number of vertices the caster's positions must have.
    pub fn vertex_count(&self) -> usize {
        self.vertex_count
    }

    /// The caster's triangles.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// Number of undirected edges.
    pub fn edge_count(&self) -> usize {
        self.edges.len()
    }

    /// Edges used by exactly one face (the border of an open mesh).
    pub fn border_edge_count(&self) -> usize {
        self.offsets.windows(2).filter(|w| w[1] - w[0] == 1).count()
    }
}

/// What one build produced.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct VolumeStats {
    /// Faces that cast (each gives a front and a back cap).
    pub casting_faces: usize,
    /// Edges with at least one quad (silhouette and border edges with respect to the light).
    pub silhouette_edges: usize,
    /// Side quads (two triangles each).
    pub quads: usize,
}

impl VolumeStats {
    /// Triangles of the volume: two caps per casting face, two per quad.
    pub fn triangles(&self) -> usize {
        2 * self.casting_faces + 2 * self.quads
    }
}

/// A caster's shadow volume for one light: a triangle soup of homogeneous vertices, rebuilt in
/// place every frame (no allocation once the buffers have grown to the largest volume).
#[derive(Clone, Debug, Default)]
pub struct ShadowVolume {
    orientation: Vec<i8>,
    moved: Vec<DVec3>,
    normals: Vec<DVec3>,
    near: Vec<[f32; 4]>,
    far: Vec<[f32; 4]>,
    vertices: Vec<[f32; 4]>,
    stats: VolumeStats,
}

impl ShadowVolume {
    /// Empty buffers.
    pub fn new() -> Self {
        Self::default()
    }

    /// Build the volume of `positions` (world space, the topology's vertex order) for `light`.
    ///
    /// # Errors
    /// [`ShadowError::Mesh`] when `positions` has the wrong length or a non-finite entry;
    /// [`ShadowError::Light`] for an invalid light; [`ShadowError::Parameter`] for a finite
    /// extrusion that is not positive and finite.
    pub fn build(
        &mut self,
        topology: &CasterTopology,
        positions: &[Vec3],
        light: &Light,
        params: &VolumeParams,
    ) -> Result<VolumeStats, ShadowError> {
        let light = light.validated()?;
        if positions.len() != topology.vertex_count {
            return Err(ShadowError::Mesh(format!(
                "{} positions for a caster topology of {} vertices",
                positions.len(),
                topology.vertex_count
            )));
        }
        if let Some((i, p)) = positions.iter().enumerate().find(|(_, p)| !p.is_finite()) {
            return Err(ShadowError::Mesh(format!("vertex {i} = {p} is not finite")));
        }
        if !(params.offset >= 0.0 && params.offset.is_finite()) {
            return Err(crate::error::bad_parameter(
                "caster offset",
                params.offset,
                "must be finite and ≥ 0",
            ));
        }
        if let Extrusion::Finite(d) = params.extrusion
            && !(d > 0.0 && d.is_finite())
        {
            return Err(crate::error::bad_parameter(
                "extrusion distance",
                d,
                "must be positive and finite",
            ));
        }
        self.orient_faces(topology, positions, &light, params.sides);
        self.offset_vertices(topology, positions, &light, params);
        self.extrude_vertices(topology, &light, params);
        self.assemble(topology);
        Ok(self.stats)
    }

    /// Per face: +1 casts as wound, −1 casts turned over, 0 casts nothing.
    fn orient_faces(
        &mut self,
        topology: &CasterTopology,
        positions: &[Vec3],
        light: &Light,
        sides: Sides,
    ) {
        self.orientation.clear();
        let at = |i: u32| positions[i as usize].as_dvec3();
        for t in &topology.triangles {
            let (a, b, c) = (at(t[0]), at(t[1]), at(t[2]));
            let n = (b - a).cross(c - a);
            let centroid = (a + b + c) / 3.0;
            let l = light.to_light(centroid);
            let touches_light = matches!(light, Light::Point(p) if [a, b, c].contains(p));
            let s = n.dot(l);
            let facing = if touches_light || s.abs() <= 1e-12 * n.length() * l.length() {
                0
            } else if s > 0.0 {
                1
            } else {
                -1
            };
            self.orientation.push(match sides {
                Sides::One => facing.max(0),
                Sides::Two => facing,
            });
        }
    }

    /// The caster's vertices in f64, moved by the offset rule (see [`VolumeParams::offset`]).
    fn offset_vertices(
        &mut self,
        topology: &CasterTopology,
        positions: &[Vec3],
        light: &Light,
        params: &VolumeParams,
    ) {
        // Only the vertices the caster's triangles use: a 1 % level touches 1 % of them.
        self.moved.resize(positions.len(), DVec3::ZERO);
        for &i in &topology.used {
            self.moved[i as usize] = positions[i as usize].as_dvec3();
        }
        if params.offset == 0.0 {
            return;
        }
        self.normals.resize(positions.len(), DVec3::ZERO);
        for &i in &topology.used {
            self.normals[i as usize] = DVec3::ZERO;
        }
        for t in &topology.triangles {
            let [a, b, c] = t.map(|i| self.moved[i as usize]);
            let n = (b - a).cross(c - a);
            for &i in t {
                self.normals[i as usize] += n;
            }
        }
        for &i in &topology.used {
            let (v, n) = (&mut self.moved[i as usize], self.normals[i as usize]);
            let n = n.normalize_or_zero();
            let side = match params.sides {
                Sides::One => 1.0,
                Sides::Two if n.dot(light.towards(*v)) < 0.0 => -1.0,
                Sides::Two => 1.0,
            };
            *v -= n * (side * params.offset);
        }
    }

    fn extrude_vertices(
        &mut self,
        topology: &CasterTopology,
        light: &Light,
        params: &VolumeParams,
    ) {
        self.near.resize(self.moved.len(), [0.0; 4]);
        self.far.resize(self.moved.len(), [0.0; 4]);
        for &i in &topology.used {
            let v = self.moved[i as usize];
            let rel = v - params.origin;
            self.near[i as usize] = [rel.x as f32, rel.y as f32, rel.z as f32, 1.0];
            let away = -light.to_light(v);
            self.far[i as usize] = match params.extrusion {
                Extrusion::Infinite => [away.x as f32, away.y as f32, away.z as f32, 0.0],
                Extrusion::Finite(d) => {
                    let e = rel + away.normalize_or_zero() * d;
                    [e.x as f32, e.y as f32, e.z as f32, 1.0]
                }
            };
        }
    }

    fn assemble(&mut self, topology: &CasterTopology) {
        self.vertices.clear();
        let mut stats = VolumeStats::default();
        let (near, far) = (&self.near, &self.far);
        for (t, &o) in topology.triangles.iter().zip(&self.orientation) {
            if o == 0 {
                continue;
            }
            stats.casting_faces += 1;
            let [a, b, c] = t.map(|i| i as usize);
            let (b, c) = if o > 0 { (b, c) } else { (c, b) };
            self.vertices
                .extend_from_slice(&[near[a], near[b], near[c]]);
            self.vertices.extend_from_slice(&[far[a], far[c], far[b]]);
        }
        for (e, &[lo, hi]) in topology.edges.iter().enumerate() {
            let uses =
                &topology.uses[topology.offsets[e] as usize..topology.offsets[e + 1] as usize];
            let count: i32 = uses
                .iter()
                .map(|u| {
                    let o = i32::from(self.orientation[u.face as usize]);
                    if u.forward { o } else { -o }
                })
                .sum();
            if count == 0 {
                continue;
            }
            stats.silhouette_edges += 1;
            let (a, b) = if count > 0 { (lo, hi) } else { (hi, lo) };
            let (a, b) = (a as usize, b as usize);
            for _ in 0..count.unsigned_abs() {
                stats.quads += 1;
                self.vertices
                    .extend_from_slice(&[near[a], far[a], far[b], near[a], far[b], near[b]]);
            }
        }
        self.stats = stats;
    }

    /// The volume as a triangle list of homogeneous vertices (x, y, z, w), relative to the
    /// build's origin; every triangle is wound counter-clockwise seen from outside.
    pub fn vertices(&self) -> &[[f32; 4]] {
        &self.vertices
    }

    /// Empty the volume, keeping its buffers (to [`ShadowVolume::append`] casters into).
    pub fn clear(&mut self) {
        self.vertices.clear();
        self.stats = VolumeStats::default();
    }

    /// Append the triangles of `other`, built for the same light, origin and extrusion:
    /// several casters drawn as one volume (the counts add, lit ⇔ 0 still holds).
    pub fn append(&mut self, other: &ShadowVolume) {
        self.vertices.extend_from_slice(&other.vertices);
        self.stats.casting_faces += other.stats.casting_faces;
        self.stats.silhouette_edges += other.stats.silhouette_edges;
        self.stats.quads += other.stats.quads;
    }

    /// What the last build produced.
    pub fn stats(&self) -> VolumeStats {
        self.stats
    }

    /// The winding number of the volume at `p` (relative to the build's origin): the signed
    /// count of volume faces a ray from `p` along `direction` crosses (+1 leaving, −1 entering),
    /// in f64 — what the stencil computes for a surface point seen along `direction`, and
    /// the number of casting faces between `p` and the light. Only meaningful for a volume
    /// built with [`Extrusion::Finite`] (returns `None` otherwise).
    pub fn winding_number(&self, p: DVec3, direction: DVec3) -> Option<i32> {
        let mut count = 0;
        for tri in self.vertices.chunks_exact(3) {
            if tri.iter().any(|v| v[3] != 1.0) {
                return None;
            }
            let [a, b, c] = [tri[0], tri[1], tri[2]]
                .map(|v| DVec3::new(f64::from(v[0]), f64::from(v[1]), f64::from(v[2])));
            if let Some(sign) = crossing(p, direction, a, b, c) {
                count += sign;
            }
        }
        Some(count)
    }
}

/// Möller–Trumbore in f64: the sign of n·d when the ray p + t·d (t > 0) crosses triangle abc.
fn crossing(p: DVec3, d: DVec3, a: DVec3, b: DVec3, c: DVec3) -> Option<i32> {
    let (e1, e2) = (b - a, c - a);
    let q = d.cross(e2);
    let det = e1.dot(q);
    if det == 0.0 {
        return None;
    }
    let inv = 1.0 / det;
    let s = p - a;
    let u = s.dot(q) * inv;
    let r = s.cross(e1);
    let v = d.dot(r) * inv;
    let t = e2.dot(r) * inv;
    let inside = u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > 0.0;
    // det = (d × e2)·e1 = −d·(e1 × e2): negative when the ray leaves through the face.
    inside.then_some(if det < 0.0 { 1 } else { -1 })
}
