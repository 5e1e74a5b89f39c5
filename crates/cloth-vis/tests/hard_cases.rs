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
