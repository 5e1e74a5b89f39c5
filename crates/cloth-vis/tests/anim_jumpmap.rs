//! `cloth-vis anim jumpmap` end to end on a small synthetic clip written as OBJ frames: every
//! output format, the heat maps, determinism and refused input.

use std::io::Write as _;
use std::path::{Path, PathBuf};

use anim_pca::{Blend, JumpMapParams, PlaybackParams};
use cloth_vis::anim_cmd::{JumpMapRequest, run_jumpmap};
use glam::Vec3;

const SIDE: usize = 8;
const PERIOD: f32 = 12.0;
const CLIP_FRAMES: usize = 40;

/// A waving 8 × 8 grid, period 12 frames, as numbered OBJ frames `1.obj` … in `dir`.
fn write_clip(dir: &Path) -> Vec<Vec<Vec3>> {
    std::fs::create_dir_all(dir).unwrap();
    let mut frames = Vec::new();
    for t in 0..CLIP_FRAMES {
        let phase = t as f32 / PERIOD * std::f32::consts::TAU;
        let frame: Vec<Vec3> = (0..SIDE * SIDE)
            .map(|n| {
                let (x, y) = ((n % SIDE) as f32, (n / SIDE) as f32);
                Vec3::new(
                    x,
                    y,
                    (phase + 0.6 * x).sin() + 0.3 * (2.0 * phase + 0.4 * y).cos(),
                )
            })
            .collect();
        let mut file = std::fs::File::create(dir.join(format!("{}.obj", t + 1))).unwrap();
        for p in &frame {
            writeln!(file, "v {} {} {}", p.x, p.y, p.z).unwrap();
        }
        for y in 0..SIDE - 1 {
            for x in 0..SIDE - 1 {
                let i = y * SIDE + x + 1;
                writeln!(file, "f {} {} {}", i, i + 1, i + SIDE + 1).unwrap();
                writeln!(file, "f {} {} {}", i, i + SIDE + 1, i + SIDE).unwrap();
            }
        }
        frames.push(frame);
    }
    frames
}

fn request(input: PathBuf, out: PathBuf) -> JumpMapRequest {
    JumpMapRequest {
        input,
        params: JumpMapParams::default(),
        playback: PlaybackParams {
            blend: Blend::Fixed(3),
            seed: 7,
            ..PlaybackParams::default()
        },
        frames: 200,
        out,
        maps: None,
    }
}

fn read_npy(path: &Path) -> (Vec<usize>, Vec<f32>) {
    let array = meshio::read_npy_f32(path).unwrap();
    (array.shape, array.data)
}

#[test]
fn npy_output_is_the_clip_replayed_with_jumps_and_deterministic() {
    let dir = tempfile::tempdir().unwrap();
    let clip = write_clip(&dir.path().join("clip"));
    let out = dir.path().join("a.npy");
    let summary = run_jumpmap(&request(dir.path().join("clip"), out.clone())).unwrap();
    let (shape, data) = read_npy(&out);
    assert_eq!(shape, vec![200, SIDE * SIDE, 3]);
    assert!(data.iter().all(|v| v.is_finite()));
    // Frame 0 is clip frame 0 rebuilt from its PCA weights (the clip has rank ≤ c here).
    for (v, p) in clip[0].iter().enumerate() {
        let q = Vec3::from_slice(&data[3 * v..3 * v + 3]);
        assert!((q - *p).length() < 1e-3, "vertex {v}: {q} vs {p}");
    }
    // 200 frames from a 40-frame clip cannot play without jumping back.
    assert!(summary.stats.transitions >= 4, "{:?}", summary.stats);
    assert_eq!(summary.stats.frames, 200);
    // Same seed, same animation; another seed, another one.
    let again = dir.path().join("b.npy");
    run_jumpmap(&request(dir.path().join("clip"), again.clone())).unwrap();
    assert_eq!(read_npy(&again).1, data);
    let other = dir.path().join("c.npy");
    let mut r = request(dir.path().join("clip"), other.clone());
    r.playback.seed = 8;
    run_jumpmap(&r).unwrap();
    assert_ne!(read_npy(&other).1, data);
}

#[test]
fn glb_and_obj_outputs_load_back_as_the_same_frames() {
    let dir = tempfile::tempdir().unwrap();
    write_clip(&dir.path().join("clip"));
    let npy = dir.path().join("a.npy");
    let mut r = request(dir.path().join("clip"), npy.clone());
    r.frames = 30;
    run_jumpmap(&r).unwrap();
    let (_, data) = read_npy(&npy);

    let glb = dir.path().join("a.glb");
    r.out = glb.clone();
    run_jumpmap(&r).unwrap();
    let (anim, _) = meshio::load_animation(&glb, &meshio::AnimationOptions::default()).unwrap();
    assert_eq!(anim.frames.len(), 30);
    assert_eq!(anim.triangles.len(), 2 * (SIDE - 1) * (SIDE - 1));
    let folder = dir.path().join("frames");
    r.out = folder.clone();
    run_jumpmap(&r).unwrap();
    let (objs, _) = meshio::load_animation(&folder, &meshio::AnimationOptions::default()).unwrap();
    assert_eq!(objs.frames.len(), 30);
    for f in [0, 13, 29] {
        for v in 0..SIDE * SIDE {
            let expected = Vec3::from_slice(&data[(f * SIDE * SIDE + v) * 3..][..3]);
            for got in [anim.frames[f][v], objs.frames[f][v]] {
                assert!((got - expected).length() < 1e-4, "frame {f} vertex {v}");
            }
        }
    }
}

#[test]
fn heat_maps_are_written_for_all_five_matrices() {
    let dir = tempfile::tempdir().unwrap();
    write_clip(&dir.path().join("clip"));
    let mut r = request(dir.path().join("clip"), dir.path().join("a.npy"));
    r.maps = Some(dir.path().join("maps"));
    run_jumpmap(&r).unwrap();
    for name in ["D", "D_velocity", "P", "P_velocity", "P_hat"] {
        let image = image::open(dir.path().join("maps").join(format!("{name}.png")))
            .unwrap()
            .to_rgb8();
        // 40 entries scaled to ≥ 256 pixels.
        assert_eq!(image.dimensions(), (280, 280), "{name}");
        // D is zero on the diagonal (black) and positive off it.
        if name == "D" {
            assert_eq!(image.get_pixel(3, 3).0, [0, 0, 0]);
            assert_ne!(image.get_pixel(3, 7 * 20).0, [0, 0, 0]);
        }
    }
}

#[test]
fn bad_requests_are_refused_before_writing() {
    let dir = tempfile::tempdir().unwrap();
    write_clip(&dir.path().join("clip"));
    let bad_ext = dir.path().join("a.txt");
    let e = run_jumpmap(&request(dir.path().join("clip"), bad_ext.clone())).unwrap_err();
    assert!(e.to_string().contains(".txt"), "{e}");
    assert!(!bad_ext.exists());
    let out = dir.path().join("a.npy");
    let mut r = request(dir.path().join("clip"), out.clone());
    r.params.sigma = -1.0;
    let e = run_jumpmap(&r).unwrap_err();
    assert!(
        e.to_string().contains("sigma") || e.to_string().contains("σ"),
        "{e}"
    );
    assert!(!out.exists());
    let mut r = request(dir.path().join("missing"), out.clone());
    r.frames = 10;
    let e = run_jumpmap(&r).unwrap_err();
    assert!(e.to_string().contains("missing"), "{e}");
    assert!(!out.exists());
}
