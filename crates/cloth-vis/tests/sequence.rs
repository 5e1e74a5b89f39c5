//! The shared frame through the facade: image sequences of a deforming cloth with per-frame
//! visibility (pipelines built once, buffers rewritten in place, per-stage times per frame),
//! the background keywords (black stays black under an environment, transparent writes the
//! coverage matte), the ground receiving the cloth's shadow, and refused frame ranges.

mod common;

use cloth_vis::{RunOptions, run_scene};
use render::sequence::FrameRange;

const SCENE: &str = r#"
effects = ["lighting", "self-shadowing"]

[[object]]
name = "cloth"
source = "synth:cloth"
frame = -1
two_sided = true

[[object]]
name = "ball"
source = "synth:cloth-obstacle"

[ground]
cells = 24

[environment]
source = "synth:sky"

[lighting]
level = 1

[camera]
width = 96
height = 80

[synth]
cloth_grid = 16
cloth_frames = 12
seed = 3
sky_width = 128
"#;

fn with_output(extra: &str) -> cloth_vis::Scene {
    common::scene(
        &format!("{SCENE}\n[output]\n{extra}\n"),
        std::path::Path::new("."),
    )
}

#[test]
fn a_sequence_writes_numbered_frames_and_builds_pipelines_once() {
    if !common::gpu_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let run = |range: &str, out: &str| {
        let options = RunOptions {
            frames: Some(range.parse::<FrameRange>().unwrap()),
            ..RunOptions::default()
        };
        run_scene(&with_output(""), &dir.path().join(out), &options).unwrap()
    };
    let one = run("11..12", "one");
    let four = run("8..12", "four");
    // The renderer is built once per run: four frames build exactly what one frame builds.
    assert_eq!(four.pipelines_built, one.pipelines_built);
    assert!(one.pipelines_built >= 2, "gouraud + backdrop at least");
    for f in 8..12 {
        let path = dir.path().join(format!("four/frame-{f:04}.png"));
        let img = image::open(&path).unwrap().to_rgba8();
        assert_eq!(img.dimensions(), (96, 80), "{}", path.display());
    }
    assert!(!dir.path().join("four/frame-0007.png").exists());
    assert!(
        !dir.path().join("four/render.png").exists(),
        "a sequence writes no still"
    );
    // Per-stage times per frame in the report, visibility recomputed every frame.
    let json: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("four/run-report.json")).unwrap(),
    )
    .unwrap();
    let stage = |name: &str| {
        json["stages"]
            .as_array()
            .unwrap()
            .iter()
            .rev()
            .find(|s| s["stage"] == name)
            .unwrap_or_else(|| panic!("no {name} stage in {json}"))
            .clone()
    };
    for name in ["visibility", "lighting", "render"] {
        let s = stage(name);
        assert_eq!(s["params"]["frames"], 4, "{name}: {s}");
        let (mean, max) = (
            s["params"]["mean_ms_per_frame"].as_f64().unwrap(),
            s["params"]["max_ms_per_frame"].as_f64().unwrap(),
        );
        assert!(mean > 0.0 && max >= mean, "{name}: mean {mean} max {max}");
    }
    // Cloth, ball, ground: allocated once each, then rewritten in place.
    assert_eq!(stage("render")["params"]["gpu_mesh_allocations"], 3);
    // The cloth moves between frames, so the frames differ.
    let a = image::open(dir.path().join("four/frame-0008.png"))
        .unwrap()
        .to_rgba8();
    let b = image::open(dir.path().join("four/frame-0011.png"))
        .unwrap()
        .to_rgba8();
    assert_ne!(a.as_raw(), b.as_raw());
}

#[test]
fn black_stays_black_under_an_environment_and_transparent_writes_the_matte() {
    if !common::gpu_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let black = run_scene(
        &with_output("background = \"black\""),
        &dir.path().join("black"),
        &RunOptions::default(),
    )
    .unwrap();
    // The corner shows no object: exactly black, although the sky was loaded for lighting.
    assert_eq!(black.image.pixels()[0], [0.0; 4]);
    let png = image::open(dir.path().join("black/render.png"))
        .unwrap()
        .to_rgba8();
    assert_eq!(png.get_pixel(0, 0).0, [0, 0, 0, 255]);

    run_scene(
        &with_output("background = \"transparent\""),
        &dir.path().join("clear"),
        &RunOptions::default(),
    )
    .unwrap();
    let png = image::open(dir.path().join("clear/render.png"))
        .unwrap()
        .to_rgba8();
    assert_eq!(png.get_pixel(0, 0).0[3], 0, "background is transparent");
    assert_eq!(png.get_pixel(48, 40).0[3], 255, "the cloth is opaque");
    let alphas: std::collections::BTreeSet<u8> = png.pixels().map(|p| p.0[3]).collect();
    assert!(alphas.len() >= 2);
    // The EXR carries the same matte (premultiplied radiance).
    let exr = exr::prelude::read_first_rgba_layer_from_file(
        dir.path().join("clear/render.exr"),
        |res, _| vec![[0.0f32; 4]; res.width() * res.height()],
        |buf: &mut Vec<[f32; 4]>, pos, (r, g, b, a): (f32, f32, f32, f32)| {
            buf[pos.y() * 96 + pos.x()] = [r, g, b, a];
        },
    )
    .unwrap();
    let px = &exr.layer_data.channel_data.pixels;
    assert_eq!(px[0], [0.0; 4]);
    assert_eq!(px[40 * 96 + 48][3], 1.0);

    let coloured = run_scene(
        &with_output("background = [0.0, 0.5, 2.0]"),
        &dir.path().join("blue"),
        &RunOptions::default(),
    )
    .unwrap();
    assert_eq!(coloured.image.pixels()[0], [0.0, 0.5, 2.0, 0.0]);
}

#[test]
fn the_ground_is_darker_under_the_cloth_than_in_the_open() {
    let Some(gpu) = gpu_context::testing::gpu_or_skip() else {
        return;
    };
    // The cloth draped over the ball, and the ground grid under it, lit by the sky through
    // the visibility engine: the ground is a receiver like any object.
    let anim = synth::simulate_cloth(&synth::ClothParams {
        grid: 16,
        frames: 12,
        ..Default::default()
    })
    .unwrap();
    let object = |name: &str, positions: Vec<glam::Vec3>, triangles: Vec<[u32; 3]>| {
        let normals =
            meshio::compute_normals(&positions, &triangles, meshio::NormalWeighting::Angle);
        cloth_vis::object::WorldObject {
            name: name.to_owned(),
            positions,
            normals,
            triangles,
            uvs: None,
            albedo: glam::Vec3::ONE,
            two_sided: false,
            front: None,
            back: None,
            animation: None,
        }
    };
    let cloth = object("cloth", anim.frames[11].clone(), anim.triangles.clone());
    let (centre, _) = render::bounding_sphere(&cloth.positions).unwrap();
    let (p, t, _) = render::ground::ground_grid(centre, 0.0, 4.0, 8);
    let mut objects = vec![cloth, object("ground", p, t)];
    let scene = with_output("");
    let sphere = lightsphere::Lightsphere::new(2).unwrap();
    let sky = synth::sky(&synth::SkyParams {
        width: 128,
        height: 64,
        ..Default::default()
    })
    .unwrap();
    let env = lightsphere::Environment::from_latlong(sky.width, sky.height, sky.texels).unwrap();
    let radiance = env
        .radiance_per_direction(&sphere, lightsphere::RadianceMethod::CellMean)
        .unwrap();
    let (vis, _) = cloth_vis::shadowing::visibility(&scene, &gpu, &objects, &sphere).unwrap();
    cloth_vis::shadowing::light_objects(&mut objects, &sphere, &radiance, Some(&vis)).unwrap();
    let ground = objects[1].front.as_ref().unwrap();
    // 9 × 9 vertices: 40 is the centre (under the cloth), 0/8/72/80 the open corners.
    let lum = |c: glam::Vec3| c.dot(glam::Vec3::new(0.2126, 0.7152, 0.0722));
    let under = lum(ground[40]);
    let open = [0, 8, 72, 80].map(|i| lum(ground[i]));
    // Under the dome the sky still reaches the centre between the corners that touch the
    // floor; the cloth takes away a clear share of it (0.60 of the least lit corner when
    // measured; without visibility the two would be equal, all normals being +Y).
    for o in open {
        assert!(
            under < 0.75 * o,
            "under the cloth {under} vs open corners {open:?}"
        );
    }
}

#[test]
fn bad_frame_ranges_are_refused_naming_the_key() {
    let dir = tempfile::tempdir().unwrap();
    for (extra, needle) in [
        ("frames = \"5..3\"", "output.frames"),
        ("frames = \"0..x\"", "output.frames"),
    ] {
        let err = run_scene(&with_output(extra), dir.path(), &RunOptions::default()).unwrap_err();
        assert!(err.to_string().contains(needle), "{extra}: {err}");
    }
    if !common::gpu_available() {
        return;
    }
    let options = RunOptions {
        frames: Some("0..13".parse().unwrap()),
        ..RunOptions::default()
    };
    let err = run_scene(&with_output(""), dir.path(), &options).unwrap_err();
    assert!(err.to_string().contains("12 frames"), "{err}");
    // A scene with no animated object cannot render a sequence.
    let still = common::scene(
        "[[object]]\nname = \"ball\"\nsource = \"synth:cloth-obstacle\"\n[output]\nframes = \"0..2\"\n",
        std::path::Path::new("."),
    );
    let err = run_scene(&still, dir.path(), &RunOptions::default()).unwrap_err();
    assert!(err.to_string().contains("no object is animated"), "{err}");
}

/// The btf effect follows a sequence: btf-NNNN.png per frame, the garment lit by the scene's
/// environment through that frame's own visibility, and the stage timed per frame.
#[test]
fn the_btf_stage_follows_a_sequence_under_the_environment() {
    if !common::gpu_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let text = SCENE.replace(
        "effects = [\"lighting\", \"self-shadowing\"]",
        "effects = [\"btf\"]",
    ) + "\n[btf]\nres = 8\nillumination = \"environment\"\nlevel = 1\nobjects = [\"cloth\"]\n";
    let scene = common::scene(&text, std::path::Path::new("."));
    let options = RunOptions {
        frames: Some("2..5".parse::<FrameRange>().unwrap()),
        ..RunOptions::default()
    };
    let output = run_scene(&scene, dir.path(), &options).unwrap();
    let frames: Vec<_> = (2..5)
        .map(|f| {
            image::open(dir.path().join(format!("btf-{f:04}.png")))
                .unwrap()
                .to_rgb8()
        })
        .collect();
    assert_eq!(frames[0].dimensions(), (2 * 96, 80));
    assert_ne!(
        frames[0], frames[2],
        "the cloth falls between frames 2 and 4"
    );
    assert!(
        !dir.path().join("btf.png").exists(),
        "no still beside the sequence"
    );
    let stage = output
        .report
        .stages
        .iter()
        .find(|s| s.stage == "btf")
        .expect("a btf stage record");
    assert_eq!(stage.params["frames"], 3, "{:?}", stage.params);
    assert_eq!(
        stage.params["illumination"]["visibility"],
        "M at lightsphere level 1"
    );
}
