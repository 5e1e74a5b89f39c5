//! `cloth-vis anim jumpmap` end to end on a small synthetic clip written as OBJ frames: every
//! output format, the heat maps, the rendered strip, determinism and refused input.

use std::io::Write as _;
use std::path::{Path, PathBuf};

use crate::commands::jumpmap::{
    JumpMapRequest, PlayControl, StripRequest, parse_cell_at, run_jumpmap,
};
use anim_pca::{Blend, JumpMapParams, PlaybackParams};
use glam::Vec3;
use gpu_context::{GpuContext, GpuOptions};

const SIDE: usize = 8;
const PERIOD: f32 = 12.0;
const CLIP_FRAMES: usize = 40;

/// A waving 8 × 8 grid, period 12 frames, as numbered OBJ frames `1.obj` … in `dir`.
fn write_clip(dir: &Path) -> Vec<Vec<Vec3>> {
    write_clip_scaled(dir, 1.0, Vec3::ZERO)
}

/// [`write_clip`] with the wave's height scaled by `amplitude` and frame t moved by
/// `t · travel`.
fn write_clip_scaled(dir: &Path, amplitude: f32, travel: Vec3) -> Vec<Vec<Vec3>> {
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
                    amplitude * ((phase + 0.6 * x).sin() + 0.3 * (2.0 * phase + 0.4 * y).cos()),
                ) + travel * t as f32
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
        clip: meshio::ClipSelector::First,
        topology: None,
        params: JumpMapParams::default(),
        control: PlayControl::default(),
        playback: PlaybackParams {
            blend: Blend::Fixed(3),
            seed: 7,
            ..PlaybackParams::default()
        },
        frames: 200,
        out,
        force: false,
        memory_limit: crate::commands::jumpmap::MAX_GENERATED_BYTES,
        maps: None,
        strip: None,
        progress: false,
    }
}

/// (frames, vertices) of a clip on disk.
fn clip_size(path: &Path) -> (usize, usize) {
    let (clip, _) = meshio::load_animation(path, &meshio::AnimationOptions::default()).unwrap();
    (clip.frames.len(), clip.vertex_count())
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
    let summary = run_jumpmap(&request(dir.path().join("clip"), out.clone()), None).unwrap();
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
    run_jumpmap(&request(dir.path().join("clip"), again.clone()), None).unwrap();
    assert_eq!(read_npy(&again).1, data);
    let other = dir.path().join("c.npy");
    let mut r = request(dir.path().join("clip"), other.clone());
    r.playback.seed = 8;
    run_jumpmap(&r, None).unwrap();
    assert_ne!(read_npy(&other).1, data);
}

#[test]
fn glb_and_obj_outputs_load_back_as_the_same_frames() {
    let dir = tempfile::tempdir().unwrap();
    write_clip(&dir.path().join("clip"));
    let npy = dir.path().join("a.npy");
    let mut r = request(dir.path().join("clip"), npy.clone());
    r.frames = 30;
    run_jumpmap(&r, None).unwrap();
    let (_, data) = read_npy(&npy);

    let glb = dir.path().join("a.glb");
    r.out = glb.clone();
    run_jumpmap(&r, None).unwrap();
    let (anim, _) = meshio::load_animation(&glb, &meshio::AnimationOptions::default()).unwrap();
    assert_eq!(anim.frames.len(), 30);
    assert_eq!(anim.triangles.len(), 2 * (SIDE - 1) * (SIDE - 1));
    let folder = dir.path().join("frames");
    r.out = folder.clone();
    run_jumpmap(&r, None).unwrap();
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
    run_jumpmap(&r, None).unwrap();
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
    let e = run_jumpmap(&request(dir.path().join("clip"), bad_ext.clone()), None).unwrap_err();
    assert!(e.to_string().contains(".txt"), "{e}");
    assert!(!bad_ext.exists());
    let out = dir.path().join("a.npy");
    let mut r = request(dir.path().join("clip"), out.clone());
    r.params.sigma = -1.0;
    let e = run_jumpmap(&r, None).unwrap_err();
    assert!(
        e.to_string().contains("sigma") || e.to_string().contains("σ"),
        "{e}"
    );
    assert!(!out.exists());
    let mut r = request(dir.path().join("missing"), out.clone());
    r.frames = 10;
    let e = run_jumpmap(&r, None).unwrap_err();
    assert!(e.to_string().contains("missing"), "{e}");
    assert!(!out.exists());
    // Issue #12: `--frames 1000000000` grew until the kernel killed the process; it is now
    // refused after loading the clip (V known), before the analysis, naming the flag.
    let mut r = request(dir.path().join("clip"), out.clone());
    r.frames = 1_000_000_000;
    let e = run_jumpmap(&r, None).unwrap_err().to_string();
    assert!(e.contains("--frames 1000000000") && e.contains("GB"), "{e}");
    assert!(e.contains("--memory-gb"), "the override is named: {e}");
    assert!(!out.exists());
    // The limit is the request's: a run just above a lowered limit is refused, one below it
    // goes through.
    let mut r = request(dir.path().join("clip"), out.clone());
    r.frames = 20;
    let (_, vertices) = clip_size(&dir.path().join("clip"));
    r.memory_limit = (20 * vertices * 12 - 1) as u64;
    let e = run_jumpmap(&r, None).unwrap_err().to_string();
    assert!(e.contains("--frames 20"), "{e}");
    r.memory_limit = (20 * vertices * 12) as u64;
    run_jumpmap(&r, None).unwrap();
    assert!(out.exists());
    // Issue #18: an output estimated above 8 GiB is refused before the analysis unless
    // --force, even when the memory limit allows it (an OBJ folder is ~3× the positions).
    let folder = dir.path().join("frames");
    let mut r = request(dir.path().join("clip"), folder.clone());
    let frames_for = |bytes: u64, per_frame: u64| (bytes / per_frame + 1) as usize;
    let (_, triangles) = {
        let (clip, _) =
            meshio::load_animation(&dir.path().join("clip"), &Default::default()).unwrap();
        (clip.frames.len(), clip.triangles.len())
    };
    let per_frame = (vertices * 40 + triangles * 24) as u64;
    r.frames = frames_for(crate::commands::output_size::REFUSE_BYTES, per_frame);
    r.memory_limit = u64::MAX;
    let e = run_jumpmap(&r, None).unwrap_err().to_string();
    assert!(
        e.contains("the output would be") && e.contains("--force"),
        "{e}"
    );
    assert!(!folder.exists());
}

/// A GPU context, or `None` after the project's skip policy (fails under CI). Lavapipe wants
/// `XDG_RUNTIME_DIR` set (e.g. `/tmp`) in the test's environment.
fn gpu() -> Option<GpuContext> {
    match GpuContext::new(&GpuOptions::default()) {
        Ok(g) => Some(g),
        Err(e) => test_data::skip(&format!("no GPU adapter: {e}")),
    }
}

/// Mean absolute difference of two equally sized RGB panels, in 8-bit steps.
fn panel_difference(a: &[[u8; 3]], b: &[[u8; 3]]) -> f64 {
    let sum: u64 = a
        .iter()
        .zip(b)
        .flat_map(|(p, q)| (0..3).map(move |k| u64::from(p[k].abs_diff(q[k]))))
        .sum();
    sum as f64 / (3 * a.len()) as f64
}

#[test]
fn strip_shows_k_shaded_frames_of_the_run_side_by_side() {
    let Some(gpu) = gpu() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    write_clip(&dir.path().join("clip"));
    let png = dir.path().join("strip.png");
    let (k, w, h) = (5usize, 96u32, 64u32);
    let mut r = request(dir.path().join("clip"), dir.path().join("a.npy"));
    r.strip = Some(StripRequest {
        path: png.clone(),
        frames: k,
        panel_size: [w, h],
    });
    run_jumpmap(&r, Some(&gpu)).unwrap();
    let image = image::open(&png).unwrap().to_rgb8();
    assert_eq!(image.dimensions(), (k as u32 * w, h));
    let panels: Vec<Vec<[u8; 3]>> = (0..k as u32)
        .map(|p| {
            (0..h)
                .flat_map(|y| (0..w).map(move |x| (x, y)))
                .map(|(x, y)| image.get_pixel(p * w + x, y).0)
                .collect()
        })
        .collect();
    for (p, panel) in panels.iter().enumerate() {
        // Not blank: the grid covers a good part of each panel (the background is black) …
        let covered = panel.iter().filter(|px| px.iter().any(|c| *c > 0)).count();
        assert!(
            covered as f64 > 0.1 * panel.len() as f64,
            "panel {p}: {covered} of {} pixels drawn",
            panel.len()
        );
        // … and it is shaded, not a flat silhouette.
        let mut levels: Vec<u8> = panel.iter().map(|px| px[1]).filter(|g| *g > 0).collect();
        levels.sort_unstable();
        levels.dedup();
        assert!(levels.len() > 8, "panel {p}: grey levels {levels:?}");
    }
    // The run moves, so its frames differ: every panel differs from the first one's pose
    // somewhere, and not all of them only a little.
    let differences: Vec<f64> = panels[1..]
        .iter()
        .map(|p| panel_difference(&panels[0], p))
        .collect();
    assert!(
        differences.iter().copied().fold(0.0, f64::max) > 2.0,
        "panels barely differ: {differences:?}"
    );
    // Same frames, same camera: rendering the run again gives the same strip.
    let again = dir.path().join("again.png");
    r.strip.as_mut().unwrap().path = again.clone();
    run_jumpmap(&r, Some(&gpu)).unwrap();
    let second = image::open(&again).unwrap().to_rgb8();
    let drift = panel_difference(
        &image.pixels().map(|p| p.0).collect::<Vec<_>>(),
        &second.pixels().map(|p| p.0).collect::<Vec<_>>(),
    );
    assert!(drift < 0.5, "re-render differs by {drift}");
}

#[test]
fn bad_strips_are_refused_before_writing() {
    let dir = tempfile::tempdir().unwrap();
    write_clip(&dir.path().join("clip"));
    let out = dir.path().join("a.npy");
    let png = dir.path().join("s.png");
    let mut r = request(dir.path().join("clip"), out.clone());
    // Without an adapter, naming the flag.
    r.strip = Some(StripRequest::new(png.clone()));
    let e = run_jumpmap(&r, None).unwrap_err();
    assert!(e.to_string().contains("--strip"), "{e}");
    assert!(e.to_string().contains("s.png"), "{e}");
    // More panels than frames, or none.
    for k in [0, 201] {
        r.strip = Some(StripRequest {
            frames: k,
            ..StripRequest::new(png.clone())
        });
        let e = run_jumpmap(&r, None).unwrap_err();
        assert!(
            e.to_string().contains(&format!("--strip-frames {k}")),
            "{e}"
        );
    }
    // Not a PNG.
    r.strip = Some(StripRequest::new(dir.path().join("s.jpg")));
    let e = run_jumpmap(&r, None).unwrap_err();
    assert!(e.to_string().contains("s.jpg"), "{e}");
    assert!(!out.exists() && !png.exists());
}

#[test]
fn loop_output_repeats_with_the_requested_period() {
    let dir = tempfile::tempdir().unwrap();
    write_clip(&dir.path().join("clip"));
    let out = dir.path().join("loop.npy");
    let mut req = request(dir.path().join("clip"), out.clone());
    req.control.loop_length = Some(24);
    req.frames = 100;
    let summary = run_jumpmap(&req, None).unwrap();
    assert!(summary.stats.transitions >= 4, "{summary:?}");
    let (shape, data) = read_npy(&out);
    assert_eq!(shape, vec![100, SIDE * SIDE, 3]);
    let frame = |t: usize| &data[t * SIDE * SIDE * 3..(t + 1) * SIDE * SIDE * 3];
    for t in 0..100 - 24 {
        assert_eq!(frame(t), frame(t + 24), "frame {t}");
    }
    // The loop is reported, obeys the no-oscillation rule, and its key frames are the clip's.
    let info = summary.loop_info.expect("a --loop run reports its loop");
    assert_eq!(info.length, 24);
    assert!(
        info.shortest_run >= 6 && info.distinct_frames >= 6,
        "{info:?}"
    );
    let (clip, _) = meshio::load_animation(
        &dir.path().join("clip"),
        &meshio::AnimationOptions::default(),
    )
    .unwrap();
    let exact = (0..24)
        .filter(|&t| {
            clip.frames.iter().any(|f| {
                f.iter()
                    .flat_map(|v| v.to_array())
                    .zip(frame(t))
                    .all(|(a, b)| a.to_bits() == b.to_bits())
            })
        })
        .count();
    assert!(
        exact >= 24 - 3 * info.jumps,
        "{exact} of 24 frames are clip frames"
    );
    // A length with no acceptable loop is refused, naming the nearest lengths that have one.
    req.control.loop_length = Some(5);
    let err = run_jumpmap(&req, None).unwrap_err().to_string();
    assert!(err.contains("no acceptable loop of exactly 5"), "{err}");
    assert!(
        err.contains("above (up to 8)") && err.contains("below"),
        "{err}"
    );
}

#[test]
fn cells_switch_where_the_schedule_says() {
    let dir = tempfile::tempdir().unwrap();
    write_clip(&dir.path().join("calm"));
    write_clip_scaled(&dir.path().join("wild"), 2.0, Vec3::ZERO);
    let out = dir.path().join("cells.npy");
    let mut req = request(dir.path().join("calm"), out.clone());
    req.control.cells = vec![dir.path().join("wild")];
    req.control.cell_at = vec![(100, 1)];
    req.frames = 300;
    run_jumpmap(&req, None).unwrap();
    let (_, data) = read_npy(&out);
    let height = |t: usize| {
        data[t * SIDE * SIDE * 3..(t + 1) * SIDE * SIDE * 3]
            .chunks(3)
            .map(|p| p[2].abs())
            .fold(0.0f32, f32::max)
    };
    // Calm (|z| ≤ 1.3) before the switch, wild (|z| up to 2.6) once the horizon and the blend
    // have passed.
    assert!((0..100).all(|t| height(t) < 1.35));
    let late = (100 + 30 + 4..300).map(height).fold(0.0f32, f32::max);
    assert!(
        late > 2.0,
        "after the switch the wild cell plays: max |z| {late}"
    );
    // A schedule naming a missing cell, or a cell with another mesh, is refused.
    req.control.cell_at = vec![(100, 2)];
    let err = run_jumpmap(&req, None).unwrap_err().to_string();
    assert!(err.contains("cell 2") && err.contains("2 cell(s)"), "{err}");
    assert!(parse_cell_at("100:x").is_err());
    assert_eq!(parse_cell_at("100:1"), Ok((100, 1)));
}

#[test]
fn root_motion_keeps_a_walking_clip_walking() {
    let dir = tempfile::tempdir().unwrap();
    let step = Vec3::new(0.25, 0.0, 0.0);
    write_clip_scaled(&dir.path().join("walk"), 1.0, step);
    let out = dir.path().join("walk.npy");
    let mut req = request(dir.path().join("walk"), out.clone());
    req.params.root_motion = anim_pca::RootMotion::Extract;
    req.frames = 400;
    let summary = run_jumpmap(&req, None).unwrap();
    assert!(summary.stats.transitions > 5, "{summary:?}");
    let (_, data) = read_npy(&out);
    let centroid_x = |t: usize| {
        data[t * SIDE * SIDE * 3..(t + 1) * SIDE * SIDE * 3]
            .chunks(3)
            .map(|p| p[0])
            .sum::<f32>()
            / (SIDE * SIDE) as f32
    };
    // 400 frames at 0.25 per frame: it walks ten times the clip's own 40-frame distance.
    for t in 1..400 {
        let dx = centroid_x(t) - centroid_x(t - 1);
        assert!((dx - 0.25).abs() < 1e-3, "frame {t}: step {dx}");
    }
}
