//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use glam::Vec3;

/// Writes `contents` to `dir/name` and returns the path.
pub fn write(dir: &Path, name: &str, contents: impl AsRef<[u8]>) -> PathBuf {
    let path = dir.join(name);
    if let Some(parent) = path.parent() {
        std::fs::create_dir_all(parent).unwrap();
    }
    std::fs::write(&path, contents).unwrap();
    path
}

/// Asserts `|a - b| <= tol` componentwise-norm, naming the values.
#[track_caller]
pub fn assert_close(a: Vec3, b: Vec3, tol: f32) {
    assert!(
        (a - b).length() <= tol,
        "{a} vs {b}: distance {} > {tol}",
        (a - b).length()
    );
}

/// Counts how many times each undirected edge occurs.
pub fn undirected_edges(triangles: &[[u32; 3]]) -> HashMap<(u32, u32), usize> {
    let mut edges = HashMap::new();
    for t in triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    edges
}

/// Counts directed edges (a → b as they appear in the triangles' winding).
pub fn directed_edges(triangles: &[[u32; 3]]) -> HashMap<(u32, u32), usize> {
    let mut edges = HashMap::new();
    for t in triangles {
        for k in 0..3 {
            *edges.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
        }
    }
    edges
}

/// A glTF of one mesh whose POSITION is `accessor`, read from a 36-byte buffer at `uri`
/// through one buffer view: the skeleton the crafted (and hostile) glTF cases vary.
pub fn one_mesh_gltf(accessor: serde_json::Value, uri: &str) -> serde_json::Value {
    serde_json::json!({
        "asset": {"version": "2.0"},
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "buffers": [{"byteLength": 36, "uri": uri}],
        "bufferViews": [{"buffer": 0, "byteLength": 36}],
        "accessors": [accessor],
    })
}

/// Standard base64 (for data URIs in crafted glTF files).
pub fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            *chunk.get(1).unwrap_or(&0),
            *chunk.get(2).unwrap_or(&0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ALPHABET[((n >> (18 - 6 * k)) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// Vertex `v`'s area-weighted normal in f64 by brute force over all triangles, straight from
/// the definition in `meshio`'s normals module: its own triangles' sum, or, when that cancels,
/// its neighbours' mean.
pub fn reference_area_normal(positions: &[Vec3], triangles: &[[u32; 3]], v: u32) -> glam::DVec3 {
    let own = |v: u32| {
        let (mut sum, mut weight) = (glam::DVec3::ZERO, 0.0);
        for t in triangles.iter().filter(|t| t.contains(&v)) {
            let [a, b, c] = t.map(|i| positions[i as usize].as_dvec3());
            sum += (b - a).cross(c - a);
            weight += (b - a).cross(c - a).length();
        }
        // The documented cancellation rule (meshio::CANCELLED_RELATIVE).
        (sum.length() > meshio::CANCELLED_RELATIVE * weight).then(|| sum.normalize())
    };
    if let Some(n) = own(v) {
        return n;
    }
    // The fallback: the mean of the neighbours' own normals, once per triangle corner.
    let mut mean = glam::DVec3::ZERO;
    for t in triangles.iter().filter(|t| t.contains(&v)) {
        for &o in t.iter().filter(|&&o| o != v) {
            mean += own(o).unwrap_or_default();
        }
    }
    mean.normalize_or_zero()
}

/// An ASCII PLY with `x y z` vertices and `list uchar int` faces.
pub fn ply_ascii(vertices: &str, faces: &str, vertex_count: usize, face_count: usize) -> String {
    format!(
        "ply\nformat ascii 1.0\nelement vertex {vertex_count}\nproperty float x\nproperty float y\nproperty float z\n\
         element face {face_count}\nproperty list uchar int vertex_indices\nend_header\n{vertices}{faces}"
    )
}

pub const QUAD_VERTICES: &str = "0 0 0\n1 0 0\n1 1 0\n0 1 0\n";

/// A binary PLY with `x y z` floats and `list uchar int` faces in the given byte order.
pub fn ply_binary(big: bool, vertices: &[[f32; 3]], faces: &[&[i32]]) -> Vec<u8> {
    let format = if big {
        "binary_big_endian"
    } else {
        "binary_little_endian"
    };
    let mut out = format!(
        "ply\nformat {format} 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        vertices.len(),
        faces.len()
    )
    .into_bytes();
    for v in vertices {
        for c in v {
            out.extend_from_slice(&if big {
                c.to_be_bytes()
            } else {
                c.to_le_bytes()
            });
        }
    }
    for f in faces {
        out.push(f.len() as u8);
        for i in *f {
            out.extend_from_slice(&if big {
                i.to_be_bytes()
            } else {
                i.to_le_bytes()
            });
        }
    }
    out
}
