//! `cloth-vis anim compress | decompress | stats` on a small synthetic clip written as `.npy`:
//! the round trip through the binary reproduces the clip within the quantization tolerance,
//! `stats` prints the library's numbers, and bad input (a corrupt file, an unsupported output,
//! mismatched counts) is refused with the file named and nothing written.

use std::path::{Path, PathBuf};
use std::process::Output;

use crate::commands::cpca::{
    AutoBits, CompressRequest, DEFAULT_K_MAX, SearchMode, run_compress, run_stats,
};
use crate::commands::cpca_decompress::{DecompressRequest, run_decompress};
use anim_pca::compress::{Compressed, Decoder, bpvf_from_file};
use glam::Vec3;

use super::common::{cli, text};

const VERTICES: usize = 64;
const FRAMES: usize = 40;
/// Half-length of a bar; the clip spans about 10 + 2·BAR units.
const BAR: f32 = 2.0;

/// Two bars of 32 vertices, each rotating about its own centre at its own rate (independently
/// moving parts: no single low-rank basis serves both).
fn clip() -> Vec<Vec<Vec3>> {
    (0..FRAMES)
        .map(|t| {
            (0..VERTICES)
                .map(|m| {
                    let (part, s) = (m / 32, (m % 32) as f32 / 8.0 - BAR);
                    let a = t as f32 * if part == 0 { 0.10 } else { 0.23 };
                    Vec3::new(10.0 * part as f32 + s * a.cos(), s * a.sin(), 0.3 * s)
                })
                .collect()
        })
        .collect()
}

fn flat(frames: &[Vec<Vec3>]) -> Vec<f32> {
    frames
        .iter()
        .flat_map(|f| f.iter().flat_map(|p| p.to_array()))
        .collect()
}

/// Writes the clip as `clip.npy` in `dir` and returns its path and frames.
pub(super) fn write_clip(dir: &Path) -> (PathBuf, Vec<Vec<Vec3>>) {
    let frames = clip();
    let path = dir.join("clip.npy");
    meshio::write_npy_f32(&path, &[FRAMES, VERTICES, 3], &flat(&frames)).unwrap();
    (path, frames)
}

#[track_caller]
fn assert_ok(out: &Output) -> String {
    assert!(
        out.status.success(),
        "exit {:?}, stderr: {}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout.clone()).unwrap()
}

#[track_caller]
fn assert_fails_naming(out: &Output, needles: &[&str]) -> String {
    assert!(
        !out.status.success(),
        "expected failure, got {:?}",
        out.status
    );
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    for n in needles {
        assert!(err.contains(n), "stderr {err:?} does not contain {n:?}");
    }
    err
}

#[test]
fn round_trip_through_the_cli_reproduces_the_clip_and_stats_match_the_library() {
    let dir = tempfile::tempdir().unwrap();
    let (input, frames) = write_clip(dir.path());
    let cpca = dir.path().join("clip.cpca");
    let out = cli(&[
        "anim",
        "compress",
        text(&input),
        "--clusters",
        "2",
        "--components",
        "4",
        "--qc",
        "18",
        "--qw",
        "18",
        "--out",
        text(&cpca),
    ]);
    let line = assert_ok(&out);
    assert!(line.starts_with("compress: V = 64, F = 40"), "{line}");
    assert!(
        line.contains("k = 2, c = 4, c* = -, q_c = 18, q_w = 18"),
        "{line}"
    );

    let decoded = dir.path().join("decoded.npy");
    assert_ok(&cli(&[
        "anim",
        "decompress",
        text(&cpca),
        "--out",
        text(&decoded),
    ]));
    let array = meshio::read_npy_f32(&decoded).unwrap();
    assert_eq!(array.shape, vec![FRAMES, VERTICES, 3]);

    // The file decodes, in the library, to exactly what the CLI wrote.
    let bytes = std::fs::read(&cpca).unwrap();
    let packed = Compressed::from_bytes(&bytes).unwrap();
    let decoder = Decoder::new(&packed);
    assert_eq!(array.data, flat(&decoder.decode_all()));

    // Each part has rank ≤ 3 about its mean and c = 4, so only quantization is left: 18-bit
    // steps are about 4e-6 of each array's range; allow 1e-4 of the clip's extent.
    let extent = 10.0 + 2.0 * BAR;
    let worst = array
        .data
        .iter()
        .zip(flat(&frames))
        .map(|(a, b)| (a - b).abs())
        .fold(0.0f32, f32::max);
    assert!(worst < 1e-4 * extent, "max |Δ| = {worst}");

    // stats prints the library's numbers.
    let stats = assert_ok(&cli(&["anim", "stats", text(&input), text(&cpca)]));
    let d = decoder.distortion(&frames).unwrap();
    let rate = packed.rate();
    let (worst_frame, worst_df) =
        d.df.iter()
            .copied()
            .enumerate()
            .fold((0, 0.0), |b, (f, x)| if x > b.1 { (f, x) } else { b });
    assert_eq!(worst_df, d.worst_df());
    for expected in [
        format!("eq. 3.16 = {:.3}", rate.eq_3_16()),
        format!("eq. 3.17 = {:.3}", rate.eq_3_17()),
        format!(
            "file = {:.3} ({} bytes)",
            bpvf_from_file(bytes.len(), VERTICES, FRAMES),
            bytes.len()
        ),
        format!("d_a = {:.4}", d.da),
        format!("worst d_f = {worst_df:.4e} (frame {worst_frame})"),
    ] {
        assert!(stats.contains(&expected), "{stats:?} lacks {expected:?}");
    }
    // The two files the wrong way round: the order, and the command that was meant.
    let swapped = cli(&["anim", "stats", text(&cpca), text(&input)]);
    let said = String::from_utf8_lossy(&swapped.stderr);
    assert!(!swapped.status.success(), "{said}");
    let meant = format!(
        "`cloth-vis anim stats {} {}`",
        input.display(),
        cpca.display()
    );
    assert!(said.contains(&meant), "{said}");
    // The library call agrees with the binary.
    let summary = run_stats(&input, &cpca).unwrap();
    assert_eq!(summary.line(), stats.trim_end());
    assert_eq!(summary.distortion, d);
}

#[test]
fn time_compression_and_obj_folder_output() {
    let dir = tempfile::tempdir().unwrap();
    let (input, _) = write_clip(dir.path());
    let cpca = dir.path().join("t.cpca");
    let params = anim_pca::compress::CpcaParams {
        clusters: 2,
        components: 4,
        time_components: Some(8),
        ..Default::default()
    };
    let summary = run_compress(&CompressRequest {
        progress: false,
        input: input.clone(),
        clip: meshio::ClipSelector::First,
        topology: None,
        params,
        target: None,
        search: SearchMode::Clusters {
            k_max: DEFAULT_K_MAX,
        },
        auto_bits: AutoBits::default(),
        out: cpca.clone(),
    })
    .unwrap();
    assert_eq!(summary.rate.time_components, Some(8));
    assert_eq!(
        summary.file_bytes,
        std::fs::metadata(&cpca).unwrap().len() as usize
    );
    assert!(summary.distortion.da.is_finite());
    let folder = dir.path().join("frames");
    // Issue #12: decompressing into a folder that held older frames left stale frames beside
    // the new ones. A folder with files is now refused before any work, and replaced whole
    // with --force.
    std::fs::create_dir(&folder).unwrap();
    std::fs::write(folder.join("frame_99999.obj"), "stale").unwrap();
    let refused = run_decompress(&DecompressRequest {
        progress: false,
        input: cpca.clone(),
        out: folder.clone(),
        force: false,
    })
    .unwrap_err()
    .to_string();
    assert!(refused.contains("--force"), "{refused}");
    assert_eq!(std::fs::read_dir(&folder).unwrap().count(), 1);
    run_decompress(&DecompressRequest {
        progress: false,
        input: cpca.clone(),
        out: folder.clone(),
        force: true,
    })
    .unwrap();
    assert!(
        !folder.join("frame_99999.obj").exists(),
        "the stale frame is gone"
    );
    let beside: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with('.'))
        .collect();
    assert!(beside.is_empty(), "no temporary folder is left: {beside:?}");
    // The clip came from .npy, so the frames are vertex-only OBJ (which meshio's loader
    // refuses as an animation): read the `v` lines directly.
    let expected =
        Decoder::new(&Compressed::from_bytes(&std::fs::read(&cpca).unwrap()).unwrap()).decode_all();
    assert_eq!(std::fs::read_dir(&folder).unwrap().count(), FRAMES);
    for (f, b) in expected.iter().enumerate() {
        let obj = std::fs::read_to_string(folder.join(format!("frame_{f:05}.obj"))).unwrap();
        let a: Vec<Vec3> = obj
            .lines()
            .filter_map(|l| l.strip_prefix("v "))
            .map(|l| {
                let xyz: Vec<f32> = l.split(' ').map(|x| x.parse().unwrap()).collect();
                Vec3::from_slice(&xyz)
            })
            .collect();
        // OBJ holds the shortest round-tripping decimal of each f32: exact.
        assert_eq!(&a, b, "frame {f}");
    }
    // Same parameters and seed: the same file.
    let again = dir.path().join("again.cpca");
    run_compress(&CompressRequest {
        progress: false,
        input,
        clip: meshio::ClipSelector::First,
        topology: None,
        params,
        target: None,
        search: SearchMode::Clusters {
            k_max: DEFAULT_K_MAX,
        },
        auto_bits: AutoBits::default(),
        out: again.clone(),
    })
    .unwrap();
    assert_eq!(
        std::fs::read(&again).unwrap(),
        std::fs::read(&cpca).unwrap()
    );
}

#[test]
fn corrupt_file_is_refused_naming_it_and_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let (input, _) = write_clip(dir.path());
    let cpca = dir.path().join("clip.cpca");
    assert_ok(&cli(&[
        "anim",
        "compress",
        text(&input),
        "--clusters",
        "2",
        "--components",
        "4",
        "--out",
        text(&cpca),
    ]));
    let mut bytes = std::fs::read(&cpca).unwrap();
    // A payload byte: the checksum catches it. The magic: refused before anything else.
    for at in [bytes.len() / 2, 0] {
        bytes[at] ^= 0x5a;
        let bad = dir.path().join(format!("bad_{at}.cpca"));
        std::fs::write(&bad, &bytes).unwrap();
        bytes[at] ^= 0x5a;
        for out in ["bad.npy", "bad.glb", "bad_frames"] {
            let out = dir.path().join(out);
            let run = cli(&["anim", "decompress", text(&bad), "--out", text(&out)]);
            assert_fails_naming(&run, &[text(&bad)]);
            assert!(!out.exists(), "{} was written", out.display());
        }
        let run = cli(&["anim", "stats", text(&input), text(&bad)]);
        assert_fails_naming(&run, &[text(&bad)]);
    }
    // No temporary files left behind either.
    let names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(
        names
            .iter()
            .all(|n| n.ends_with(".npy") || n.ends_with(".cpca")),
        "{names:?}"
    );
}

#[test]
fn unsupported_outputs_are_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    // The inputs do not exist: an error naming the output proves nothing was read.
    let missing = dir.path().join("missing.cpca");
    let out = dir.path().join("out.txt");
    let run = cli(&["anim", "decompress", text(&missing), "--out", text(&out)]);
    let err = assert_fails_naming(&run, &[text(&out), ".txt", ".npy", ".glb"]);
    assert!(!err.contains("missing.cpca"), "{err}");

    let missing_clip = dir.path().join("missing.npy");
    let out = dir.path().join("clip.npy");
    let run = cli(&["anim", "compress", text(&missing_clip), "--out", text(&out)]);
    let err = assert_fails_naming(&run, &[text(&out), ".cpca"]);
    assert!(!err.contains("missing.npy"), "{err}");
    assert!(!out.exists());

    // A .glb needs triangles, and a clip from .npy has none: refused before decoding.
    let (input, _) = write_clip(dir.path());
    let cpca = dir.path().join("clip.cpca");
    let params = anim_pca::compress::CpcaParams {
        clusters: 2,
        ..Default::default()
    };
    run_compress(&CompressRequest {
        progress: false,
        input,
        clip: meshio::ClipSelector::First,
        topology: None,
        params,
        target: None,
        search: SearchMode::Clusters {
            k_max: DEFAULT_K_MAX,
        },
        auto_bits: AutoBits::default(),
        out: cpca.clone(),
    })
    .unwrap();
    let glb = dir.path().join("clip.glb");
    let err = run_decompress(&DecompressRequest {
        progress: false,
        input: cpca.clone(),
        out: glb.clone(),
        force: false,
    })
    .unwrap_err()
    .to_string();
    assert!(
        err.contains(text(&cpca)) && err.contains("triangles"),
        "{err}"
    );
    assert!(!glb.exists());

    // A bad parameter names itself and its value; nothing is written.
    let bad = dir.path().join("bad.cpca");
    let run = cli(&[
        "anim",
        "compress",
        text(&dir.path().join("clip.npy")),
        "--qc",
        "33",
        "--out",
        text(&bad),
    ]);
    assert_fails_naming(&run, &["bits_components", "33"]);
    assert!(!bad.exists());
}

#[test]
fn stats_refuses_mismatched_counts_naming_both_files() {
    let dir = tempfile::tempdir().unwrap();
    let (input, frames) = write_clip(dir.path());
    let cpca = dir.path().join("clip.cpca");
    assert_ok(&cli(&[
        "anim",
        "compress",
        text(&input),
        "--clusters",
        "2",
        "--out",
        text(&cpca),
    ]));
    let short = dir.path().join("short.npy");
    meshio::write_npy_f32(&short, &[FRAMES - 1, VERTICES, 3], &flat(&frames[1..])).unwrap();
    let run = cli(&["anim", "stats", text(&short), text(&cpca)]);
    assert_fails_naming(
        &run,
        &[
            text(&short),
            text(&cpca),
            &format!("{} frames x {VERTICES} vertices", FRAMES - 1),
            &format!("{FRAMES} frames x {VERTICES} vertices"),
        ],
    );
}

/// A GPU context, or `None` after the project's skip policy (fails under CI).
fn gpu() -> Option<gpu_context::GpuContext> {
    match gpu_context::GpuContext::new(&gpu_context::GpuOptions::default()) {
        Ok(g) => Some(g),
        Err(e) => test_data::skip(&format!("no GPU adapter: {e}")),
    }
}

#[test]
fn stats_draws_the_error_per_frame_and_the_clusters() {
    let dir = tempfile::tempdir().unwrap();
    let (input, frames) = write_clip(dir.path());
    let cpca = dir.path().join("c.cpca");
    compress_into(&input.clone(), &cpca, 2, 2);
    let svg = dir.path().join("df.svg");
    let out = cli(&[
        "anim",
        "stats",
        text(&input),
        text(&cpca),
        "--error-plot",
        text(&svg),
    ]);
    assert!(out.status.success(), "{out:?}");
    let chart = std::fs::read_to_string(&svg).unwrap();
    assert!(chart.starts_with("<svg") && chart.trim_end().ends_with("</svg>"));
    // One polyline point per frame.
    let line = chart.split("<polyline").nth(1).unwrap();
    let points = line
        .split("points=\"")
        .nth(1)
        .unwrap()
        .split('"')
        .next()
        .unwrap();
    assert_eq!(points.split_whitespace().count(), frames.len());

    // A wrong picture extension is refused before any work.
    let out = cli(&[
        "anim",
        "stats",
        text(&input),
        text(&cpca),
        "--error-plot",
        text(&dir.path().join("df.png")),
    ]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("df.png"));

    let Some(gpu) = gpu() else { return };
    // The npy clip has no triangles: a cluster picture of it is refused by name.
    let request = crate::commands::cpca::StatsRequest {
        clip: meshio::ClipSelector::First,
        topology: None,
        original: input.clone(),
        cpca: cpca.clone(),
        clusters_png: Some(dir.path().join("clusters.png")),
        error_plot: None,
        frontier: false,
        progress: false,
    };
    let e = crate::commands::cpca::run_stats_with_pictures(&request, Some(&gpu)).unwrap_err();
    assert!(e.to_string().contains("triangles"), "{e}");
    assert!(!dir.path().join("clusters.png").exists());
    // With triangles: two ribbons (the bars given a width along z, so that their triangles
    // have area), each turning at its own rate; each cluster gets its own colour.
    let ribbons: Vec<Vec<Vec3>> = (0..FRAMES)
        .map(|t| {
            (0..VERTICES)
                .map(|m| {
                    let (part, s) = (m / 32, ((m % 32) / 2) as f32 / 4.0 - BAR);
                    let a = t as f32 * if part == 0 { 0.10 } else { 0.23 };
                    let z = if m % 2 == 0 { -0.5 } else { 0.5 };
                    Vec3::new(10.0 * part as f32 + s * a.cos(), s * a.sin(), z)
                })
                .collect()
        })
        .collect();
    let triangles: Vec<[u32; 3]> = (0..2u32)
        .flat_map(|bar| (0..15u32).map(move |q| bar * 32 + 2 * q))
        .flat_map(|i| [[i, i + 1, i + 2], [i + 1, i + 3, i + 2]])
        .collect();
    let packed = Compressed::encode(
        &ribbons,
        &triangles,
        30.0,
        &anim_pca::compress::CpcaParams {
            clusters: 2,
            components: 2,
            ..Default::default()
        },
    )
    .unwrap();
    let image =
        crate::commands::cpca::cluster_strip(&gpu, &packed, Path::new("clusters.png")).unwrap();
    // Count distinct hues among lit pixels: background plus one per cluster at least.
    let colours = figures::strip::label_colours(2);
    let hue = |c: glam::Vec3| (c.x - c.z).signum();
    assert_ne!(
        hue(colours[0]),
        hue(colours[1]),
        "the two labels share a hue"
    );
    let mut seen = [false; 2];
    for p in image.pixels() {
        let [r, _, b, _] = p.0;
        if r.abs_diff(b) > 40 {
            seen[usize::from(b > r)] = true;
        }
    }
    assert_eq!(seen, [true, true], "both clusters' colours should appear");
    let labels = packed.labels();
    assert_ne!(
        labels[0], labels[40],
        "the bars should fall in different clusters"
    );
}

/// `anim decompress` streams frames into a `.glb` (issue #12: it decoded the whole clip, then
/// copied it again, before writing): the file reads back as the decoder's frames, up to the
/// f32 rounding of the morph-target layout (frame 0 + delta).
#[test]
fn glb_output_reads_back_as_the_decoded_frames() {
    let dir = tempfile::tempdir().unwrap();
    // The two-bar clip as a ribbon: consecutive vertices of each bar form triangles.
    let triangles: Vec<[u32; 3]> = (0..VERTICES as u32 - 2)
        .filter(|i| i % 32 < 30)
        .map(|i| [i, i + 1, i + 2])
        .collect();
    let input = dir.path().join("clip.glb");
    let animation = meshio::Animation {
        triangles: triangles.clone(),
        frames: clip(),
        frame_rate: 30.0,
        uvs: None,
    };
    meshio::write_glb_animation(&input, &animation).unwrap();
    let cpca = dir.path().join("clip.cpca");
    compress_into(&input, &cpca, 2, 6);
    let glb = dir.path().join("out/decoded.glb");
    let run = cli(&["anim", "decompress", text(&cpca), "--out", text(&glb)]);
    assert_ok(&run);
    let (back, _) = meshio::load_animation(&glb, &meshio::AnimationOptions::default()).unwrap();
    let expected =
        Decoder::new(&Compressed::from_bytes(&std::fs::read(&cpca).unwrap()).unwrap()).decode_all();
    assert_eq!(back.frames.len(), expected.len());
    // The same triangles, each possibly starting at another corner (same winding).
    let canonical = |t: &[u32; 3]| {
        let k = (0..3).min_by_key(|&k| t[k]).unwrap_or(0);
        [t[k], t[(k + 1) % 3], t[(k + 2) % 3]]
    };
    let back_triangles: Vec<[u32; 3]> = back.triangles.iter().map(canonical).collect();
    assert_eq!(back_triangles, triangles);
    for (f, (a, b)) in back.frames.iter().zip(&expected).enumerate() {
        for (p, q) in a.iter().zip(b) {
            // |p| ≤ 12: two roundings of f32 (delta, then sum) stay below 4 ulp of 16.
            assert!(
                (*p - *q).abs().max_element() <= 4e-6,
                "frame {f}: {p} vs {q}"
            );
        }
    }
    // The same frames as a float vertex-animation texture: exactly the decoder's positions.
    let vat = dir.path().join("out/decoded.vat.exr");
    assert_ok(&cli(&[
        "anim",
        "decompress",
        text(&cpca),
        "--out",
        text(&vat),
    ]));
    let (_, _, texels) = super::common::read_exr_rgba(&vat);
    for (f, frame) in expected.iter().enumerate() {
        for (v, p) in frame.iter().enumerate() {
            let t = texels[f * VERTICES + v];
            assert_eq!(
                [t[0], t[1], t[2], t[3]],
                [p.x, p.y, p.z, 1.0],
                "frame {f} vertex {v}"
            );
        }
    }
    assert!(dir.path().join("out/decoded.vat.json").is_file());
}

/// A `.glb` morph animation's weights grow as F²: a clip longer than
/// `meshio::MAX_GLB_ANIMATION_FRAMES` is refused before decoding, naming the count, the limit
/// and the outputs that take it; nothing is written.
#[test]
fn a_clip_too_long_for_glb_is_refused_before_decoding() {
    let dir = tempfile::tempdir().unwrap();
    let frames = meshio::MAX_GLB_ANIMATION_FRAMES + 1;
    let long: Vec<f32> = (0..frames)
        .flat_map(|f| {
            let t = f as f32 * 0.01;
            [0.0, 0.0, t, 1.0, t.sin(), 0.0, 0.0, 1.0, t.cos()]
        })
        .collect();
    let input = dir.path().join("long.npy");
    meshio::write_npy_f32(&input, &[frames, 3, 3], &long).unwrap();
    let cpca = dir.path().join("long.cpca");
    compress_into(&input, &cpca, 1, 2);
    let glb = dir.path().join("long.glb");
    let run = cli(&["anim", "decompress", text(&cpca), "--out", text(&glb)]);
    assert_fails_naming(
        &run,
        &[
            text(&glb),
            "4097 frames",
            "MAX_GLB_ANIMATION_FRAMES",
            ".npy",
        ],
    );
    assert!(!glb.exists());
}

/// `anim compress INPUT --clusters K --components C --out CPCA`, through the library.
fn compress_into(input: &Path, cpca: &Path, clusters: usize, components: usize) {
    run_compress(&CompressRequest {
        progress: false,
        input: input.to_owned(),
        clip: meshio::ClipSelector::First,
        topology: None,
        params: anim_pca::compress::CpcaParams {
            clusters,
            components,
            ..Default::default()
        },
        target: None,
        search: SearchMode::Clusters {
            k_max: DEFAULT_K_MAX,
        },
        auto_bits: AutoBits::default(),
        out: cpca.to_owned(),
    })
    .unwrap();
}

#[test]
fn default_bits_are_the_fewest_within_one_percent_of_the_unquantized_error() {
    // Issue #19: 18-bit codes spent bits for nothing. Without --qc/--qw the bits are chosen:
    // the decoded d_a stays within 1 % of the 32-bit (unquantized) d_a, and where the model
    // itself is lossy (one cluster, one component for two bars turning at their own rates)
    // the file is smaller than the thesis's 18/18 at the same k and c.
    let dir = tempfile::tempdir().unwrap();
    let (input, _) = write_clip(dir.path());
    let params = anim_pca::compress::CpcaParams {
        clusters: 1,
        components: 1,
        ..Default::default()
    };
    let run = |auto_bits, params, name: &str| {
        run_compress(&CompressRequest {
            progress: false,
            input: input.clone(),
            clip: meshio::ClipSelector::First,
            topology: None,
            params,
            target: None,
            search: SearchMode::Clusters {
                k_max: DEFAULT_K_MAX,
            },
            auto_bits,
            out: dir.path().join(name),
        })
        .unwrap()
    };
    let both = AutoBits {
        components: true,
        weights: true,
    };
    let chosen = run(both, params, "auto.cpca");
    let (d0, tried) = chosen.bits.expect("bits were chosen");
    assert!(tried <= 12, "{tried} encodings");
    let bound = d0 + (0.01 * d0).max(anim_pca::compress::DA_FLOOR);
    assert!(chosen.distortion.da <= bound, "{chosen:?}");
    let fixed = run(AutoBits::default(), params, "fixed.cpca");
    assert!(fixed.bits.is_none());
    assert!(
        chosen.file_bytes < fixed.file_bytes,
        "chosen {} bytes, 18/18 {} bytes",
        chosen.file_bytes,
        fixed.file_bytes
    );
    assert!(chosen.line().contains("chosen"), "{}", chosen.line());
    // One bit fewer of q_w breaks the 1 % (the bisection measured it).
    let qw = chosen.rate.bits_weights;
    if qw > 1 {
        let fewer = anim_pca::compress::CpcaParams {
            bits_components: chosen.rate.bits_components,
            bits_weights: qw - 1,
            ..params
        };
        let worse = run(AutoBits::default(), fewer, "fewer.cpca");
        assert!(
            worse.distortion.da > d0 * 1.01 + 1e-9,
            "q_w {} also meets it",
            qw - 1
        );
    }
    // A fixed q_c is kept while q_w is chosen.
    let only_w = run(
        AutoBits {
            components: false,
            weights: true,
        },
        anim_pca::compress::CpcaParams {
            bits_components: 20,
            ..params
        },
        "only_w.cpca",
    );
    assert_eq!(only_w.rate.bits_components, 20);
    assert_eq!(only_w.rate.bits_weights, qw);
}
