//! `cloth-vis hemicube` through the binary: the open fraction equals the library's maps,
//! NaN for unused vertices, radiance [N, 3] under a light, the seed's point-light limitation
//! against the exact ray, and refusals naming the flag and value before any work.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::common::{cli, text, z_up_copy};
use glam::Vec3;

/// A 5×5 floor facing +y, a 2×2 roof 0.5 above its middle (facing down), and one vertex used
/// by no face (the last).
fn floor_and_roof(dir: &Path) -> PathBuf {
    let mut obj = String::new();
    for i in 0..5 {
        for j in 0..5 {
            obj.push_str(&format!("v {} 0 {}\n", i as f32 * 0.25, j as f32 * 0.25));
        }
    }
    for (x, z) in [(0.25, 0.25), (0.75, 0.25), (0.75, 0.75), (0.25, 0.75)] {
        obj.push_str(&format!("v {x} 0.5 {z}\n"));
    }
    obj.push_str("v 9 9 9\n");
    for i in 0..4 {
        for j in 0..4 {
            let a = i * 5 + j + 1;
            obj.push_str(&format!(
                "f {a} {} {}\nf {a} {} {}\n",
                a + 1,
                a + 6,
                a + 6,
                a + 5
            ));
        }
    }
    obj.push_str("f 26 27 28\nf 26 28 29\n");
    let path = dir.join("scene.obj");
    std::fs::write(&path, obj).unwrap();
    path
}

fn run_ok(args: &[&str]) -> String {
    let out = cli(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

#[test]
fn open_fraction_matches_the_library_with_nan_for_unused_vertices() {
    let dir = tempfile::tempdir().unwrap();
    let input = floor_and_roof(dir.path());
    let out = dir.path().join("a.npy");
    let stdout = run_ok(&[
        "hemicube",
        text(&input),
        "--res",
        "16",
        "--builder",
        "cpu",
        "--out",
        text(&out),
    ]);
    let lines: Vec<&str> = stdout.lines().collect();
    let [line, wrote] = lines[..] else {
        panic!("a summary and a `wrote` line: {stdout}");
    };
    assert!(
        line.starts_with("hemicube: HC 16x16 x 30 vertices in ")
            && line.ends_with(" ms (cpu), 112 bytes per vertex"),
        "{line}"
    );
    assert_eq!(wrote, format!("wrote {}", out.display()));
    let array = meshio::read_npy_f32(&out).unwrap();
    assert_eq!(array.shape, vec![30]);
    let (mesh, _) = meshio::load_mesh(&input, &meshio::LoadOptions::default()).unwrap();
    let scene = occlusion_gpu::Scene::single(mesh.positions, mesh.normals, mesh.triangles).unwrap();
    let layout = Arc::new(
        hemicube::PixelLayout::new(
            hemicube::Model::Hemicube { res: 16 },
            hemicube::FormFactorRule::Exact,
        )
        .unwrap(),
    );
    let (maps, _) =
        hemicube::build_with_rays(&scene, layout, &hemicube::BuildParams::default()).unwrap();
    let expected = maps.open_fraction();
    for (i, (a, e)) in array.data.iter().zip(&expected).enumerate() {
        assert!(
            (a.is_nan() && e.is_nan()) || a == e,
            "vertex {i}: {a} vs {e}"
        );
    }
    assert!(array.data[29].is_nan());
    // The floor's centre (2, 2) lies under the roof, whose form factor from there is
    // (4/π) b atan(b), b = 0.5/√1.25 (a 0.5-wide square 0.5 above): 0.238 blocked.
    let b = 0.5f64 / 1.25f64.sqrt();
    let blocked = 4.0 / std::f64::consts::PI * b * b.atan();
    assert!(
        (f64::from(array.data[12]) - (1.0 - blocked)).abs() < 5e-3,
        "{:?}",
        array.data
    );
    assert!(array.data[0] > 0.9, "{:?}", array.data);
}

#[test]
fn a_light_between_vertex_and_roof_is_occluded_by_the_map_and_lit_by_the_ray() {
    let dir = tempfile::tempdir().unwrap();
    let input = floor_and_roof(dir.path());
    let run = |test: &str| {
        let out = dir.path().join(format!("{test}.npy"));
        run_ok(&[
            "hemicube",
            text(&input),
            "--res",
            "16",
            "--builder",
            "cpu",
            "--point-light",
            "0.5,0.25,0.5,1,1,1",
            "--light-test",
            test,
            "--out",
            text(&out),
        ]);
        let array = meshio::read_npy_f32(&out).unwrap();
        assert_eq!(array.shape, vec![30, 3]);
        Vec3::from_slice(&array.data[12 * 3..12 * 3 + 3])
    };
    // Vertex 12 at (0.5, 0, 0.5), the light 0.25 straight above it: (1/π) · 1 · 1 / 0.0625.
    assert_eq!(run("map"), Vec3::ZERO);
    let exact = 1.0 / (std::f32::consts::PI * 0.0625);
    let lit = run("ray");
    assert!(
        (lit - Vec3::splat(exact)).abs().max_element() < 1e-3 * exact,
        "{lit}"
    );
}

#[test]
fn bad_flags_are_refused_naming_the_value() {
    let dir = tempfile::tempdir().unwrap();
    let input = floor_and_roof(dir.path());
    let out = dir.path().join("x.npy");
    let i = text(&input);
    let o = text(&out);
    for (args, needle) in [
        (vec!["--res", "7"], "hemicube resolution 7"),
        (vec!["--res", "0"], "hemicube resolution 0"),
        (vec!["--model", "sp", "--aperture", "180"], "aperture 180"),
        (
            vec!["--model", "hs", "--builder", "gpu"],
            "cannot be rasterised",
        ),
        (vec!["--res", "16x4"], "PHIxTHETA is for --model hs"),
        (vec!["--rotation", "30"], "--rotation 30"),
        (vec!["--point-light", "1,2,3"], "got 3 numbers"),
        (vec!["--point-light", "1,2,3,1,1,-1"], "intensity"),
        (
            vec!["--builder", "gpu", "--max-distance", "0.2"],
            "--max-distance",
        ),
        (vec!["--max-distance", "-1"], "--max-distance -1"),
        (vec!["--frame", "3"], "--frame 3"),
    ] {
        let mut all = vec!["hemicube", i, "--out", o];
        all.extend(args.iter().copied());
        let run = cli(&all);
        let err = String::from_utf8_lossy(&run.stderr);
        assert!(!run.status.success(), "{args:?} succeeded");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(!out.exists(), "{args:?} left an output");
    }
    // 2.3 GB of maps (4,356 vertices × 2048² bits): refused after loading, before building.
    let run = cli(&[
        "hemicube",
        "synth:cloth",
        "--model",
        "hs",
        "--res",
        "2048x2048",
        "--builder",
        "cpu",
        "--out",
        o,
    ]);
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(err.contains("lower --res"), "{err}");
    let run = cli(&["hemicube", i, "--out", text(&dir.path().join("x.txt"))]);
    assert!(String::from_utf8_lossy(&run.stderr).contains("--out must end in .npy"));
}

#[test]
fn a_z_up_copy_with_up_axis_z_gets_the_radiance_of_the_y_up_original() {
    use crate::commands::hemicube::{Builder, HemicubeRequest, run_hemicube};
    use crate::commands::up_axis::UpAxis;
    let dir = tempfile::tempdir().unwrap();
    let input = floor_and_roof(dir.path());
    // The same scene authored Z-up.
    let z_up = z_up_copy(&input);
    // A smooth lat-long map: bright zenith, dim nadir, a gentle swing in azimuth.
    let (w, h) = (64usize, 32usize);
    let texels = (0..w * h)
        .map(|i| {
            let (col, row) = ((i % w) as f32, (i / w) as f32);
            let up = 1.0 - (row + 0.5) / h as f32;
            let swing = (std::f32::consts::TAU * (col + 0.5) / w as f32).cos();
            [1.0 + 4.0 * up + 0.5 * swing, 1.0 + 3.0 * up, 1.0 + 2.0 * up]
        })
        .collect();
    let sky = lightsphere::Environment::from_latlong(w, h, texels).unwrap();
    let radiance = |input: &Path, up_axis: UpAxis, name: &str| {
        let out = dir.path().join(name);
        let request = HemicubeRequest {
            input: input.to_owned(),
            topology: None,
            frame: 0,
            model: hemicube::Model::Hemicube { res: 16 },
            rule: hemicube::FormFactorRule::Exact,
            builder: Some(Builder::Cpu),
            max_distance: None,
            environment: Some(sky.clone()),
            rotation_deg: 30.0,
            up_axis,
            lookup: hemicube::EnvLookup::Exact,
            point_lights: Vec::new(),
            light_test: hemicube::PointVisibility::Ray,
            out: Some(out.clone()),
            render: None,
            exposure_ev: None,
            render_size: [64, 64],
            progress: false,
        };
        run_hemicube(&request, None).unwrap();
        meshio::read_npy_f32(&out).unwrap().data
    };
    let reference = radiance(&input, UpAxis::PosY, "y.npy");
    let turned = radiance(&z_up, UpAxis::PosZ, "z.npy");
    let lying = radiance(&z_up, UpAxis::PosY, "lying.npy");
    let worst = |a: &[f32], b: &[f32]| {
        a.iter()
            .zip(b)
            .filter(|(x, _)| x.is_finite())
            .map(|(x, y)| ((x - y) / x).abs())
            .fold(0.0f32, f32::max)
    };
    // A quarter turn carries each vertex's hemicube frame with it: equal to rounding
    // (measured 9e-8 relative).
    let (same, off) = (worst(&reference, &turned), worst(&reference, &lying));
    assert!(same < 1e-4, "turned: {same}");
    // Without --up-axis the bright zenith lights the lying copy from the side.
    assert!(off > 0.2, "lying: {off}");
}
