//! PC2 and MDD point caches (issue #18 item 3): written and read back bit for bit, topology
//! from a mesh, Blender's MDD variant, and headers the bytes cannot back refused before any
//! allocation.

use std::path::Path;

use glam::Vec3;
use meshio::{AnimationOptions, MeshIoError, SourceFormat, load_animation, write_mdd, write_pc2};

fn clip(frames: usize, points: usize) -> Vec<Vec<Vec3>> {
    (0..frames)
        .map(|f| {
            (0..points)
                .map(|m| Vec3::new(m as f32 * 0.1, (f as f32 * 0.3 + m as f32).sin(), -1.5e-7))
                .collect()
        })
        .collect()
}

fn with_topology(mesh: &Path) -> AnimationOptions {
    AnimationOptions {
        topology: Some(mesh.to_owned()),
        ..AnimationOptions::default()
    }
}

#[test]
fn the_chicken_as_pc2_and_mdd_loads_to_the_obj_folders_frames_bit_for_bit() {
    let Some(folder) = test_data::shared_file("anim/chickenCrossing") else {
        return;
    };
    let (obj, _) = load_animation(&folder, &AnimationOptions::default()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let (pc2, mdd) = (dir.path().join("c.pc2"), dir.path().join("c.mdd"));
    write_pc2(&pc2, &obj.frames, 1.0, 1.0).unwrap();
    write_mdd(&mdd, &obj.frames, 30.0).unwrap();
    let topology = folder.join("1.obj");
    for path in [&pc2, &mdd] {
        let (back, report) = load_animation(path, &with_topology(&topology)).unwrap();
        assert_eq!(back.frames.len(), 170);
        assert_eq!(back.frames, obj.frames, "{}", path.display());
        assert_eq!(back.triangles, obj.triangles);
        assert!(!report.topology_missing);
        assert_eq!(back.frame_rate, 30.0);
    }
    // Sizes: a PC2 is its 32-byte header and 12 bytes per vertex per frame.
    let bytes = std::fs::metadata(&pc2).unwrap().len();
    assert_eq!(bytes, 32 + 12 * 3030 * 170);
}

#[test]
fn round_trips_without_topology_are_point_clouds() {
    let dir = tempfile::tempdir().unwrap();
    let frames = clip(7, 11);
    let (pc2, mdd) = (dir.path().join("a.pc2"), dir.path().join("a.mdd"));
    write_pc2(&pc2, &frames, 0.0, 1.0).unwrap();
    write_mdd(&mdd, &frames, 24.0).unwrap();
    let (a, report) = load_animation(&pc2, &AnimationOptions::default()).unwrap();
    assert_eq!(a.frames, frames);
    assert!(a.triangles.is_empty() && report.topology_missing);
    assert_eq!(report.format, SourceFormat::Pc2);
    // An MDD's evenly stepped times give its frame rate.
    let (b, report) = load_animation(&mdd, &AnimationOptions::default()).unwrap();
    assert_eq!(b.frames, frames);
    assert_eq!(report.format, SourceFormat::Mdd);
    assert!((b.frame_rate - 24.0).abs() < 1e-3, "{}", b.frame_rate);
}

#[test]
fn blenders_mdd_with_its_extra_rest_block_reads_the_frames() {
    // Blender's export_mdd.py writes the counts, the times, one block of rest positions, then
    // the frames.
    let frames = clip(4, 5);
    let rest = vec![Vec3::splat(9.0); 5];
    let mut bytes = Vec::new();
    bytes.extend_from_slice(&4i32.to_be_bytes());
    bytes.extend_from_slice(&5i32.to_be_bytes());
    for f in 0..4 {
        bytes.extend_from_slice(&(f as f32 / 25.0).to_be_bytes());
    }
    for frame in std::iter::once(&rest).chain(&frames) {
        for c in frame.iter().flat_map(|v| v.to_array()) {
            bytes.extend_from_slice(&c.to_be_bytes());
        }
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("blender.mdd");
    std::fs::write(&path, bytes).unwrap();
    let (clip, report) = load_animation(&path, &AnimationOptions::default()).unwrap();
    assert_eq!(clip.frames, frames);
    assert!(
        report.notes.iter().any(|n| n.contains("rest pose")),
        "{:?}",
        report.notes
    );
    assert!((clip.frame_rate - 25.0).abs() < 1e-3);
}

#[test]
fn headers_the_bytes_cannot_back_are_refused_before_allocating() {
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, bytes: &[u8]| {
        let p = dir.path().join(name);
        std::fs::write(&p, bytes).unwrap();
        p
    };
    let pc2_header = |points: i32, samples: i32| {
        let mut b = b"POINTCACHE2\0".to_vec();
        for v in [1i32, points] {
            b.extend_from_slice(&v.to_le_bytes());
        }
        b.extend_from_slice(&0f32.to_le_bytes());
        b.extend_from_slice(&1f32.to_le_bytes());
        b.extend_from_slice(&samples.to_le_bytes());
        b
    };
    // 2^31 − 1 points × 2^31 − 1 samples claimed by 32 bytes: ~5.5·10¹⁹ bytes asked for.
    let huge = write("huge.pc2", &pc2_header(i32::MAX, i32::MAX));
    let err = load_animation(&huge, &AnimationOptions::default()).unwrap_err();
    assert!(matches!(err, MeshIoError::Truncated { .. }), "{err}");
    assert!(err.to_string().contains("huge.pc2"), "{err}");
    for (name, bytes, needle) in [
        ("zero.pc2", pc2_header(0, 5), "points = 0"),
        ("negative.pc2", pc2_header(3, -1), "samples = -1"),
        (
            "magic.pc2",
            b"POINTCACHE3\0........................".to_vec(),
            "POINTCACHE2",
        ),
        ("short.mdd", vec![0, 0, 0, 1], "4 bytes"),
        (
            "frames.mdd",
            [i32::MAX.to_be_bytes(), 1i32.to_be_bytes()].concat(),
            "truncated",
        ),
        // 12·P·F beyond u64: the size check itself must not overflow.
        (
            "both.mdd",
            [i32::MAX.to_be_bytes(), i32::MAX.to_be_bytes()].concat(),
            "truncated",
        ),
    ] {
        let p = write(name, &bytes);
        let message = load_animation(&p, &AnimationOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            message.contains(name) && message.contains(needle),
            "{message}"
        );
    }
    // A topology mesh whose vertex count differs is refused naming both files.
    let frames = clip(2, 4);
    let pc2 = dir.path().join("four.pc2");
    write_pc2(&pc2, &frames, 0.0, 1.0).unwrap();
    let mesh = write("tri.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    let message = load_animation(&pc2, &with_topology(&mesh))
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("four.pc2") && message.contains("tri.obj"),
        "{message}"
    );
    // Writers refuse clips they cannot store.
    assert!(write_pc2(&dir.path().join("e.pc2"), &[], 0.0, 1.0).is_err());
    let ragged = vec![vec![Vec3::ZERO; 3], vec![Vec3::ZERO; 2]];
    assert!(write_mdd(&dir.path().join("r.mdd"), &ragged, 30.0).is_err());
    assert!(write_mdd(&dir.path().join("n.mdd"), &frames, f32::NAN).is_err());
    assert!(!dir.path().join("r.mdd").exists());
}

#[cfg(unix)]
#[test]
fn a_point_cache_that_is_a_fifo_is_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("cache.mdd");
    test_data::make_fifo(&fifo);
    let message = load_animation(&fifo, &AnimationOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("cache.mdd") && message.contains("FIFO"),
        "{message}"
    );
}
