//! Vertex-animation textures: decoding the images with their sidecar (independently, with the
//! `exr` and `image` crates) gives back every frame — exactly from EXR, within half a 16-bit
//! step from PNG — and the angle-weighted normals; wrapped rows for wide meshes; bad requests
//! leave no file.

use std::path::Path;

use glam::Vec3;
use meshio::{VatClip, compute_normals, vat_companions, write_vat_with};

/// A waving n×n grid far from the origin, `frames` frames.
fn waving(n: usize, frames: usize) -> (Vec<Vec<Vec3>>, Vec<[u32; 3]>) {
    let at = |r: usize, c: usize| (r * n + c) as u32;
    let mut triangles = Vec::new();
    for r in 0..n - 1 {
        for c in 0..n - 1 {
            triangles.push([at(r, c), at(r + 1, c), at(r + 1, c + 1)]);
            triangles.push([at(r, c), at(r + 1, c + 1), at(r, c + 1)]);
        }
    }
    let frames = (0..frames)
        .map(|f| {
            (0..n * n)
                .map(|i| {
                    let (x, y) = ((i % n) as f32 / n as f32, (i / n) as f32 / n as f32);
                    Vec3::new(x, y, 0.2 * (x * 6.0 + f as f32 * 0.3).sin())
                        + Vec3::new(100.0, -50.0, 7.0)
                })
                .collect()
        })
        .collect();
    (frames, triangles)
}

fn write(path: &Path, frames: &[Vec<Vec3>], triangles: &[[u32; 3]]) -> meshio::VatReport {
    let clip = VatClip {
        triangles,
        frame_rate: 25.0,
        frames: frames.len(),
        vertices: frames[0].len(),
    };
    write_vat_with(path, &clip, |f, p, alpha| {
        p.copy_from_slice(&frames[f]);
        alpha
            .iter_mut()
            .enumerate()
            .for_each(|(i, a)| *a = (i + f) as f32 / 1000.0);
        Ok::<(), meshio::MeshIoError>(())
    })
    .unwrap()
}

fn read_exr(path: &Path) -> (usize, usize, Vec<[f32; 4]>) {
    let image = exr::prelude::read_first_rgba_layer_from_file(
        path,
        |size, _| {
            (
                size.width(),
                vec![[0.0f32; 4]; size.width() * size.height()],
            )
        },
        |(w, px), pos, (r, g, b, a): (f32, f32, f32, f32)| {
            px[pos.y() * *w + pos.x()] = [r, g, b, a]
        },
    )
    .unwrap();
    let size = image.layer_data.size;
    (
        size.width(),
        size.height(),
        image.layer_data.channel_data.pixels.1,
    )
}

fn texel(i: usize, f: usize, width: usize, rows: usize) -> usize {
    (f * rows + i / width) * width + i % width
}

#[test]
fn exr_and_png_decode_to_the_frames() {
    let (frames, triangles) = waving(12, 5);
    let dir = tempfile::tempdir().unwrap();
    let exr_path = dir.path().join("clip.vat.exr");
    let report = write(&exr_path, &frames, &triangles);
    assert_eq!(
        (report.width, report.height, report.rows_per_frame),
        (144, 5, 1)
    );
    let (normals_path, sidecar) = vat_companions(&exr_path);
    assert!(sidecar.ends_with("clip.vat.json") && normals_path.ends_with("clip.vat-normals.exr"));
    let (w, h, texels) = read_exr(&exr_path);
    let (_, _, normal_texels) = read_exr(&normals_path);
    assert_eq!((w, h), (144, 5));
    for (f, frame) in frames.iter().enumerate() {
        let normals = compute_normals(frame, &triangles, meshio::NormalWeighting::Angle);
        for (i, p) in frame.iter().enumerate() {
            let t = texels[texel(i, f, w, 1)];
            assert_eq!([t[0], t[1], t[2]], p.to_array(), "frame {f} vertex {i}");
            assert_eq!(t[3], (i + f) as f32 / 1000.0);
            let n = normal_texels[texel(i, f, w, 1)];
            assert_eq!([n[0], n[1], n[2]], normals[i].to_array());
        }
    }
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&sidecar).unwrap()).unwrap();
    assert_eq!(json["frame_count"], 5);
    assert_eq!(json["vertex_count"], 144);
    assert_eq!(json["fps"], 25.0);

    let png_path = dir.path().join("clip.vat.png");
    write(&png_path, &frames, &triangles);
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("clip.vat.json")).unwrap()).unwrap();
    let bound = |k: &str| -> Vec3 {
        let v: Vec<f32> = json[k]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap() as f32)
            .collect();
        Vec3::from_slice(&v)
    };
    let (lo, hi) = (bound("bounds_min"), bound("bounds_max"));
    let image = image::open(&png_path).unwrap().into_rgba16();
    assert_eq!(image.dimensions(), (144, 5));
    let step = (hi - lo) / 65535.0;
    for (f, frame) in frames.iter().enumerate() {
        for (i, p) in frame.iter().enumerate() {
            let px = image.get_pixel((i % 144) as u32, f as u32).0;
            let v = Vec3::new(px[0] as f32, px[1] as f32, px[2] as f32) / 65535.0;
            let decoded = lo + v * (hi - lo);
            // Half a quantization step, plus f32 rounding of the coordinates (~100).
            let err = (decoded - *p).abs();
            assert!(
                err.cmple(step * 0.5 + Vec3::splat(2e-5)).all(),
                "frame {f} vertex {i}: {err} vs {step}"
            );
        }
    }
}

#[test]
fn wide_meshes_wrap_onto_several_rows_per_frame() {
    let (frames, triangles) = waving(95, 2); // 9,025 vertices > 8,192
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("wide.exr");
    let report = write(&path, &frames, &triangles);
    assert_eq!(
        (report.width, report.rows_per_frame, report.height),
        (8192, 2, 4)
    );
    let (w, _, texels) = read_exr(&path);
    for (f, frame) in frames.iter().enumerate() {
        for i in [0, 8191, 8192, 9024] {
            let t = texels[texel(i, f, w, 2)];
            assert_eq!(
                [t[0], t[1], t[2]],
                frame[i].to_array(),
                "frame {f} vertex {i}"
            );
        }
    }
}

#[test]
fn bad_requests_leave_no_file() {
    let (mut frames, triangles) = waving(4, 3);
    let dir = tempfile::tempdir().unwrap();
    let clip = |frames: usize| VatClip {
        triangles: &triangles,
        frame_rate: 30.0,
        frames,
        vertices: 16,
    };
    let ok = |_: usize, _: &mut [Vec3], _: &mut [f32]| Ok::<(), meshio::MeshIoError>(());
    for (name, clip) in [
        ("a.jpg", clip(3)),
        ("b.exr", clip(0)),
        ("c.exr", clip(16385)),
    ] {
        let path = dir.path().join(name);
        assert!(write_vat_with(&path, &clip, ok).is_err(), "{name}");
    }
    frames[2][5] = Vec3::NAN;
    let path = dir.path().join("nan.png");
    let error = write_vat_with(&path, &clip(3), |f, p: &mut [Vec3], _: &mut [f32]| {
        p.copy_from_slice(&frames[f]);
        Ok::<(), meshio::MeshIoError>(())
    })
    .unwrap_err();
    assert!(error.to_string().contains("2 vertex 5"), "{error}");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}
