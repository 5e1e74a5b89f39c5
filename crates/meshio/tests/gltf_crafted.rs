//! Skinning, morph targets, interpolation and node transforms checked on small glTF files
//! written by the test, whose positions are known analytically.

mod common;

use std::f32::consts::FRAC_PI_2;
use std::path::{Path, PathBuf};

use common::{assert_close, base64};
use glam::{Quat, Vec3};
use meshio::{AnimationOptions, ClipSelector, LoadOptions, MeshIoError, load_animation, load_mesh};
use serde_json::{Value, json};

/// Coordinates are at most 2 in magnitude and pass through a few f32 matrix products and a
/// slerp: a few dozen ulps of the largest coordinate.
const TOL: f32 = 64.0 * f32::EPSILON * 2.0;

/// Collects binary data and accessors for a glTF document.
#[derive(Default)]
struct Builder {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Builder {
    fn view(&mut self, bytes: &[u8]) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        self.views
            .push(json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()}));
        self.bin.extend_from_slice(bytes);
        self.views.len() - 1
    }

    /// A FLOAT accessor of type `ty` ("SCALAR", "VEC3", "VEC4", "MAT4" …).
    fn floats(&mut self, data: &[f32], ty: &str, components: usize) -> usize {
        let bytes: Vec<u8> = data.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(&bytes);
        let mut accessor = json!({"bufferView": view, "componentType": 5126, "count": data.len() / components, "type": ty});
        if ty == "VEC3" {
            let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
            for p in data.chunks(3) {
                lo = lo.min(Vec3::from_slice(p));
                hi = hi.max(Vec3::from_slice(p));
            }
            accessor["min"] = json!(lo.to_array());
            accessor["max"] = json!(hi.to_array());
        }
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    fn u16s(&mut self, data: &[u16], ty: &str, components: usize) -> usize {
        let bytes: Vec<u8> = data.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(&bytes);
        self.accessors.push(json!({"bufferView": view, "componentType": 5123, "count": data.len() / components, "type": ty}));
        self.accessors.len() - 1
    }

    fn positions(&mut self, points: &[Vec3]) -> usize {
        let flat: Vec<f32> = points.iter().flat_map(|p| p.to_array()).collect();
        self.floats(&flat, "VEC3", 3)
    }

    /// Writes `doc` (with this builder's buffer as a data URI) to `dir/name`.
    fn write_gltf(self, mut doc: Value, dir: &Path, name: &str) -> PathBuf {
        doc["asset"] = json!({"version": "2.0"});
        doc["buffers"] = json!([{
            "byteLength": self.bin.len(),
            "uri": format!("data:application/octet-stream;base64,{}", base64(&self.bin)),
        }]);
        doc["bufferViews"] = json!(self.views);
        doc["accessors"] = json!(self.accessors);
        common::write(dir, name, serde_json::to_vec_pretty(&doc).unwrap())
    }

    /// Writes `doc` as a binary .glb container (JSON chunk + BIN chunk).
    fn write_glb(self, mut doc: Value, dir: &Path, name: &str) -> PathBuf {
        doc["asset"] = json!({"version": "2.0"});
        let mut bin = self.bin;
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        doc["buffers"] = json!([{"byteLength": bin.len()}]);
        doc["bufferViews"] = json!(self.views);
        doc["accessors"] = json!(self.accessors);
        let mut json_bytes = serde_json::to_vec(&doc).unwrap();
        while !json_bytes.len().is_multiple_of(4) {
            json_bytes.push(b' ');
        }
        let total = 12 + 8 + json_bytes.len() + 8 + bin.len();
        let mut out = Vec::new();
        out.extend_from_slice(b"glTF");
        out.extend_from_slice(&2u32.to_le_bytes());
        out.extend_from_slice(&(total as u32).to_le_bytes());
        out.extend_from_slice(&(json_bytes.len() as u32).to_le_bytes());
        out.extend_from_slice(b"JSON");
        out.extend_from_slice(&json_bytes);
        out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&bin);
        common::write(dir, name, out)
    }
}

fn quat(q: Quat) -> [f32; 4] {
    q.to_array()
}

/// Two joints: joint 0 at the origin, joint 1 at (0, 1, 0) as its child. Vertices:
/// 0 (0,0,0) and 1 (1,0,0) on joint 0; 2 (0,2,0) on joint 1; 3 (1,2,0) half on each.
/// Joint 1 rotates from identity (t = 0) to 90° about z (t = 0.5). The mesh node carries a
/// translation that skinning must ignore.
fn two_joint_skin(dir: &Path, interpolation: &str) -> PathBuf {
    let mut b = Builder::default();
    let pos = b.positions(&[
        Vec3::ZERO,
        Vec3::X,
        Vec3::new(0.0, 2.0, 0.0),
        Vec3::new(1.0, 2.0, 0.0),
    ]);
    let joints = b.u16s(&[0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0], "VEC4", 4);
    let weights = b.floats(
        &[
            1., 0., 0., 0., 1., 0., 0., 0., 1., 0., 0., 0., 0.5, 0.5, 0., 0.,
        ],
        "VEC4",
        4,
    );
    let indices = b.u16s(&[0, 1, 3, 0, 3, 2], "SCALAR", 1);
    let ibm0 = glam::Mat4::IDENTITY.to_cols_array();
    let ibm1 = glam::Mat4::from_translation(Vec3::new(0.0, -1.0, 0.0)).to_cols_array();
    let ibms = b.floats(&[ibm0, ibm1].concat(), "MAT4", 16);
    let times = b.floats(&[0.0, 0.5], "SCALAR", 1);
    let rotations = b.floats(
        &[quat(Quat::IDENTITY), quat(Quat::from_rotation_z(FRAC_PI_2))].concat(),
        "VEC4",
        4,
    );
    let doc = json!({
        "scene": 0,
        "scenes": [{"nodes": [0, 2]}],
        "nodes": [
            {"children": [1]},
            {"translation": [0.0, 1.0, 0.0]},
            {"mesh": 0, "skin": 0, "translation": [100.0, 0.0, 0.0]},
        ],
        "meshes": [{"primitives": [{
            "attributes": {"POSITION": pos, "JOINTS_0": joints, "WEIGHTS_0": weights},
            "indices": indices,
        }]}],
        "skins": [{"joints": [0, 1], "inverseBindMatrices": ibms}],
        "animations": [{
            "name": "bend",
            "samplers": [{"input": times, "output": rotations, "interpolation": interpolation}],
            "channels": [{"sampler": 0, "target": {"node": 1, "path": "rotation"}}],
        }],
    });
    b.write_gltf(doc, dir, "skin.gltf")
}

/// Expected positions of vertices 2 and 3 with joint 1 at angle `theta` about z.
fn bent(theta: f32) -> (Vec3, Vec3) {
    let pivot = Vec3::new(0.0, 1.0, 0.0);
    let r = Quat::from_rotation_z(theta);
    let v2 = pivot + r * Vec3::Y;
    let v3 = 0.5 * Vec3::new(1.0, 2.0, 0.0) + 0.5 * (pivot + r * Vec3::new(1.0, 1.0, 0.0));
    (v2, v3)
}

#[test]
fn two_joint_skin_at_half_time_is_rotated_ninety_degrees() {
    let dir = tempfile::tempdir().unwrap();
    let path = two_joint_skin(dir.path(), "LINEAR");
    let options = AnimationOptions {
        frame_rate: 8.0,
        ..AnimationOptions::default()
    };
    let (anim, report) = load_animation(&path, &options).unwrap();
    assert_eq!(anim.frame_count(), 5); // t = 0, 0.125, …, 0.5
    assert_eq!(report.clip.as_ref().unwrap().name.as_deref(), Some("bend"));
    // t = 0: bind pose, and the mesh node's translation (100, 0, 0) is ignored.
    assert_close(anim.frames[0][2], Vec3::new(0.0, 2.0, 0.0), TOL);
    // t = 0.5: joint 1 at 90° about z around (0, 1, 0); half-weighted vertex 3 at the mean of
    // (1, 2, 0) and (-1, 2, 0).
    let last = &anim.frames[4];
    assert_close(last[0], Vec3::ZERO, TOL);
    assert_close(last[1], Vec3::X, TOL);
    assert_close(last[2], Vec3::new(-1.0, 1.0, 0.0), TOL);
    assert_close(last[3], Vec3::new(0.0, 2.0, 0.0), TOL);
    // In between, slerp turns at constant angular speed: 22.5° steps. (A normalised lerp
    // would be 0.9° off at t = 0.125, about 0.016 in position.)
    for (i, frame) in anim.frames.iter().enumerate() {
        let (v2, v3) = bent(i as f32 * FRAC_PI_2 / 4.0);
        assert_close(frame[2], v2, TOL);
        assert_close(frame[3], v3, TOL);
    }
}

#[test]
fn step_interpolation_holds_the_previous_keyframe() {
    let dir = tempfile::tempdir().unwrap();
    let path = two_joint_skin(dir.path(), "STEP");
    let options = AnimationOptions {
        frame_rate: 8.0,
        ..AnimationOptions::default()
    };
    let (anim, _) = load_animation(&path, &options).unwrap();
    assert_close(anim.frames[3][2], Vec3::new(0.0, 2.0, 0.0), TOL); // identity until t = 0.5
    assert_close(anim.frames[4][2], Vec3::new(-1.0, 1.0, 0.0), TOL); // 90° from t = 0.5
}

#[test]
fn static_load_of_a_skinned_file_is_its_rest_pose() {
    let dir = tempfile::tempdir().unwrap();
    let path = two_joint_skin(dir.path(), "LINEAR");
    let (mesh, report) = load_mesh(&path, &LoadOptions::default()).unwrap();
    // Rest transforms equal the bind pose here, so skinning reproduces the bind positions.
    assert_close(mesh.positions[2], Vec3::new(0.0, 2.0, 0.0), TOL);
    assert_close(mesh.positions[3], Vec3::new(1.0, 2.0, 0.0), TOL);
    assert!(report.normals_computed);
    // Triangles are counter-clockwise in the xy plane: normals +z.
    for n in &mesh.normals {
        assert_close(*n, Vec3::Z, TOL);
    }
}

/// One triangle with one morph target (+1 in z for every vertex), default weight 0.25, and a
/// weights channel sampled with the given interpolation and outputs.
fn morph_file(dir: &Path, interpolation: &str, outputs: &[f32]) -> PathBuf {
    let mut b = Builder::default();
    let pos = b.positions(&[Vec3::ZERO, Vec3::X, Vec3::Y]);
    let delta = b.positions(&[Vec3::Z; 3]);
    let times = b.floats(&[0.0, 1.0], "SCALAR", 1);
    let values = b.floats(outputs, "SCALAR", 1);
    let doc = json!({
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"weights": [0.25], "primitives": [{"attributes": {"POSITION": pos}, "targets": [{"POSITION": delta}]}]}],
        "animations": [{
            "samplers": [{"input": times, "output": values, "interpolation": interpolation}],
            "channels": [{"sampler": 0, "target": {"node": 0, "path": "weights"}}],
        }],
    });
    b.write_gltf(doc, dir, "morph.gltf")
}

#[test]
fn morph_target_default_weight_applies_in_static_load() {
    let dir = tempfile::tempdir().unwrap();
    let path = morph_file(dir.path(), "LINEAR", &[0.0, 1.0]);
    let (mesh, _) = load_mesh(&path, &LoadOptions::default()).unwrap();
    assert_close(mesh.positions[1], Vec3::new(1.0, 0.0, 0.25), TOL);
}

#[test]
fn morph_weights_interpolate_linearly() {
    let dir = tempfile::tempdir().unwrap();
    let path = morph_file(dir.path(), "LINEAR", &[0.0, 1.0]);
    let options = AnimationOptions {
        frame_rate: 4.0,
        ..AnimationOptions::default()
    };
    let (anim, _) = load_animation(&path, &options).unwrap();
    assert_eq!(anim.frame_count(), 5);
    for (i, frame) in anim.frames.iter().enumerate() {
        assert_close(frame[2], Vec3::new(0.0, 1.0, i as f32 * 0.25), TOL);
    }
}

#[test]
fn cubic_spline_uses_scaled_hermite_tangents() {
    let dir = tempfile::tempdir().unwrap();
    // Keyframes (in-tangent, value, out-tangent): k0 = (0, 0, 2), k1 = (0, 1, 0); dt = 1.
    // p(s) = (s³ − 2s² + s)·2 + (−2s³ + 3s²)·1; p(0.25) = 0.28125 + 0.15625 = 0.4375.
    let path = morph_file(dir.path(), "CUBICSPLINE", &[0.0, 0.0, 2.0, 0.0, 1.0, 0.0]);
    let options = AnimationOptions {
        frame_rate: 4.0,
        ..AnimationOptions::default()
    };
    let (anim, _) = load_animation(&path, &options).unwrap();
    let expected = [0.0, 0.4375, 0.75, 0.9375, 1.0];
    for (frame, z) in anim.frames.iter().zip(expected) {
        assert_close(frame[0], Vec3::new(0.0, 0.0, z), TOL);
    }
}

#[test]
fn node_transforms_apply_and_mirroring_keeps_triangles_front_facing() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let pos = b.positions(&[Vec3::ZERO, Vec3::X, Vec3::Y]);
    let normal = b.positions(&[Vec3::Z; 3]);
    let doc = json!({
        "scenes": [{"nodes": [0, 2]}],
        "nodes": [
            {"translation": [0.0, 0.0, 5.0], "children": [1]},
            {"mesh": 0, "scale": [2.0, 2.0, 2.0]},
            {"mesh": 0, "scale": [-1.0, 1.0, 1.0]},
        ],
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos, "NORMAL": normal}}]}],
    });
    let path = b.write_gltf(doc, dir.path(), "nodes.gltf");
    let (mesh, report) = load_mesh(&path, &LoadOptions::default()).unwrap();
    assert_eq!(mesh.vertex_count(), 6);
    assert!(!report.normals_computed);
    // Instance 1: scaled by 2 under a parent translated by 5 in z.
    assert_close(mesh.positions[1], Vec3::new(2.0, 0.0, 5.0), TOL);
    // Instance 2: mirrored in x; its triangle is flipped so that its geometric normal stays
    // +z, matching the transformed file normal.
    assert_close(mesh.positions[4], Vec3::new(-1.0, 0.0, 0.0), TOL);
    assert_eq!(mesh.triangles[1], [3, 5, 4]);
    let recomputed = meshio::compute_normals(
        &mesh.positions,
        &mesh.triangles,
        meshio::NormalWeighting::Angle,
    );
    for (file, computed) in mesh.normals.iter().zip(&recomputed) {
        assert_close(*file, Vec3::Z, TOL);
        assert_close(*computed, Vec3::Z, TOL);
    }
}

#[test]
fn glb_container_loads_like_gltf_and_strips_are_converted() {
    let dir = tempfile::tempdir().unwrap();
    let make = || {
        let mut b = Builder::default();
        let pos = b.positions(&[Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.0)]);
        let indices = b.u16s(&[0, 1, 2, 3], "SCALAR", 1);
        let doc = json!({
            "scenes": [{"nodes": [0]}],
            "nodes": [{"mesh": 0}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": pos}, "indices": indices, "mode": 5}]}],
        });
        (b, doc)
    };
    let (b, doc) = make();
    let gltf_path = b.write_gltf(doc, dir.path(), "strip.gltf");
    let (b, doc) = make();
    let glb_path = b.write_glb(doc, dir.path(), "strip.glb");
    let (a, ra) = load_mesh(&gltf_path, &LoadOptions::default()).unwrap();
    let (g, rg) = load_mesh(&glb_path, &LoadOptions::default()).unwrap();
    assert_eq!(a, g);
    assert_eq!(
        (ra.format, rg.format),
        (meshio::SourceFormat::Gltf, meshio::SourceFormat::Glb)
    );
    // glTF strip order: p_i = {v_i, v_{i+1+i%2}, v_{i+2−i%2}}.
    assert_eq!(a.triangles, vec![[0, 1, 2], [1, 3, 2]]);
    for n in &a.normals {
        assert_close(*n, Vec3::Z, TOL);
    }
}

#[test]
fn point_primitives_are_an_error_naming_the_primitive() {
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let pos = b.positions(&[Vec3::ZERO, Vec3::X, Vec3::Y]);
    let doc = json!({
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos}, "mode": 0}]}],
    });
    let path = b.write_gltf(doc, dir.path(), "points.gltf");
    let err = load_mesh(&path, &LoadOptions::default()).unwrap_err();
    assert!(
        matches!(&err, MeshIoError::Gltf { element, .. } if element == "mesh 0 primitive 0"),
        "{err}"
    );
}

#[test]
fn clip_selection_by_name_and_index_with_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let path = two_joint_skin(dir.path(), "LINEAR");
    let by_name = AnimationOptions {
        clip: ClipSelector::Name("bend".into()),
        frame_rate: 8.0,
        ..AnimationOptions::default()
    };
    assert_eq!(load_animation(&path, &by_name).unwrap().0.frame_count(), 5);
    let missing = AnimationOptions {
        clip: ClipSelector::Name("walk".into()),
        ..AnimationOptions::default()
    };
    let err = load_animation(&path, &missing).unwrap_err();
    assert!(err.to_string().contains("\"bend\""), "{err}");
    let out_of_range = AnimationOptions {
        clip: ClipSelector::Index(3),
        ..AnimationOptions::default()
    };
    assert!(matches!(
        load_animation(&path, &out_of_range),
        Err(MeshIoError::InvalidOption { option: "clip", .. })
    ));
    let too_long = AnimationOptions {
        frame_rate: 1000.0,
        max_frames: 10,
        ..AnimationOptions::default()
    };
    assert!(matches!(
        load_animation(&path, &too_long),
        Err(MeshIoError::InvalidOption {
            option: "max_frames",
            ..
        })
    ));
}

#[test]
fn quarter_turn_keyframes_rotate_a_rigid_node() {
    // A rigid (unskinned) instance whose node rotates 0 → 90° about y: at t = 0.5, 45°.
    let dir = tempfile::tempdir().unwrap();
    let mut b = Builder::default();
    let pos = b.positions(&[Vec3::X, Vec3::Y, Vec3::Z]);
    let times = b.floats(&[0.0, 1.0], "SCALAR", 1);
    let rotations = b.floats(
        &[quat(Quat::IDENTITY), quat(Quat::from_rotation_y(FRAC_PI_2))].concat(),
        "VEC4",
        4,
    );
    let doc = json!({
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos}}]}],
        "animations": [{
            "samplers": [{"input": times, "output": rotations}],
            "channels": [{"sampler": 0, "target": {"node": 0, "path": "rotation"}}],
        }],
    });
    let path = b.write_gltf(doc, dir.path(), "rigid.gltf");
    let (anim, _) = load_animation(
        &path,
        &AnimationOptions {
            frame_rate: 2.0,
            ..AnimationOptions::default()
        },
    )
    .unwrap();
    let h = std::f32::consts::FRAC_1_SQRT_2;
    assert_close(anim.frames[1][0], Vec3::new(h, 0.0, -h), TOL);
    assert_close(anim.frames[2][0], Vec3::new(0.0, 0.0, -1.0), TOL);
}

/// Issue #18: a Draco file failed with "accessors[0].bufferView: Missing data". The error
/// names the extension, what it is and what to do. (Both meshopt forms are decoded:
/// tests/meshopt.rs.)
#[test]
fn compressed_geometry_extensions_are_named() {
    let dir = tempfile::tempdir().unwrap();
    for (extension, hint) in [("KHR_draco_mesh_compression", "without Draco")] {
        let doc = json!({
            "asset": {"version": "2.0"},
            "extensionsUsed": [extension],
            "extensionsRequired": [extension],
            "scenes": [{"nodes": [0]}],
            "nodes": [{"mesh": 0}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
            "accessors": [{"componentType": 5126, "count": 3, "type": "VEC3",
                           "min": [0, 0, 0], "max": [1, 1, 0]}],
        });
        let path = common::write(dir.path(), "packed.gltf", serde_json::to_vec(&doc).unwrap());
        let message = load_mesh(&path, &LoadOptions::default())
            .unwrap_err()
            .to_string();
        for needle in ["packed.gltf", "extensionsRequired[0]", extension, hint] {
            assert!(message.contains(needle), "{needle:?} missing: {message}");
        }
        assert!(!message.contains("Missing data"), "{message}");
    }
}

/// EXT_meshopt_compression is decoded (tests/meshopt.rs, on gltfpack's output); a compressed
/// view whose source lies outside its buffer, or whose decoded size exceeds the view, is an
/// error naming the view, and a fallback buffer declaring more than the file may decode to is
/// refused before it is allocated.
#[test]
fn hostile_meshopt_views_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let base = |view_ext: serde_json::Value, fallback_len: u64| {
        json!({
            "asset": {"version": "2.0"},
            "extensionsUsed": ["EXT_meshopt_compression"],
            "extensionsRequired": ["EXT_meshopt_compression"],
            "scenes": [{"nodes": [0]}],
            "nodes": [{"mesh": 0}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
            "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                           "min": [0, 0, 0], "max": [1, 1, 0]}],
            "bufferViews": [{"buffer": 1, "byteLength": 36, "byteStride": 12,
                             "extensions": {"EXT_meshopt_compression": view_ext}}],
            "buffers": [
                {"byteLength": 8, "uri": "data:application/octet-stream;base64,AAAAAAAAAAA="},
                {"byteLength": fallback_len, "extensions": {"EXT_meshopt_compression": {"fallback": true}}}
            ],
        })
    };
    let cases = [
        (
            base(
                json!({"buffer": 0, "byteOffset": 4, "byteLength": 100, "byteStride": 12, "count": 3, "mode": "ATTRIBUTES"}),
                36,
            ),
            "bytes 4+100 of buffer 0",
        ),
        (
            base(
                json!({"buffer": 0, "byteLength": 8, "byteStride": 12, "count": 30, "mode": "ATTRIBUTES"}),
                36,
            ),
            "exceed the view's byteLength",
        ),
        (
            base(
                json!({"buffer": 0, "byteLength": 8, "byteStride": 12, "count": 3, "mode": "ATTRIBUTES"}),
                36,
            ),
            "vertex codec",
        ),
        (
            base(
                json!({"buffer": 0, "byteLength": 8, "byteStride": 12, "count": 3, "mode": "SPIRAL"}),
                36,
            ),
            "mode \"SPIRAL\"",
        ),
        (
            base(
                json!({"buffer": 0, "byteLength": 8, "byteStride": 12, "count": 3, "mode": "ATTRIBUTES"}),
                1 << 40,
            ),
            "fallback buffers declare",
        ),
    ];
    for (doc, needle) in cases {
        let path = common::write(dir.path(), "packed.gltf", serde_json::to_vec(&doc).unwrap());
        let message = load_mesh(&path, &LoadOptions::default())
            .unwrap_err()
            .to_string();
        assert!(message.contains(needle), "{needle:?} missing: {message}");
    }
}

/// KHR_mesh_quantization (what gltfpack writes by default): integer positions, dequantized by
/// the node's scale and translation (unsigned short) or by normalisation (signed short,
/// normalised). Both load to the float triangle within f32 rounding.
#[test]
fn quantized_positions_are_dequantized() {
    let dir = tempfile::tempdir().unwrap();
    let expected = [
        Vec3::new(-1.0, 0.0, 0.5),
        Vec3::new(1.0, 0.0, 0.5),
        Vec3::new(0.0, 2.0, -0.5),
    ];
    // Unsigned short, scale 2/65535 per step from the translation (-1, 0, -0.5).
    let step = 2.0 / 65535.0;
    let to_u16 = |p: Vec3| {
        ((p - Vec3::new(-1.0, 0.0, -0.5)) / step)
            .round()
            .to_array()
            .map(|x| x as u16)
    };
    // Signed short normalised: x / 32767 in [-1, 1], then the node scale 2.
    let to_i16 = |p: Vec3| (p / 2.0 * 32767.0).round().to_array().map(|x| x as i16);
    for (name, component_type, normalized, scale, translation) in [
        ("u16.gltf", 5123, false, [step; 3], [-1.0, 0.0, -0.5]),
        ("i16.gltf", 5122, true, [2.0f32; 3], [0.0, 0.0, 0.0]),
    ] {
        let mut b = Builder::default();
        // VEC3 of 2-byte components, padded to a 4-byte stride as glTF requires.
        let mut bytes = Vec::new();
        for p in expected {
            let q: [u16; 3] = if component_type == 5123 {
                to_u16(p)
            } else {
                to_i16(p).map(|x| x as u16)
            };
            for x in q.into_iter().chain([0]) {
                bytes.extend_from_slice(&x.to_le_bytes());
            }
        }
        let view = b.view(&bytes);
        b.views[view]["byteStride"] = json!(8);
        b.views[view]["target"] = json!(34962);
        let (lo, hi) = if component_type == 5123 {
            (json!([0, 0, 0]), json!([65535, 65535, 65535]))
        } else {
            (json!([-16384, 0, -8192]), json!([16384, 32767, 8192]))
        };
        b.accessors
            .push(json!({"bufferView": view, "componentType": component_type,
            "normalized": normalized, "count": 3, "type": "VEC3", "min": lo, "max": hi}));
        let doc = json!({
            "extensionsUsed": ["KHR_mesh_quantization"],
            "extensionsRequired": ["KHR_mesh_quantization"],
            "scenes": [{"nodes": [0]}],
            "nodes": [{"mesh": 0, "scale": scale, "translation": translation}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        });
        let path = b.write_gltf(doc, dir.path(), name);
        let (mesh, _) =
            load_mesh(&path, &LoadOptions::default()).unwrap_or_else(|e| panic!("{name}: {e}"));
        for (got, want) in mesh.positions.iter().zip(expected) {
            // Half a quantization step of 2/65535 (u16) or 2/32767 (i16).
            assert_close(*got, want, 2.0 / 32767.0);
        }
    }
}
