//! The real animations of shared/data: OBJ frame folders and skinned glTF files.

mod common;

use std::path::Path;

use common::undirected_edges;
use glam::{Mat4, Quat, Vec3};
use meshio::{AnimationOptions, ClipSelector, LoadOptions, load_animation, load_mesh};
use serde_json::Value;

#[test]
fn horse_gallop_frames_in_order_and_the_loop_closes() {
    let Some(dir) = test_data::shared_file("anim/horse-gallop") else {
        return;
    };
    let (anim, report) = load_animation(&dir, &AnimationOptions::default()).unwrap();
    assert_eq!((anim.frame_count(), anim.vertex_count()), (25, 8_431));
    assert_eq!(anim.triangles.len(), 16_843);
    assert_eq!(anim.frame_rate, 30.0);
    let boundary = undirected_edges(&anim.triangles)
        .values()
        .filter(|&&n| n == 1)
        .count();
    assert_eq!(boundary, 19);
    // SOURCES.md: frame 25 equals frame 1 to within 3.8e-5 (one gallop cycle).
    let max_gap = anim.frames[24]
        .iter()
        .zip(&anim.frames[0])
        .map(|(a, b)| (*a - *b).abs().max_element())
        .fold(0.0, f32::max);
    assert!(
        max_gap <= 3.8e-5 + 1e-6,
        "frame 25 differs from frame 1 by {max_gap}"
    );
    // ... while the middle of the cycle is far from it.
    let mid_gap = anim.frames[12]
        .iter()
        .zip(&anim.frames[0])
        .map(|(a, b)| (*a - *b).length())
        .fold(0.0, f32::max);
    assert!(mid_gap > 0.05, "{mid_gap}");
    assert!(
        report.frame_files[0].ends_with("0001.obj") && report.frame_files[24].ends_with("0025.obj")
    );
}

#[test]
fn chicken_frames_ordered_numerically_not_lexicographically() {
    let Some(dir) = test_data::shared_file("anim/chickenCrossing") else {
        return;
    };
    let (anim, report) = load_animation(&dir, &AnimationOptions::default()).unwrap();
    assert_eq!((anim.frame_count(), anim.vertex_count()), (170, 3_030));
    assert_eq!(anim.triangles.len(), 5_664);
    assert_eq!(report.duplicate_positions, 1);
    let boundary = undirected_edges(&anim.triangles)
        .values()
        .filter(|&&n| n == 1)
        .count();
    assert_eq!(boundary, 294);
    for (i, file) in report.frame_files.iter().enumerate() {
        assert_eq!(
            file.file_name().unwrap().to_str().unwrap(),
            format!("{}.obj", i + 1)
        );
    }
    // Numeric order is temporally smooth: every step moves less than the jump from frame 1 to
    // frame 10, which is where lexicographic order (1, 10, 100, …) would go next.
    let step = |a: &[Vec3], b: &[Vec3]| {
        a.iter()
            .zip(b)
            .map(|(p, q)| (*p - *q).length())
            .fold(0.0, f32::max)
    };
    let worst_step = anim
        .frames
        .windows(2)
        .map(|w| step(&w[0], &w[1]))
        .fold(0.0, f32::max);
    assert!(
        worst_step < step(&anim.frames[0], &anim.frames[99]),
        "{worst_step}"
    );
    let (lo, hi) = anim.bounding_box().unwrap();
    assert!(lo.x > 22.0 && hi.x < 28.0, "chicken x range {lo} {hi}");
    // Normals per frame: unit or zero.
    for n in anim.normals_for_frame(169) {
        assert!(n == Vec3::ZERO || (n.length() - 1.0).abs() < 1e-5);
    }
}

/// The JSON chunk of a GLB file.
fn glb_json(path: &Path) -> Value {
    let bytes = std::fs::read(path).unwrap();
    let len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    serde_json::from_slice(&bytes[20..20 + len]).unwrap()
}

fn local_matrix(node: &Value) -> Mat4 {
    if let Some(m) = node.get("matrix") {
        let m: Vec<f32> = m
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap() as f32)
            .collect();
        return Mat4::from_cols_slice(&m);
    }
    let get = |key: &str, default: &[f32]| -> Vec<f32> {
        node.get(key).map_or(default.to_vec(), |v| {
            v.as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap() as f32)
                .collect()
        })
    };
    let (t, r, s) = (
        get("translation", &[0.0; 3]),
        get("rotation", &[0.0, 0.0, 0.0, 1.0]),
        get("scale", &[1.0; 3]),
    );
    Mat4::from_scale_rotation_translation(
        Vec3::from_slice(&s),
        Quat::from_slice(&r).normalize(),
        Vec3::from_slice(&t),
    )
}

/// Bounding box of the mesh node's POSITION min/max boxes, transformed by the mesh node's
/// global matrix (exact for the signed axis permutations these files use).
fn expected_rest_box(json: &Value) -> (Vec3, Vec3) {
    let nodes = json["nodes"].as_array().unwrap();
    let parent_of = |i: usize| {
        nodes.iter().position(|n| {
            n["children"]
                .as_array()
                .is_some_and(|c| c.iter().any(|x| x == i))
        })
    };
    let mesh_node = nodes.iter().position(|n| n.get("mesh").is_some()).unwrap();
    let mut global = local_matrix(&nodes[mesh_node]);
    let mut at = mesh_node;
    while let Some(p) = parent_of(at) {
        global = local_matrix(&nodes[p]) * global;
        at = p;
    }
    let mesh = &json["meshes"][nodes[mesh_node]["mesh"].as_u64().unwrap() as usize];
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for prim in mesh["primitives"].as_array().unwrap() {
        let acc = &json["accessors"][prim["attributes"]["POSITION"].as_u64().unwrap() as usize];
        let v = |key: &str| {
            Vec3::from_slice(
                &acc[key]
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|x| x.as_f64().unwrap() as f32)
                    .collect::<Vec<_>>(),
            )
        };
        let (a, b) = (v("min"), v("max"));
        for corner in 0..8 {
            let c = Vec3::new(
                if corner & 1 == 0 { a.x } else { b.x },
                if corner & 2 == 0 { a.y } else { b.y },
                if corner & 4 == 0 { a.z } else { b.z },
            );
            let p = global.transform_point3(c);
            lo = lo.min(p);
            hi = hi.max(p);
        }
    }
    (lo, hi)
}

/// Loads a glTF file statically and as animation(s); checks counts, the bind pose, and that
/// every sampled frame stays a plausible size.
fn check_gltf(
    relative: &str,
    vertices: usize,
    triangles: usize,
    clips: &[(&str, f32)],
    frame_rate: f32,
) {
    let Some(path) = test_data::shared_file(relative) else {
        return;
    };
    let (mesh, _) = load_mesh(&path, &LoadOptions::default()).unwrap();
    assert_eq!(
        (mesh.vertex_count(), mesh.triangle_count()),
        (vertices, triangles),
        "{relative}"
    );
    // In these files the rest pose is the bind pose (G(joint)·IBM = G(mesh node) to 2e-5), so
    // skinning the rest pose must reproduce the stored positions under the mesh node's transform.
    let (lo, hi) = mesh.bounding_box().unwrap();
    let (elo, ehi) = expected_rest_box(&glb_json(&path));
    let diag = (ehi - elo).length();
    assert!(
        (lo - elo).length() < 1e-4 * diag && (hi - ehi).length() < 1e-4 * diag,
        "{relative}: rest box {lo}..{hi}, expected {elo}..{ehi}"
    );
    for (index, (name, duration)) in clips.iter().enumerate() {
        let clip = if name.is_empty() {
            ClipSelector::Index(index)
        } else {
            ClipSelector::Name(name.to_string())
        };
        let options = AnimationOptions {
            frame_rate,
            clip,
            ..AnimationOptions::default()
        };
        let (anim, report) = load_animation(&path, &options).unwrap();
        let info = report.clip.unwrap();
        assert!(
            (info.end_s - duration).abs() < 0.01,
            "{relative} clip {name}: ends at {}",
            info.end_s
        );
        let span = f64::from(info.end_s - info.start_s);
        assert_eq!(
            anim.frame_count(),
            (span * f64::from(frame_rate) + 1e-4).floor() as usize + 1
        );
        assert_eq!(anim.vertex_count(), vertices);
        for (f, frame) in anim.frames.iter().enumerate() {
            let (flo, fhi) = meshio::Mesh {
                positions: frame.clone(),
                ..Default::default()
            }
            .bounding_box()
            .unwrap();
            let ratio = (fhi - flo).length() / diag;
            assert!(
                (0.5..2.0).contains(&ratio),
                "{relative} clip {name} frame {f}: box diagonal ratio {ratio}"
            );
        }
    }
}

#[test]
fn fox_three_clips() {
    check_gltf(
        "anim/gltf/Fox.glb",
        1_728,
        576,
        &[("Survey", 3.4167), ("Walk", 0.7083), ("Run", 1.1583)],
        30.0,
    );
}

#[test]
fn cesium_man_walk() {
    check_gltf("anim/gltf/CesiumMan.glb", 3_273, 4_672, &[("", 2.0)], 30.0);
}

#[test]
fn brainstem_walk_59_primitives() {
    // 2 fps keeps the test small: 70 frames × 34 159 vertices.
    check_gltf(
        "anim/gltf/BrainStem.glb",
        34_159,
        61_666,
        &[("", 34.88)],
        2.0,
    );
}
