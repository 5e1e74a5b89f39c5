//! Named adversarial cases for the facade: huge coordinate offsets, mirroring transforms,
//! frames outside an animation, a sun 10⁴× the sky, real meshes with unreferenced vertices,
//! scene values that would run for minutes (a 16384-wide sky) refused before any work, and a
//! scene file that is a FIFO.

mod common;

use cloth_vis::{Error, RunOptions, Scene, run_scene};
use common::{SMALL_SYNTH, gpu_available};

fn run(text: &str, base: &std::path::Path) -> Result<cloth_vis::RunOutput, Error> {
    let scene = Scene::from_toml(text, base, "hard case").unwrap();
    let dir = tempfile::tempdir().unwrap();
    run_scene(&scene, dir.path(), &RunOptions::default())
}

fn all_finite(output: &cloth_vis::RunOutput) -> bool {
    output
        .image
        .pixels()
        .iter()
        .all(|p| p.iter().all(|c| c.is_finite()))
}

#[test]
fn huge_offset_and_mirroring_scale_stay_finite_and_lit() {
    if !gpu_available() {
        return;
    }
    let text = format!(
        r#"effects = ["lighting"]
[[object]]
name = "cloth"
source = "synth:cloth"
translation = [1e5, -1e5, 1e5]
rotation_deg = [10.0, 200.0, -30.0]
scale = 3.0
two_sided = true
[environment]
source = "synth:sky"
[lighting]
level = 2
[camera]
width = 48
height = 48
{SMALL_SYNTH}"#
    );
    let output = run(&text, ".".as_ref()).unwrap();
    assert!(all_finite(&output));
    // Something other than the backdrop was drawn: the cloth is in view despite the offset.
    let centre = output.image.pixels()[24 * 48 + 24];
    assert!(centre[..3].iter().all(|c| *c > 0.0), "{centre:?}");
}

/// Issue #12 (scene values named by key): a scale or translation that puts the geometry
/// beyond `MAX_WORLD_COORDINATE` was refused later as "camera.eye = [inf, inf, inf] once
/// framed"; it is refused by the object's keys when the geometry is placed.
#[test]
fn a_transform_beyond_the_f32_range_is_refused_by_the_objects_keys() {
    for (key, value) in [
        ("scale", "1e30"),
        ("translation", "[1e16, 0.0, 0.0]"),
        ("translation", "[0.0, -3e38, 0.0]"),
    ] {
        let text = format!(
            "[[object]]\nname = \"cloth\"\nsource = \"synth:cloth\"\n{key} = {value}\n{SMALL_SYNTH}"
        );
        let scene = Scene::from_toml(&text, ".".as_ref(), "big.toml").unwrap();
        let message = cloth_vis::inputs::load_geometry(&scene, false)
            .err()
            .unwrap_or_else(|| panic!("{key} = {value} accepted"))
            .to_string();
        assert!(
            message.contains("big.toml")
                && message.contains("object[0] (cloth).scale/translation")
                && message.contains("MAX_WORLD_COORDINATE"),
            "{message}"
        );
    }
    // The bound itself still loads: 1e5 offsets are exercised with a render below.
    let text = format!(
        "[[object]]\nname = \"cloth\"\nsource = \"synth:cloth\"\ntranslation = [1e14, 0.0, 0.0]\n{SMALL_SYNTH}"
    );
    let scene = Scene::from_toml(&text, ".".as_ref(), "big.toml").unwrap();
    assert!(cloth_vis::inputs::load_geometry(&scene, false).is_ok());
}

#[test]
fn frames_outside_the_animation_are_refused_with_the_count() {
    if !gpu_available() {
        return;
    }
    let text = format!(
        "[[object]]\nname = \"cloth\"\nsource = \"synth:cloth\"\nframe = 40\n{SMALL_SYNTH}"
    );
    let err = run(&text, ".".as_ref()).unwrap_err();
    assert!(
        matches!(
            err,
            Error::Frame {
                frame: 40,
                count: 40,
                ..
            }
        ),
        "{err}"
    );
    // Named by the scene and its key, as every other scene value is.
    let message = err.to_string();
    assert!(
        message.contains("scene hard case") && message.contains("object[0] (cloth).frame"),
        "{message}"
    );
    let text = format!(
        "[[object]]\nname = \"cloth\"\nsource = \"synth:cloth\"\nframe = -41\n{SMALL_SYNTH}"
    );
    assert!(matches!(
        run(&text, ".".as_ref()).unwrap_err(),
        Error::Frame { frame: -41, .. }
    ));
}

#[test]
fn bunny_with_unreferenced_vertices_under_a_real_map_renders_finite() {
    let Some(bunny) = test_data::shared_file("meshes/bun_zipper_res2.ply") else {
        return;
    };
    let Some(env) = test_data::shared_file("env/venice_sunset_1k.hdr") else {
        return;
    };
    if !gpu_available() {
        return;
    }
    let text = format!(
        r#"effects = ["lighting"]
[[object]]
name = "bunny"
source = {bunny:?}
[environment]
source = {env:?}
rotation_deg = 120.0
[lighting]
level = 3
[camera]
width = 64
height = 64
"#
    );
    let output = run(&text, ".".as_ref()).unwrap();
    assert!(all_finite(&output));
    let geometry = &output.report.stages[0];
    assert_eq!(geometry.params["bunny"]["vertices"], 8171);
    assert_eq!(
        geometry.params["bunny"]["input"]["unreferenced_vertices"],
        25
    );
    let light = output
        .report
        .stages
        .iter()
        .find(|s| s.stage == "light-directions")
        .unwrap();
    for e in light.params["relative_power_error_rgb"].as_array().unwrap() {
        assert!(e.as_f64().unwrap().abs() < 0.01, "{light:?}");
    }
}

#[test]
fn a_corrupt_mesh_file_fails_with_its_name_and_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = dir.path().join("broken.ply");
    std::fs::write(
        &mesh,
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n1\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    let text =
        "[[object]]\nname = \"broken\"\nsource = \"broken.ply\"\n[camera]\nwidth = 8\nheight = 8\n";
    let scene = Scene::from_toml(text, dir.path(), "hard case").unwrap();
    let Err(err) = run_scene(&scene, &out, &RunOptions::default()) else {
        panic!("a corrupt mesh rendered");
    };
    // Without a GPU the adapter error comes first; with one, the mesh error names the file.
    if !matches!(err, Error::Gpu(_)) {
        assert!(err.to_string().contains("broken.ply"), "{err}");
    }
    // Issue #12: the output folder is created only once the inputs have loaded.
    assert!(!out.exists(), "the failed run created {}", out.display());
}

#[test]
fn a_sky_too_wide_for_any_use_is_refused_by_key_before_any_work() {
    // Issue #12: `sky_width = 16384` with `prefilter_sigma_deg = 90` passed validation and was
    // still running after 60 s at 6.2 GB.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let text = "[[object]]\nname = \"cloth\"\nsource = \"synth:cloth\"\n\
                [environment]\nsource = \"synth:sky\"\nprefilter_sigma_deg = 90\n\
                [synth]\nsky_width = 16384\n";
    let scene = Scene::from_toml(text, dir.path(), "wide.toml").unwrap();
    let message = scene.validate().unwrap_err().to_string();
    assert!(
        message.contains("wide.toml")
            && message.contains("synth.sky_width")
            && message.contains("16384"),
        "{message}"
    );
    let err = run_scene(&scene, &out, &RunOptions::default()).unwrap_err();
    assert!(err.to_string().contains("synth.sky_width"), "{err}");
    assert!(!out.exists(), "the output folder is not created");
}

#[test]
fn sky_values_the_generator_refuses_are_named_by_scene_key_before_any_work() {
    // Issue #12: `sun_elevation_deg = 120` was refused by the generator after work started,
    // named `SkyParams::sun_elevation_deg`.
    let dir = tempfile::tempdir().unwrap();
    for (value, key) in [
        ("sun_elevation_deg = 120.0", "synth.sun_elevation_deg"),
        ("sun_elevation_deg = -5.0", "synth.sun_elevation_deg"),
        ("sun_azimuth_deg = inf", "synth.sun_azimuth_deg"),
    ] {
        let text = format!(
            "[[object]]\nname = \"cloth\"\nsource = \"synth:cloth\"\n\
             [environment]\nsource = \"synth:sky\"\n[synth]\n{value}\n"
        );
        let scene = Scene::from_toml(&text, dir.path(), "sky.toml").unwrap();
        let message = scene.validate().unwrap_err().to_string();
        assert!(
            message.contains("sky.toml") && message.contains(key),
            "{value}: {message}"
        );
        assert!(
            !message.contains("SkyParams") && !message.contains("::"),
            "named by the scene key only, not the library's field: {message}"
        );
    }
}

#[cfg(unix)]
#[test]
fn a_scene_file_that_is_a_fifo_is_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("scene.toml");
    test_data::make_fifo(&fifo);
    let message = Scene::load(&fifo).unwrap_err().to_string();
    assert!(
        message.contains("scene.toml") && message.contains("FIFO"),
        "{message}"
    );
}

/// Issue #12: "a degenerate camera renders blank with exit 0; huge but finite radiance renders
/// black with exit 0". A camera looking away from the objects is refused before any stage, by
/// its keys; one whose view holds the objects' bounding sphere but no triangle (two specks far
/// apart, the camera between them) is refused on the rendered coverage; objects that render
/// all black (albedo 0) are refused; an environment brighter than `MAX_RADIANCE` is refused
/// when it loads. No output folder is left by any of them.
#[test]
fn blank_black_and_blinding_renders_are_refused_with_no_output() {
    if !gpu_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let speck = |x: f32| format!("v {x} 0 0\nv {} 0 0\nv {x} 0.01 0\nf 1 2 3\n", x + 0.01);
    std::fs::write(dir.path().join("left.obj"), speck(-10.0)).unwrap();
    std::fs::write(dir.path().join("right.obj"), speck(10.0)).unwrap();
    // RGBE exponent 255: 6.6e35 per channel, finite.
    let mut hdr = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 4\n".to_vec();
    hdr.extend([255u8; 32]);
    std::fs::write(dir.path().join("blinding.hdr"), hdr).unwrap();
    let cloth = "[[object]]\nname = \"cloth\"\nsource = \"synth:cloth\"\nframe = -1\n";
    let specks = "[[object]]\nname = \"l\"\nsource = \"left.obj\"\n\
                  [[object]]\nname = \"r\"\nsource = \"right.obj\"\n";
    let lit = "[environment]\nsource = \"synth:sky\"\n[lighting]\nlevel = 1\n";
    let blinding = "[environment]\nsource = \"blinding.hdr\"\n[lighting]\nlevel = 1\n";
    let ball = "[[object]]\nname = \"ball\"\nsource = \"synth:cloth-obstacle\"\n";
    // (name, objects and environment, camera keys, what the error names)
    let cases: [(&str, String, &str, &[&str]); 5] = [
        (
            "away",
            cloth.to_owned(),
            "eye = [0.0, 0.0, 50.0]\ntarget = [0.0, 0.0, 100.0]\n",
            &["camera.eye", "camera.target", "no object is in view"],
        ),
        (
            // Below the ball's centre, looking up at it with the default up vector: a camera
            // that only exists once framed, refused by its key before any stage.
            "below",
            ball.to_owned(),
            "eye = [0.0, 0.0, 0.0]\n",
            &["camera.up", "once framed on the objects"],
        ),
        (
            "between",
            specks.to_owned(),
            "eye = [0.0, 0.0, 5.0]\ntarget = [0.0, 0.0, 0.0]\nfov_deg = 5.0\n",
            &["no object covers a pixel", "camera.eye"],
        ),
        (
            "black",
            format!("effects = [\"lighting\"]\n{cloth}albedo = [0.0, 0.0, 0.0]\n{lit}"),
            "",
            &["object pixels are black", "albedo 0"],
        ),
        (
            "blinding",
            format!("effects = [\"lighting\"]\n{cloth}{blinding}"),
            "",
            &["blinding.hdr", "MAX_RADIANCE"],
        ),
    ];
    for (name, body, camera, needles) in cases {
        let text =
            format!("{body}[output]\npng = \"a.png\"\n[camera]\nwidth = 48\nheight = 32\n{camera}");
        let scene = Scene::from_toml(&text, dir.path(), &format!("{name}.toml")).unwrap();
        let out = dir.path().join(format!("out-{name}"));
        let err = run_scene(&scene, &out, &RunOptions::default())
            .err()
            .unwrap_or_else(|| panic!("{name}: rendered without an error"));
        let message = err.to_string();
        for n in needles {
            assert!(message.contains(n), "{name}: {message:?} lacks {n:?}");
        }
        assert!(
            !out.exists(),
            "{name}: the failed run left {}",
            out.display()
        );
    }
}
