//! `.npy` reading and writing, and `.npy` animations with and without topology.

mod common;

use std::path::Path;

use glam::Vec3;
use meshio::{AnimationOptions, MeshIoError, load_animation, read_npy_f32, write_npy_f32};

/// A .npy file with a hand-written header dict and raw data.
fn raw_npy(dir: &Path, name: &str, dict: &str, data: &[u8]) -> std::path::PathBuf {
    let mut header = dict.as_bytes().to_vec();
    header.push(b'\n');
    let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
    bytes.extend_from_slice(&(header.len() as u16).to_le_bytes());
    bytes.extend_from_slice(&header);
    bytes.extend_from_slice(data);
    common::write(dir, name, bytes)
}

#[test]
fn write_then_read_round_trips_every_shape_the_facade_uses() {
    let dir = tempfile::tempdir().unwrap();
    let shapes: [&[usize]; 6] = [&[7], &[4, 7], &[7, 2], &[3, 5, 3], &[], &[0, 3]];
    for shape in shapes {
        let n: usize = shape.iter().product();
        let data: Vec<f32> = (0..n).map(|i| i as f32 * 0.5 - 3.0).collect();
        let path = dir.path().join(format!("a{}.npy", shape.len()));
        write_npy_f32(&path, shape, &data).unwrap();
        let back = read_npy_f32(&path).unwrap();
        assert_eq!(back.shape, shape.to_vec());
        assert_eq!(back.data, data);
        let bytes = std::fs::read(&path).unwrap();
        let header_len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
        assert_eq!((10 + header_len) % 64, 0, "data must start 64-byte aligned");
    }
    // No temporary files are left beside the outputs.
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .filter_map(|e| {
            let name = e.unwrap().file_name().into_string().unwrap();
            name.ends_with(".tmp").then_some(name)
        })
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}

#[test]
fn big_endian_f64_fortran_order_is_converted_to_row_major_f32() {
    let dir = tempfile::tempdir().unwrap();
    // The 2×3 matrix [[0, 1, 2], [3, 4, 5]] stored column-major as big-endian f64.
    let data: Vec<u8> = [0.0f64, 3.0, 1.0, 4.0, 2.0, 5.0]
        .iter()
        .flat_map(|v| v.to_be_bytes())
        .collect();
    let path = raw_npy(
        dir.path(),
        "f.npy",
        "{'descr': '>f8', 'fortran_order': True, 'shape': (2, 3), }",
        &data,
    );
    let array = read_npy_f32(&path).unwrap();
    assert_eq!(array.shape, vec![2, 3]);
    assert_eq!(array.data, vec![0.0, 1.0, 2.0, 3.0, 4.0, 5.0]);
}

#[test]
fn unsupported_dtype_and_wrong_lengths_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    let ints = raw_npy(
        dir.path(),
        "i.npy",
        "{'descr': '<i4', 'fortran_order': False, 'shape': (2,), }",
        &[0; 8],
    );
    assert!(matches!(read_npy_f32(&ints), Err(MeshIoError::Npy { .. })));
    let short = raw_npy(
        dir.path(),
        "s.npy",
        "{'descr': '<f4', 'fortran_order': False, 'shape': (3,), }",
        &[0; 8],
    );
    let err = read_npy_f32(&short).unwrap_err();
    assert!(
        err.to_string().contains("12 bytes") && err.to_string().contains("8 bytes"),
        "{err}"
    );
    let not_npy = common::write(dir.path(), "x.npy", b"hello world");
    assert!(matches!(
        read_npy_f32(&not_npy),
        Err(MeshIoError::InvalidHeader { .. })
    ));
}

#[test]
fn shape_mismatch_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.npy");
    let err = write_npy_f32(&path, &[2, 3], &[1.0; 5]).unwrap_err();
    assert!(matches!(
        err,
        MeshIoError::ShapeMismatch {
            expected: Some(6),
            actual: 5,
            ..
        }
    ));
    assert!(!path.exists());
    assert!(write_npy_f32(&path, &[usize::MAX, 3], &[]).is_err());
    // Below a file, where no folder can be created: an I/O error, no output.
    let blocker = dir.path().join("blocker");
    std::fs::write(&blocker, b"a file").unwrap();
    assert!(matches!(
        write_npy_f32(&blocker.join("below/a.npy"), &[1], &[1.0]),
        Err(MeshIoError::Io { .. })
    ));
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    // Missing folders are created, as by every writer.
    write_npy_f32(&dir.path().join("new/dir/a.npy"), &[1], &[1.0]).unwrap();
}

#[test]
fn npy_animation_with_and_without_topology() {
    let dir = tempfile::tempdir().unwrap();
    let quad = common::write(
        dir.path(),
        "quad.obj",
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n",
    );
    // Two frames: the second lifted by 1 in z.
    let frame = [
        0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0f32,
    ];
    let lifted: Vec<f32> = frame
        .chunks(3)
        .flat_map(|p| [p[0], p[1], p[2] + 1.0])
        .collect();
    let path = dir.path().join("anim.npy");
    write_npy_f32(&path, &[2, 4, 3], &[&frame[..], &lifted].concat()).unwrap();

    let with = AnimationOptions {
        topology: Some(quad),
        frame_rate: 24.0,
        ..AnimationOptions::default()
    };
    let (anim, report) = load_animation(&path, &with).unwrap();
    assert_eq!(anim.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!(anim.frames[1][2], Vec3::new(1.0, 1.0, 1.0));
    assert_eq!(anim.frame_rate, 24.0);
    assert!(!report.topology_missing);

    let (anim, report) = load_animation(&path, &AnimationOptions::default()).unwrap();
    assert!(anim.triangles.is_empty() && report.topology_missing);
    assert_eq!(anim.frame_count(), 2);

    let triangle = common::write(
        dir.path(),
        "tri.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    );
    let wrong = AnimationOptions {
        topology: Some(triangle),
        ..AnimationOptions::default()
    };
    assert!(matches!(
        load_animation(&path, &wrong),
        Err(MeshIoError::TopologyMismatch {
            topology_vertices: 3,
            animation_vertices: 4,
            ..
        })
    ));

    let flat = dir.path().join("flat.npy");
    write_npy_f32(&flat, &[2, 6], &[0.0; 12]).unwrap();
    assert!(matches!(
        load_animation(&flat, &AnimationOptions::default()),
        Err(MeshIoError::Npy { .. })
    ));
}

#[test]
fn chicken_round_trips_through_npy() {
    let Some(dir) = test_data::shared_file("anim/chickenCrossing") else {
        return;
    };
    let (anim, _) = load_animation(&dir, &AnimationOptions::default()).unwrap();
    let out = tempfile::tempdir().unwrap();
    let path = out.path().join("chicken.npy");
    let flat: Vec<f32> = anim
        .frames
        .iter()
        .flatten()
        .flat_map(|p| p.to_array())
        .collect();
    write_npy_f32(&path, &[anim.frame_count(), anim.vertex_count(), 3], &flat).unwrap();
    let options = AnimationOptions {
        topology: Some(dir.join("1.obj")),
        ..AnimationOptions::default()
    };
    let (back, _) = load_animation(&path, &options).unwrap();
    assert_eq!(back, anim);
}

#[test]
fn streamed_frames_equal_the_whole_array_and_a_wrong_stream_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let frames: Vec<Vec<Vec3>> = (0..4)
        .map(|f| {
            (0..5)
                .map(|v| Vec3::new(f as f32, v as f32, -0.5 * (f * v) as f32))
                .collect()
        })
        .collect();
    // Lazily produced frames, as a decoder yields them.
    let streamed = dir.path().join("streamed.npy");
    meshio::write_npy_frames(&streamed, 4, 5, (0..4).map(|f| frames[f].clone())).unwrap();
    let whole = dir.path().join("whole.npy");
    let flat: Vec<f32> = frames.iter().flatten().flat_map(|p| p.to_array()).collect();
    write_npy_f32(&whole, &[4, 5, 3], &flat).unwrap();
    assert_eq!(
        std::fs::read(&streamed).unwrap(),
        std::fs::read(&whole).unwrap()
    );
    let back = load_animation(&streamed, &AnimationOptions::default())
        .unwrap()
        .0;
    assert_eq!(back.frames, frames);

    // Too few frames, too many, and a short frame: an error naming the file, and no file.
    for (name, count, cut) in [("few.npy", 5, 5), ("many.npy", 3, 5), ("short.npy", 4, 4)] {
        let path = dir.path().join(name);
        let stream = frames.iter().enumerate().map(|(f, frame)| {
            if f == 2 {
                frame[..cut].to_vec()
            } else {
                frame.clone()
            }
        });
        let err = meshio::write_npy_frames(&path, count, 5, stream).unwrap_err();
        assert!(
            matches!(err, MeshIoError::ShapeMismatch { .. }) && err.to_string().contains(name),
            "{err}"
        );
        assert!(!path.exists(), "{name} was left behind");
    }
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names.len(), 2, "only the two good files: {names:?}");
}
