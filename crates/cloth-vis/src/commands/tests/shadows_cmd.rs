//! `cloth-vis shadows` through the binary: the mask of a square over the ground by stencil and
//! by rays against the cells it must cover, the row/column convention of the issue, LOD
//! casters, the rendered picture, and refusals naming the flag and value before any output.

use std::path::Path;

use super::common::{binary, cli, text, z_up_copy};

/// A unit square at height 1 centred over (0.25, 0), wound to face down (the light is above:
/// one-sided casting would drop it, two-sided must keep it; the command picks two-sided for a
/// mesh with border edges).
fn square(dir: &Path) -> std::path::PathBuf {
    let path = dir.join("square.obj");
    std::fs::write(
        &path,
        "v -0.25 1 -0.5\nv 0.75 1 -0.5\nv 0.75 1 0.5\nv -0.25 1 0.5\nf 1 2 3\nf 1 3 4\n",
    )
    .unwrap();
    path
}

fn run(args: &[&str]) -> (bool, String, String) {
    let out = cli(args);
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn gpu() -> bool {
    gpu_context::testing::gpu_or_skip().is_some()
}

#[test]
fn the_mask_covers_the_squares_shadow_in_the_issues_row_and_column_order() {
    let dir = tempfile::tempdir().unwrap();
    let input = square(dir.path());
    // Extent x ∈ [−1, 1] (8 columns of 0.25), z ∈ [−2, 2] (8 rows of 0.5); the light straight
    // above projects the square onto x ∈ [−0.25, 0.75], z ∈ [−0.5, 0.5]: columns 3..=6, rows
    // 3..=4.
    let expected: Vec<f32> = (0..8)
        .flat_map(|j| {
            (0..8).map(move |i| f32::from(u8::from((3..=6).contains(&i) && (3..=4).contains(&j))))
        })
        .collect();
    let mut modes = vec!["--cpu"];
    if gpu() {
        modes.push("--sides=auto");
    }
    for mode in modes {
        let out = dir.path().join(format!("mask{}.npy", mode.len()));
        let (ok, stdout, stderr) = run(&[
            "shadows",
            text(&input),
            "--light-dir",
            "0,1,0",
            "--ground",
            "0",
            "--ground-extent",
            "-1,-2,1,2",
            "--grid",
            "8",
            mode,
            "--out",
            text(&out),
        ]);
        assert!(ok, "{mode}: {stderr}");
        assert!(
            stdout.starts_with("shadows: 2 triangles (caster) in "),
            "{stdout}"
        );
        assert!(stdout.contains(", two-sided,"), "{stdout}");
        let mask = meshio::read_npy_f32(&out).unwrap();
        assert_eq!(mask.shape, [8, 8]);
        assert_eq!(mask.data, expected, "{mode}");
    }
}

#[test]
fn a_lod_caster_and_a_picture() {
    if !gpu() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    // A closed icosphere written as OBJ: 1,280 triangles.
    let (positions, triangles) = synth::obstacle_mesh(
        &synth::Obstacle::Sphere {
            centre: glam::Vec3::new(0.0, 2.0, 0.0),
            radius: 1.0,
        },
        3,
    );
    let mut obj = String::new();
    for p in &positions {
        obj.push_str(&format!("v {} {} {}\n", p.x, p.y, p.z));
    }
    for t in &triangles {
        obj.push_str(&format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1));
    }
    let input = dir.path().join("ball.obj");
    std::fs::write(&input, obj).unwrap();
    let (out, picture) = (dir.path().join("m.npy"), dir.path().join("m.png"));
    let (ok, stdout, stderr) = run(&[
        "shadows",
        text(&input),
        "--light-pos",
        "0.3,6,0.2",
        "--ground",
        "0",
        "--grid",
        "64",
        "--lod",
        "hard",
        "--out",
        text(&out),
        "--render",
        text(&picture),
        "--render-size",
        "96x96",
    ]);
    assert!(ok, "{stderr}");
    assert!(
        stdout.starts_with("shadows: 128 triangles (caster)"),
        "{stdout}"
    );
    assert!(
        stdout.contains(", one-sided,") && stdout.contains("Hausdorff"),
        "{stdout}"
    );
    assert!(picture.is_file());
    // The disc of the sphere (radius 6/√15 = 1.55 from the formula) in the default extent
    // (x, z ∈ [−3, 3]): about π·1.55²/36 = 21 % of the cells.
    let mask = meshio::read_npy_f32(&out).unwrap();
    let share = mask.data.iter().sum::<f32>() / mask.data.len() as f32;
    assert!((share - 0.21).abs() < 0.03, "{share}");
}

#[test]
fn a_z_up_copy_with_up_axis_z_casts_the_y_up_originals_mask() {
    let dir = tempfile::tempdir().unwrap();
    let input = square(dir.path());
    let z_up = z_up_copy(&input);
    let mut modes = vec!["--cpu"];
    if gpu() {
        modes.push("--sides=two");
    }
    // Each light in the Y-up frame and in the Z-up copy's, (x, y, z) ↦ (x, −z, y).
    let lights = [
        ("--light-pos", "0.4,3,0.3", "0.4,-0.3,3"),
        ("--light-dir", "0.2,1,0.1", "0.2,-0.1,1"),
    ];
    for mode in modes {
        for (flag, y_up_light, z_up_light) in lights {
            let mask = |mesh: &Path, light: &str, up: &str| {
                let out = dir.path().join("mask.npy");
                let (ok, _, stderr) = run(&[
                    "shadows",
                    text(mesh),
                    flag,
                    light,
                    "--ground",
                    "0",
                    "--ground-extent",
                    "-1,-2,1,2",
                    "--grid",
                    "16",
                    "--up-axis",
                    up,
                    mode,
                    "--out",
                    text(&out),
                ]);
                assert!(ok, "{mode} {flag} {up}: {stderr}");
                meshio::read_npy_f32(&out).unwrap().data
            };
            let original = mask(&input, y_up_light, "y");
            let covered = original.iter().filter(|&&v| v > 0.0).count();
            assert!((20..100).contains(&covered), "{mode} {flag}: {covered}");
            // Stood up by an exact quarter turn: the same mask, cell for cell.
            assert_eq!(mask(&z_up, z_up_light, "z"), original, "{mode} {flag}");
            // Left lying, the square stands edge-on across the ground: another mask.
            assert_ne!(mask(&z_up, z_up_light, "y"), original, "{mode} {flag}");
        }
    }
}

/// Mesa's device-select layer has libwayland print "error: XDG_RUNTIME_DIR is invalid or not
/// set in the environment." where no session exists; the binary switches the layer off there
/// (`main.rs`), so a headless run's stderr holds nothing but its own messages.
#[test]
fn a_headless_gpu_run_prints_no_wayland_error() {
    if !gpu() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let input = square(dir.path());
    let out = dir.path().join("mask.npy");
    let run = std::process::Command::new(binary())
        .args([
            "shadows",
            text(&input),
            "--light-dir",
            "0,1,0",
            "--ground",
            "0",
        ])
        .args(["--grid", "8", "--out", text(&out)])
        .env_remove("XDG_RUNTIME_DIR")
        .env_remove("NODEVICE_SELECT")
        .env_remove("MESA_VK_DEVICE_SELECT")
        .env_remove("DRI_PRIME")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stderr}");
    assert!(!stderr.contains("XDG_RUNTIME_DIR"), "{stderr}");
}

#[test]
fn an_all_lit_mask_that_nothing_could_shadow_says_why() {
    let dir = tempfile::tempdir().unwrap();
    let input = square(dir.path());
    let out = dir.path().join("mask.npy");
    // The square is at y = 1.
    for (light, ground, why) in [
        (
            ["--light-dir", "0,1,0"],
            "2",
            "the mesh lies at or below the ground",
        ),
        (
            ["--light-dir", "0.3,-1,0"],
            "0",
            "points at or below the horizon",
        ),
        (
            ["--light-pos", "0,-0.5,0"],
            "0",
            "the light at height -0.5000 is at or below",
        ),
    ] {
        let mut args = vec!["shadows", text(&input), "--ground", ground, "--cpu"];
        args.extend(light);
        args.extend(["--grid", "16", "--out", text(&out)]);
        let (ok, stdout, stderr) = run(&args);
        assert!(ok, "{light:?}: {stderr}");
        assert!(stdout.contains("0.00 % shadowed"), "{stdout}");
        assert!(
            stdout.contains(why) && stdout.contains("nothing can shadow the ground"),
            "{light:?}: {stdout}"
        );
    }
    // A light above a mesh above the ground: no note.
    let (ok, stdout, _) = run(&[
        "shadows",
        text(&input),
        "--ground",
        "0",
        "--cpu",
        "--light-dir",
        "0,1,0",
        "--grid",
        "16",
        "--out",
        text(&out),
    ]);
    assert!(ok && !stdout.contains("note:"), "{stdout}");
}

#[test]
fn bad_flags_are_refused_before_any_output() {
    let dir = tempfile::tempdir().unwrap();
    let input = square(dir.path());
    let out = dir.path().join("never.npy");
    for (flags, expected) in [
        (vec!["--light-dir", "0,0,0"], "--light-dir"),
        (vec!["--light-dir", "0,1,0", "--grid", "0"], "grid = 0"),
        (vec!["--light-dir", "0,1,0", "--lod", "1.5"], "--lod"),
        (vec!["--light-dir", "0,1,0", "--alpha", "90"], "--alpha"),
        (
            vec!["--light-dir", "0,1,0", "--ground-extent", "1,0,0,1"],
            "ground extent",
        ),
        (vec!["--light-pos", "0,nan,0"], "not finite"),
    ] {
        let mut args = vec![
            "shadows",
            text(&input),
            "--ground",
            "0",
            "--cpu",
            "--out",
            text(&out),
        ];
        args.extend(flags.iter().copied());
        let (ok, _, stderr) = run(&args);
        assert!(!ok, "{flags:?} was accepted");
        assert!(stderr.contains(expected), "{flags:?}: {stderr}");
        assert!(!out.exists(), "{flags:?} left an output");
    }
    let (ok, _, stderr) = run(&[
        "shadows",
        text(&input),
        "--ground",
        "0",
        "--light-dir",
        "0,1,0",
        "--cpu",
        "--out",
        text(&dir.path().join("mask.txt")),
    ]);
    assert!(!ok && stderr.contains(".npy"), "{stderr}");
}

/// Without `--ground-extent` the mask holds the whole shadow of the square under a lamp just
/// above its height (the ×3 box alone ends 1.25 from the square's centre; this shadow runs
/// past 7): no shadowed cell on the mask's border, the square's footprint shadowed.
#[test]
fn the_default_extent_holds_a_low_lamps_whole_shadow() {
    let dir = tempfile::tempdir().unwrap();
    let input = square(dir.path());
    let out = dir.path().join("low.npy");
    let (ok, stdout, stderr) = run(&[
        "shadows",
        text(&input),
        "--light-pos",
        "1.5,1.2,0",
        "--ground",
        "0",
        "--cpu",
        "--grid",
        "64",
        "--out",
        text(&out),
    ]);
    assert!(ok, "{stderr}");
    let mask = meshio::read_npy_f32(&out).unwrap().data;
    let n = 64;
    let border = (0..n * n)
        .filter(|&k| {
            mask[k] > 0.0 && (k / n == 0 || k / n == n - 1 || k % n == 0 || k % n == n - 1)
        })
        .count();
    let share = mask.iter().sum::<f32>() / mask.len() as f32;
    assert!(
        border == 0 && share > 0.02,
        "{border} border cells, {share}: {stdout}"
    );
}
