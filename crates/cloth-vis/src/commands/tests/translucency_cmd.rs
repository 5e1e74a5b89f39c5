//! `cloth-vis sh` and `cloth-vis translucency` through the binary: the SH of a uniform map
//! against its closed form (E00 = 4π·K0·L, B = πL along every axis), a backlit sphere whose
//! far side glows, the sine deformer's image sequence, and refusals naming the flag and value
//! before any output.

use std::path::Path;

use super::common::{cli, text};

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

/// A uniform map of radiance `l` written as OpenEXR.
fn uniform_map(dir: &Path, l: f32) -> std::path::PathBuf {
    let path = dir.join("uniform.exr");
    lightsphere::Environment::from_latlong(16, 8, vec![[l; 3]; 128])
        .unwrap()
        .write_exr(&path)
        .unwrap();
    path
}

/// A closed icosphere of radius 0.02 m (2 cm of material) written as OBJ.
fn ball(dir: &Path) -> std::path::PathBuf {
    let (positions, triangles) = synth::obstacle_mesh(
        &synth::Obstacle::Sphere {
            centre: glam::Vec3::ZERO,
            radius: 0.02,
        },
        4,
    );
    let mut obj = String::new();
    for p in &positions {
        obj.push_str(&format!("v {} {} {}\n", p.x, p.y, p.z));
    }
    for t in &triangles {
        obj.push_str(&format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1));
    }
    let path = dir.join("ball.obj");
    std::fs::write(&path, obj).unwrap();
    path
}

#[test]
fn sh_of_a_uniform_map_is_its_closed_form() {
    let dir = tempfile::tempdir().unwrap();
    let map = uniform_map(dir.path(), 2.0);
    let out = dir.path().join("e.npy");
    let (ok, stdout, stderr) = run(&["sh", text(&map), "--out", text(&out)]);
    assert!(ok, "{stderr}");
    let e = meshio::read_npy_f32(&out).unwrap();
    assert_eq!(e.shape, [9, 3]);
    let e00 = 4.0 * std::f32::consts::PI * translucency::sh::K0 as f32 * 2.0;
    assert!((e.data[0] - e00).abs() < 1e-5, "{:?}", &e.data[..3]);
    assert!(e.data[3..].iter().all(|v| v.abs() < 1e-5), "{:?}", e.data);
    assert!(stdout.contains(" ms (no window); E00 = "), "{stdout}");
    // B = π·L along every axis.
    assert_eq!(
        stdout.matches("6.28319 6.28319 6.28319").count(),
        6,
        "{stdout}"
    );
}

#[test]
fn sh_refuses_bad_flags_before_any_output() {
    let dir = tempfile::tempdir().unwrap();
    let map = uniform_map(dir.path(), 1.0);
    let out = dir.path().join("e.npy");
    for (args, needle) in [
        (vec!["--window", "0"], "--window"),
        (vec!["--lanczos", "-1"], "--lanczos"),
        (vec!["--rotation", "nan"], "--rotation"),
    ] {
        let mut all = vec!["sh", text(&map), "--out", text(&out)];
        all.extend(args);
        let (ok, _, stderr) = run(&all);
        assert!(!ok && stderr.contains(needle), "{needle}: {stderr}");
        assert!(!out.exists());
    }
    let (ok, _, stderr) = run(&["sh", text(&map), "--out", text(&dir.path().join("e.txt"))]);
    assert!(!ok && stderr.contains(".npy"), "{stderr}");
    let missing = dir.path().join("none.hdr");
    let (ok, _, stderr) = run(&["sh", text(&missing), "--out", text(&out)]);
    assert!(!ok && stderr.contains("none.hdr"), "{stderr}");
    assert!(!out.exists());
}

#[test]
fn a_backlit_ball_glows_and_the_deformer_writes_a_sequence() {
    if !gpu() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let input = ball(dir.path());
    let png = dir.path().join("ball.exr");
    // The light behind the ball (−z), the camera in front (+z, framed automatically).
    let (ok, stdout, stderr) = run(&[
        "translucency",
        text(&input),
        "--light-pos",
        "0.01,0.0,-0.2",
        "--material",
        "skin1",
        "--render-size",
        "96x96",
        "--out",
        text(&png),
    ]);
    assert!(ok, "{stderr}");
    assert!(
        stdout.contains("translucency: ") && stdout.contains("cube map"),
        "{stdout}"
    );
    let image = exr::prelude::read_first_rgba_layer_from_file(
        &png,
        |res, _| vec![[0.0f32; 4]; res.width() * res.height()],
        |px, pos, (r, g, b, a): (f32, f32, f32, f32)| px[pos.y() * 96 + pos.x()] = [r, g, b, a],
    )
    .unwrap()
    .layer_data
    .channel_data
    .pixels;
    // The camera sees the unlit side: only the subsurface term lights it, redder than blue
    // (skin scatters red deepest).
    let centre = image[48 * 96 + 48];
    assert!(centre[3] > 0.99 && centre[0] > 0.0, "{centre:?}");
    assert!(centre[0] > centre[2], "{centre:?}");
    assert!(
        !dir.path().read_dir().unwrap().any(|e| e
            .unwrap()
            .file_name()
            .to_string_lossy()
            .ends_with(".run"))
    );

    let seq = dir.path().join("seq");
    let (ok, stdout, stderr) = run(&[
        "translucency",
        text(&input),
        "--light-dir",
        "0,0,-1",
        "--deform",
        "0.1,1,4",
        "--frames",
        "0..4",
        "--render-size",
        "64x64",
        "--out",
        text(&seq),
    ]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("per frame over 4 frames"), "{stdout}");
    for f in 0..4 {
        assert!(seq.join(format!("frame-{f:04}.png")).is_file());
    }
}

#[test]
fn translucency_refuses_bad_requests_before_any_output() {
    let dir = tempfile::tempdir().unwrap();
    let input = ball(dir.path());
    let png = dir.path().join("o.png");
    let cases: [(&[&str], &str); 5] = [
        (&["--light-pos", "0,0,1", "--material", "jade"], "jade"),
        (
            &[
                "--light-pos",
                "0,0,1",
                "--sigma-a",
                "-1,0,0",
                "--sigma-s",
                "1,1,1",
            ],
            "sigma_a",
        ),
        (&["--light-dir", "0,0,0"], "direction"),
        (&["--light-pos", "0,0,1", "--frames", "0..2"], "folder"),
        (&["--light-pos", "0,0,1", "--cube-size", "1"], "cube_size"),
    ];
    for (args, needle) in cases {
        let mut all = vec!["translucency", text(&input), "--out", text(&png)];
        all.extend_from_slice(args);
        let (ok, _, stderr) = run(&all);
        assert!(!ok && stderr.contains(needle), "{needle}: {stderr}");
        assert!(!png.exists());
    }
    // No light at all: clap names the flags.
    let (ok, _, stderr) = run(&["translucency", text(&input), "--out", text(&png)]);
    assert!(!ok && stderr.contains("--light-pos"), "{stderr}");
}

/// A big ball with a small one above it (along +y, or along +z when `z_up`), as OBJ: a shape
/// whose up axis shows in the picture.
fn snowman(dir: &Path, z_up: bool) -> std::path::PathBuf {
    let mut obj = String::new();
    let mut base = 1;
    for (centre, radius) in [
        (glam::Vec3::ZERO, 0.02),
        (glam::Vec3::new(0.0, 0.03, 0.0), 0.01),
    ] {
        let (positions, triangles) =
            synth::obstacle_mesh(&synth::Obstacle::Sphere { centre, radius }, 3);
        for p in &positions {
            // Z-up: (x, y, z) → (x, −z, y), a quarter turn about +x.
            let p = if z_up {
                glam::Vec3::new(p.x, -p.z, p.y)
            } else {
                *p
            };
            obj.push_str(&format!("v {} {} {}\n", p.x, p.y, p.z));
        }
        for t in &triangles {
            obj.push_str(&format!(
                "f {} {} {}\n",
                t[0] + base,
                t[1] + base,
                t[2] + base
            ));
        }
        base += positions.len() as u32;
    }
    let path = dir.join(if z_up { "z_up.obj" } else { "y_up.obj" });
    std::fs::write(&path, obj).unwrap();
    path
}

#[test]
fn a_z_up_copy_with_up_axis_z_renders_as_the_y_up_original() {
    if !gpu() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let (y_up, z_up) = (snowman(dir.path(), false), snowman(dir.path(), true));
    let render = |input: &Path, light_dir: &str, up: &str, name: &str| {
        let png = dir.path().join(name);
        let (ok, _, stderr) = run(&[
            "translucency",
            text(input),
            "--light-dir",
            light_dir,
            "--up-axis",
            up,
            "--exposure",
            "0",
            "--render-size",
            "64x64",
            "--out",
            text(&png),
        ]);
        assert!(ok, "{stderr}");
        image::open(&png).unwrap().to_rgb8().into_raw()
    };
    // The light (0.3, 1, 0.5) of the Y-up original is (0.3, −0.5, 1) in the Z-up copy's frame.
    let reference = render(&y_up, "0.3,1,0.5", "y", "y.png");
    let turned = render(&z_up, "0.3,-0.5,1", "z", "z.png");
    let lying = render(&z_up, "0.3,-0.5,1", "y", "lying.png");
    let mean_diff = |a: &[u8], b: &[u8]| {
        a.iter()
            .zip(b)
            .map(|(x, y)| f64::from(x.abs_diff(*y)))
            .sum::<f64>()
            / a.len() as f64
    };
    let (same, off) = (
        mean_diff(&reference, &turned),
        mean_diff(&reference, &lying),
    );
    // Stood up, the copy is the original up to the rounding of its turned vertices (measured:
    // identical PNGs on lavapipe).
    assert!(same < 0.5, "turned: {same}");
    // Left lying, the small ball sits beside the big one: another picture.
    assert!(off > 5.0, "lying: {off}");
}
