//! Fin geometry for silhouette enhancement of fuzzy cloth (thesis §5.7.3, after Lengyel et al.
//! 2001): per frame, the mesh's silhouette edges for the current viewer, each extruded along
//! its vertex normals into a quad ("fin") that a grazing-view fibre texture is drawn on.
//!
//! - **Silhouette edges** (§5.7.3, "fin edges" E_F): an edge with one front- and one back-facing
//!   triangle, or a border edge (one triangle: the rim of an open surface such as a sleeve). A
//!   triangle is front-facing when (e − p₀)·((p₁ − p₀) × (p₂ − p₀)) > 0 in f64 for an eye e
//!   ([`Viewer::Eye`]), or d·n > 0 for a direction d towards the viewer ([`Viewer::Direction`]);
//!   a triangle seen exactly edge-on (= 0) counts as back-facing (it covers no area). An edge
//!   shared by more than two triangles is a silhouette when its triangles do not all face the
//!   same way.
//! - **Orientation and loops**: each silhouette edge runs the way its front-facing triangle
//!   (a border edge: its triangle if front-facing, reversed if not) traverses it, so the edges of
//!   a closed mesh's silhouette join head to tail into loops. They are chained per frame: open
//!   paths first, from the vertices where one starts, then the closed loops.
//! - **Texture coordinates**: eqs. 5.16–5.21 as printed give V1: (L, O), V2: (D, O) with
//!   D = |uv(V1)| and L the edge's UV length (5.16, 5.17) — a texture span of |D − L| and a
//!   jump at every shared vertex. This module uses the intended reading V1: (D, O),
//!   V2: (D + L, O), V3: (D, 1), V4: (D + L, 1) with **D the running length along the chain** and
//!   L the edge's world length, both in material units ([`FinParams::material_size`]), so the
//!   texture runs on continuously across every shared vertex of a loop (the value at a joint is
//!   the same float on both fins) and repeats once per material size whatever the UV seams.
//! - **Extrusion**: V3 = V1 + h·n̂₁, V4 = V2 + h·n̂₂ with h = [`FinParams::height`] material
//!   units; a vertex without a usable normal takes the mean of its edge's face normals.
//! - **The two ends** (blend01/blend02 of Listing 5.1): each fin vertex carries the weight of
//!   its V2 end, 0 at V1 and V3, 1 at V2 and V4, so a shader blends the fin lit as at V1
//!   ((1 − w)·F(light at V1)) with the fin lit as at V2 (w·F(light at V2)), and the mesh vertex
//!   each end comes from, to look its light up.
//!
//! [`FinBuilder`] keeps every buffer between frames (sized for the worst case when built), so a
//! deforming mesh is processed each frame without allocating.
//!
//! ```
//! use btf::fins::{FinBuilder, FinMesh, FinParams, Viewer};
//! use glam::Vec3;
//!
//! // A square of two triangles facing +Z: its four border edges are its silhouette.
//! let positions = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
//! let normals = [Vec3::Z; 4];
//! let mut builder = FinBuilder::new(&[[0, 1, 2], [0, 2, 3]], 4).unwrap();
//! let mut fins = FinMesh::default();
//! let params = FinParams { material_size: 0.5, height: 0.2, offset: 0.0 };
//! builder.build(&positions, &normals, Viewer::Eye(Vec3::new(0.3, 0.4, 2.0)), &params, &mut fins);
//! assert_eq!(fins.len(), 4);
//! // One closed loop of length 4 world units = 8 material units.
//! assert_eq!(fins.chains(), 1);
//! assert_eq!(fins.texcoords[4 * 3 + 1].x, 8.0);
//! // Extruded 0.2 × 0.5 along +Z.
//! assert!((fins.positions[2].z - 0.1).abs() < 1e-6);
//! ```

use glam::{DVec3, Vec2, Vec3};

/// Where the viewer is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Viewer {
    /// A perspective eye at this world position.
    Eye(Vec3),
    /// An orthographic view: the world direction towards the viewer.
    Direction(Vec3),
}

/// Fin size and texture mapping.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FinParams {
    /// World length of one repeat of the fin texture along the edge (a material unit).
    pub material_size: f32,
    /// Fin height in material units (world height = `height × material_size`).
    pub height: f32,
    /// O: the texture's t at the fin's base (the material's fin offset, eqs. 5.18–5.21); its
    /// tip is at t = 1.
    pub offset: f32,
}

impl Default for FinParams {
    fn default() -> Self {
        Self {
            material_size: 1.0,
            height: 0.25,
            offset: 0.0,
        }
    }
}

/// Why a mesh cannot carry fins.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum FinError {
    /// A triangle names a vertex that does not exist.
    #[error("triangle {triangle} names vertex {vertex}, but the mesh has {vertices} vertices")]
    VertexOutOfRange {
        /// The triangle's index.
        triangle: usize,
        /// The vertex it names.
        vertex: u32,
        /// The mesh's vertex count.
        vertices: usize,
    },
}

/// The fins of one frame: four vertices per fin (V1, V2, V3, V4: base at V1, base at V2, tip
/// above V1, tip above V2), drawn as the triangles (V1, V2, V4) and (V1, V4, V3).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FinMesh {
    /// World positions, 4 per fin.
    pub positions: Vec<Vec3>,
    /// Texture coordinates (s along the chain in material units, t from O at the base to 1 at
    /// the tip), 4 per fin.
    pub texcoords: Vec<Vec2>,
    /// Weight of the V2 end (blend02; blend01 = 1 − w), 4 per fin: 0, 1, 0, 1.
    pub end_weight: Vec<f32>,
    /// The mesh vertices of each fin's two ends (V1, V2), 1 per fin.
    pub ends: Vec<[u32; 2]>,
    /// Index of the chain each fin belongs to, 1 per fin (fins of a chain are consecutive).
    pub chain: Vec<u32>,
}

impl FinMesh {
    /// Fins in this frame.
    pub fn len(&self) -> usize {
        self.ends.len()
    }

    /// Whether there are none (no silhouette).
    pub fn is_empty(&self) -> bool {
        self.ends.is_empty()
    }

    /// Silhouette chains (closed loops and open paths).
    pub fn chains(&self) -> usize {
        self.chain.last().map_or(0, |c| *c as usize + 1)
    }

    /// The fins' triangles as indices into [`FinMesh::positions`]: two per fin.
    pub fn triangles(&self) -> impl Iterator<Item = [u32; 3]> + '_ {
        (0..self.len() as u32).flat_map(|f| {
            let b = 4 * f;
            [[b, b + 1, b + 3], [b, b + 3, b + 2]]
        })
    }

    fn clear(&mut self) {
        self.positions.clear();
        self.texcoords.clear();
        self.end_weight.clear();
        self.ends.clear();
        self.chain.clear();
    }

    fn reserve(&mut self, fins: usize) {
        self.positions.reserve(4 * fins);
        self.texcoords.reserve(4 * fins);
        self.end_weight.reserve(4 * fins);
        self.ends.reserve(fins);
        self.chain.reserve(fins);
    }
}

/// A unique undirected edge: its vertices in the winding of its first triangle, and where its
/// triangles are listed.
#[derive(Clone, Copy, Debug)]
struct Edge {
    a: u32,
    b: u32,
    /// Range into `FinBuilder::edge_faces`.
    first: u32,
    count: u32,
}

/// Extracts fins frame after frame for one triangle topology ([`FinBuilder::build`]).
#[derive(Clone, Debug)]
pub struct FinBuilder {
    triangles: Vec<[u32; 3]>,
    vertices: usize,
    edges: Vec<Edge>,
    /// Triangles per edge, (triangle, whether it runs a → b).
    edge_faces: Vec<(u32, bool)>,
    // Per-frame scratch, sized once.
    front: Vec<bool>,
    /// Silhouette edges of the frame, oriented: (from, to, edge).
    silhouette: Vec<(u32, u32, u32)>,
    /// Out-edges per vertex (CSR over `silhouette`, by `from`).
    out_start: Vec<u32>,
    out_edges: Vec<u32>,
    in_degree: Vec<u32>,
    used: Vec<bool>,
}

impl FinBuilder {
    /// The edge structure of `triangles` over `vertices` vertices (built once per topology).
    /// Degenerate triangles (a repeated vertex) contribute no edges.
    ///
    /// # Errors
    /// [`FinError::VertexOutOfRange`] for a triangle naming a missing vertex.
    pub fn new(triangles: &[[u32; 3]], vertices: usize) -> Result<Self, FinError> {
        let mut keyed: Vec<(u32, u32, u32, bool)> = Vec::with_capacity(3 * triangles.len());
        for (t, tri) in triangles.iter().enumerate() {
            if let Some(&vertex) = tri.iter().find(|&&v| v as usize >= vertices) {
                return Err(FinError::VertexOutOfRange {
                    triangle: t,
                    vertex,
                    vertices,
                });
            }
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                if a != b {
                    keyed.push((a.min(b), a.max(b), t as u32, a < b));
                }
            }
        }
        keyed.sort_unstable();
        let mut edges = Vec::new();
        let mut edge_faces = Vec::with_capacity(keyed.len());
        let mut i = 0;
        while i < keyed.len() {
            let (lo, hi, first_face, forward) = keyed[i];
            let (a, b) = if forward { (lo, hi) } else { (hi, lo) };
            let first = edge_faces.len() as u32;
            while i < keyed.len() && (keyed[i].0, keyed[i].1) == (lo, hi) {
                // Stored relative to (a, b): whether the face runs a → b.
                let runs_lo_hi = keyed[i].3;
                edge_faces.push((keyed[i].2, runs_lo_hi == forward));
                i += 1;
            }
            debug_assert_eq!(edge_faces[first as usize].0, first_face);
            edges.push(Edge {
                a,
                b,
                first,
                count: edge_faces.len() as u32 - first,
            });
        }
        let n_edges = edges.len();
        Ok(Self {
            triangles: triangles.to_vec(),
            vertices,
            edges,
            edge_faces,
            front: vec![false; triangles.len()],
            silhouette: Vec::with_capacity(n_edges),
            out_start: vec![0; vertices + 1],
            out_edges: vec![0; n_edges],
            in_degree: vec![0; vertices],
            used: vec![false; n_edges],
        })
    }

    /// Unique edges of the topology.
    pub fn edge_count(&self) -> usize {
        self.edges.len()
    }

    /// The silhouette edges for `viewer` as (from, to) vertex pairs, oriented as in the module
    /// docs, in the topology's edge order.
    ///
    /// # Panics
    /// When `positions` is shorter than the vertex count given to [`FinBuilder::new`].
    pub fn silhouette_edges(&mut self, positions: &[Vec3], viewer: Viewer) -> Vec<[u32; 2]> {
        self.classify(positions, viewer);
        self.silhouette.iter().map(|&(a, b, _)| [a, b]).collect()
    }

    /// Facing of every triangle, then the oriented silhouette edges of the frame.
    fn classify(&mut self, positions: &[Vec3], viewer: Viewer) {
        assert!(
            positions.len() >= self.vertices,
            "{} positions for {} vertices",
            positions.len(),
            self.vertices
        );
        for (front, tri) in self.front.iter_mut().zip(&self.triangles) {
            let [p0, p1, p2] = tri.map(|v| positions[v as usize].as_dvec3());
            let n = (p1 - p0).cross(p2 - p0);
            let towards = match viewer {
                Viewer::Eye(e) => e.as_dvec3() - p0,
                Viewer::Direction(d) => d.as_dvec3(),
            };
            *front = n.dot(towards) > 0.0;
        }
        self.silhouette.clear();
        for (e, edge) in self.edges.iter().enumerate() {
            let faces = &self.edge_faces[edge.first as usize..(edge.first + edge.count) as usize];
            let orientation = if faces.len() == 1 {
                // Border: as its triangle runs it when that faces the viewer.
                let (t, runs_ab) = faces[0];
                Some(runs_ab == self.front[t as usize])
            } else {
                let front = faces.iter().find(|(t, _)| self.front[*t as usize]);
                let back = faces.iter().any(|(t, _)| !self.front[*t as usize]);
                match (front, back) {
                    (Some(&(_, runs_ab)), true) => Some(runs_ab),
                    _ => None,
                }
            };
            if let Some(ab) = orientation {
                let (from, to) = if ab {
                    (edge.a, edge.b)
                } else {
                    (edge.b, edge.a)
                };
                self.silhouette.push((from, to, e as u32));
            }
        }
    }

    /// The fins of one frame into `out` (cleared first; its buffers keep their capacity):
    /// silhouette edges for `viewer` chained into loops and paths, extruded along `normals`.
    ///
    /// # Panics
    /// When `positions` or `normals` is shorter than the vertex count given to
    /// [`FinBuilder::new`].
    pub fn build(
        &mut self,
        positions: &[Vec3],
        normals: &[Vec3],
        viewer: Viewer,
        params: &FinParams,
        out: &mut FinMesh,
    ) {
        assert!(normals.len() >= self.vertices, "one normal per vertex");
        self.classify(positions, viewer);
        out.clear();
        out.reserve(self.edges.len());
        // Out-edges per vertex (counting sort by `from`) and in-degrees.
        self.out_start.fill(0);
        self.in_degree.fill(0);
        for &(from, to, _) in &self.silhouette {
            self.out_start[from as usize + 1] += 1;
            self.in_degree[to as usize] += 1;
        }
        for v in 0..self.vertices {
            self.out_start[v + 1] += self.out_start[v];
        }
        // `out_start[v]` doubles as v's fill cursor: each edge goes to the next free slot.
        for (s, &(from, _, _)) in self.silhouette.iter().enumerate() {
            let slot = self.out_start[from as usize] as usize;
            self.out_edges[slot] = s as u32;
            self.out_start[from as usize] += 1;
        }
        // The cursors ended at the next vertex's start: shift them back.
        for v in (0..self.vertices).rev() {
            self.out_start[v + 1] = self.out_start[v];
        }
        self.out_start[0] = 0;
        self.used[..self.silhouette.len()].fill(false);
        let unit = f64::from(params.material_size);
        let height = f64::from(params.height) * unit;
        let mut chain = 0u32;
        // Open paths start where more silhouette edges leave a vertex than arrive; then loops.
        for pass in 0..2 {
            for s in 0..self.silhouette.len() {
                if self.used[s] {
                    continue;
                }
                let from = self.silhouette[s].0 as usize;
                let degree_out = self.out_start[from + 1] - self.out_start[from];
                if pass == 0 && degree_out <= self.in_degree[from] {
                    continue;
                }
                self.walk(s, chain, positions, normals, (unit, height), params, out);
                chain += 1;
            }
        }
    }

    /// Emits the chain starting with silhouette edge `first`, following unused out-edges head
    /// to tail; D runs from 0.
    #[allow(clippy::too_many_arguments)]
    fn walk(
        &mut self,
        first: usize,
        chain: u32,
        positions: &[Vec3],
        normals: &[Vec3],
        (unit, height): (f64, f64),
        params: &FinParams,
        out: &mut FinMesh,
    ) {
        let mut s = first;
        let mut running = 0.0f32;
        loop {
            self.used[s] = true;
            let (from, to, e) = self.silhouette[s];
            let (p1, p2) = (positions[from as usize], positions[to as usize]);
            let length = ((p2.as_dvec3() - p1.as_dvec3()).length() / unit) as f32;
            let (d0, d1) = (running, running + length);
            let face_normal = self.edge_normal(e as usize, positions);
            let lift = |v: u32| {
                let n = normals[v as usize];
                let n = if n.is_finite() && n.length_squared() > 0.0 {
                    n.as_dvec3().normalize()
                } else {
                    face_normal
                };
                (positions[v as usize].as_dvec3() + height * n).as_vec3()
            };
            out.positions.extend([p1, p2, lift(from), lift(to)]);
            out.texcoords.extend([
                Vec2::new(d0, params.offset),
                Vec2::new(d1, params.offset),
                Vec2::new(d0, 1.0),
                Vec2::new(d1, 1.0),
            ]);
            out.end_weight.extend([0.0, 1.0, 0.0, 1.0]);
            out.ends.push([from, to]);
            out.chain.push(chain);
            running = d1;
            // The next unused edge leaving `to`.
            let (start, end) = (
                self.out_start[to as usize] as usize,
                self.out_start[to as usize + 1] as usize,
            );
            match self.out_edges[start..end]
                .iter()
                .map(|&n| n as usize)
                .find(|&n| !self.used[n])
            {
                Some(next) => s = next,
                None => break,
            }
        }
    }

    /// The unit mean of edge `e`'s face normals (+Y when they cancel or are degenerate).
    fn edge_normal(&self, e: usize, positions: &[Vec3]) -> DVec3 {
        let edge = self.edges[e];
        let faces = &self.edge_faces[edge.first as usize..(edge.first + edge.count) as usize];
        let sum: DVec3 = faces
            .iter()
            .map(|&(t, _)| {
                let [p0, p1, p2] =
                    self.triangles[t as usize].map(|v| positions[v as usize].as_dvec3());
                (p1 - p0).cross(p2 - p0).normalize_or_zero()
            })
            .sum();
        sum.try_normalize().unwrap_or(DVec3::Y)
    }
}
