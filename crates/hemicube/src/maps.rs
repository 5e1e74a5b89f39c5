//! Per-vertex visibility maps stored as 1 bit per pixel plus the vertex frame.
//!
//! The seed stores 24-bit RGB per pixel (the cube-map texel a pixel sees, or (0,0,0) for
//! "occluded", a code that collides with texel (0, 0) of face 0, T 6020–6026; SEED-NOTES §1.10).
//! Here a pixel is one bit, **1 = open** (the environment is seen), and its direction is rebuilt
//! from the pixel index and the vertex frame: 24× smaller (HC 64²: 1,536 + 16 bytes per vertex
//! instead of 36 KiB) and no collision.

use std::sync::Arc;

use glam::{Mat3, Quat, Vec3};

use crate::layout::PixelLayout;

/// The orthonormal frame of a vertex's map: z = the normal, x and y in the tangent plane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VertexFrame {
    /// World from vertex frame.
    pub rotation: Quat,
}

impl VertexFrame {
    /// The frame of a unit normal with a tangent chosen continuously from it (Duff et al. 2017,
    /// "Building an orthonormal basis, revisited"); the in-plane orientation is arbitrary
    /// (SEED-NOTES §1.9) and only fixes where a direction lands in the map.
    pub fn from_normal(n: Vec3) -> Self {
        let sign = 1.0f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let t = Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let bt = Vec3::new(b, sign + n.y * n.y * a, -n.y);
        Self::from_axes(t, bt, n)
    }

    /// The frame of a unit normal and a tangent (Gram–Schmidt against the normal; falls back
    /// to [`VertexFrame::from_normal`] when the tangent is parallel to it).
    pub fn from_normal_tangent(n: Vec3, tangent: Vec3) -> Self {
        match (tangent - n * n.dot(tangent)).try_normalize() {
            Some(t) => Self::from_axes(t, n.cross(t), n),
            None => Self::from_normal(n),
        }
    }

    fn from_axes(t: Vec3, b: Vec3, n: Vec3) -> Self {
        Self {
            rotation: Quat::from_mat3(&Mat3::from_cols(t, b, n)).normalize(),
        }
    }

    /// The normal (world).
    pub fn normal(&self) -> Vec3 {
        self.rotation * Vec3::Z
    }

    /// A vertex-frame direction in the world.
    pub fn to_world(&self, local: Vec3) -> Vec3 {
        self.rotation * local
    }

    /// A world direction in the vertex frame.
    pub fn to_local(&self, world: Vec3) -> Vec3 {
        self.rotation.inverse() * world
    }
}

/// Bits per storage word.
const WORD: usize = 64;

/// The visibility maps of N vertices in one model: bit p of vertex i is 1 when pixel p sees the
/// environment. A vertex used by no triangle has no frame and an all-zero map.
#[derive(Clone, Debug)]
pub struct VisibilityMaps {
    layout: Arc<PixelLayout>,
    frames: Vec<Option<VertexFrame>>,
    words_per_vertex: usize,
    bits: Vec<u64>,
}

impl VisibilityMaps {
    /// All-occluded maps for `frames.len()` vertices.
    pub fn new(layout: Arc<PixelLayout>, frames: Vec<Option<VertexFrame>>) -> Self {
        let words_per_vertex = layout.len().div_ceil(WORD);
        let bits = vec![0; words_per_vertex * frames.len()];
        Self {
            layout,
            frames,
            words_per_vertex,
            bits,
        }
    }

    /// The pixel layout shared by every map.
    pub fn layout(&self) -> &PixelLayout {
        &self.layout
    }

    /// The shared layout (for building other maps over it).
    pub fn layout_arc(&self) -> &Arc<PixelLayout> {
        &self.layout
    }

    /// Number of vertices.
    pub fn len(&self) -> usize {
        self.frames.len()
    }

    /// Whether there are no vertices.
    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }

    /// Vertex i's frame (`None` for a vertex used by no triangle).
    pub fn frame(&self, i: usize) -> Option<VertexFrame> {
        self.frames[i]
    }

    /// Storage per vertex in bytes: the bits rounded up to 64-bit words, plus the frame as a
    /// unit quaternion (16 bytes).
    pub fn bytes_per_vertex(&self) -> usize {
        self.words_per_vertex * 8 + std::mem::size_of::<Quat>()
    }

    /// Whether pixel p of vertex i is open.
    pub fn is_open(&self, i: usize, p: usize) -> bool {
        self.bits[i * self.words_per_vertex + p / WORD] >> (p % WORD) & 1 == 1
    }

    /// Vertex i's words (bit p % 64 of word p / 64).
    pub fn words(&self, i: usize) -> &[u64] {
        &self.bits[i * self.words_per_vertex..][..self.words_per_vertex]
    }

    /// Mutable words of every vertex, `words_per_vertex` each, for builders.
    pub(crate) fn words_mut(&mut self) -> (&mut [u64], usize) {
        (&mut self.bits, self.words_per_vertex)
    }

    /// Open pixels of vertex i.
    pub fn open_pixels(&self, i: usize) -> impl Iterator<Item = usize> + '_ {
        self.words(i).iter().enumerate().flat_map(|(w, &word)| {
            let mut m = word;
            std::iter::from_fn(move || {
                (m != 0).then(|| {
                    let b = m.trailing_zeros() as usize;
                    m &= m - 1;
                    w * WORD + b
                })
            })
        })
    }

    /// The cosine-weighted open fraction Σ_p V_p ΔF_p of every vertex (1 = fully open for HC
    /// and HS with exact ΔF; at most F(A) for SP), accumulated in f64; NaN for a vertex used by
    /// no triangle. The same convention as `occlusion-gpu`'s a_i.
    pub fn open_fraction(&self) -> Vec<f32> {
        let ff = self.layout.form_factors();
        (0..self.len())
            .map(|i| match self.frames[i] {
                None => f32::NAN,
                // `+ 0.0`: an empty f64 sum is −0.0, and a closed vertex should read 0.
                Some(_) => {
                    (self.open_pixels(i).map(|p| f64::from(ff[p])).sum::<f64>() + 0.0) as f32
                }
            })
            .collect()
    }

    /// Number of pixels where `self` and `other` differ, per vertex.
    ///
    /// # Panics
    /// If the two have different vertex counts or layouts sizes.
    pub fn differing_pixels(&self, other: &VisibilityMaps) -> Vec<u32> {
        assert_eq!(self.bits.len(), other.bits.len(), "maps of different sizes");
        self.bits
            .chunks_exact(self.words_per_vertex)
            .zip(other.bits.chunks_exact(self.words_per_vertex))
            .map(|(a, b)| a.iter().zip(b).map(|(x, y)| (x ^ y).count_ones()).sum())
            .collect()
    }
}
