//! End-to-end runs on the GPU (lavapipe in CI): the demo scene writes a non-constant PNG and EXR
//! and a run report listing exactly the planned stages.

mod common;

use cloth_vis::{Plan, RunOptions, Scene, demo_scene, run_scene};
use common::{SMALL_SYNTH, gpu_available};

fn small_demo() -> Scene {
    // The embedded demo with small procedural inputs and image, so the test stays quick.
    let mut scene = demo_scene().unwrap();
    scene.synth.cloth_grid = Some(24);
    scene.synth.cloth_frames = Some(40);
    scene.synth.sky_width = Some(256);
    scene.camera.width = 160;
    scene.camera.height = 128;
    scene
}

/// The cloth of the small demo alone on black at a fixed exposure with only the btf effect.
fn btf_only_cloth() -> Scene {
    let mut scene = small_demo();
    scene.objects.retain(|o| o.name == "cloth");
    scene.ground = None;
    scene.output.background = cloth_vis::scene::BackgroundDesc::BLACK;
    scene.output.exposure = cloth_vis::scene::ExposureDesc::Fixed(0.0);
    scene.effects = vec!["btf".to_owned()];
    scene
}

/// Runs `scene`; its btf.png and the btf stage's report record.
fn run_btf(scene: &Scene) -> (image::RgbImage, serde_json::Value) {
    let dir = tempfile::tempdir().unwrap();
    run_scene(scene, dir.path(), &RunOptions::default()).unwrap();
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("run-report.json")).unwrap())
            .unwrap();
    let stage = json["stages"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["stage"] == "btf")
        .unwrap()
        .clone();
    (
        image::open(dir.path().join("btf.png")).unwrap().to_rgb8(),
        stage,
    )
}

#[test]
fn demo_writes_non_constant_png_exr_and_a_report_of_the_planned_stages() {
    if !gpu_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    // The cloth alone on black, so that btf.png's non-black pixels are the cloth's.
    let mut scene = small_demo();
    scene.objects.retain(|o| o.name == "cloth");
    scene.ground = None;
    scene.output.background = cloth_vis::scene::BackgroundDesc::BLACK;
    let output = run_scene(&scene, dir.path(), &RunOptions::default()).unwrap();
    let plan = Plan::for_scene(&scene).unwrap();
    let ran: Vec<&str> = output
        .report
        .stages
        .iter()
        .map(|s| s.stage.as_str())
        .collect();
    let planned: Vec<&str> = plan.stages().iter().map(|s| s.name()).collect();
    assert_eq!(ran, planned);

    let png = image::open(dir.path().join("demo.png")).unwrap().to_rgb8();
    assert_eq!(png.dimensions(), (160, 128));
    let first = *png.get_pixel(0, 0);
    assert!(png.pixels().any(|p| *p != first), "PNG is constant");
    let distinct: std::collections::HashSet<_> = png.pixels().map(|p| p.0).collect();
    assert!(
        distinct.len() > 50,
        "only {} distinct colours",
        distinct.len()
    );

    // EXR: linear radiance, finite, non-negative, not constant.
    // (MSAA shades partly covered pixels at the centroid: no extrapolated, negative colour.)
    let exr = output.image.pixels();
    if let Some((i, p)) = exr
        .iter()
        .enumerate()
        .find(|(_, p)| !p.iter().all(|c| c.is_finite() && *c >= 0.0))
    {
        panic!("pixel {i} = {p:?} is negative or not finite");
    }
    assert!(exr.iter().any(|p| p != &exr[0]));
    assert!(dir.path().join("demo.exr").metadata().unwrap().len() > 1000);

    // btf.png: the cloth with the woven BTF (left) beside plain texturing (right), same
    // camera, same coverage, different appearance (view-dependent, shadowed mesostructure).
    let btf = image::open(dir.path().join("btf.png")).unwrap().to_rgb8();
    assert_eq!(btf.dimensions(), (2 * 160, 128));
    let (mut covered, mut differ, mut coverage_mismatch) = (0usize, 0usize, 0usize);
    for y in 0..128 {
        for x in 0..160 {
            let (l, r) = (btf.get_pixel(x, y).0, btf.get_pixel(x + 160, y).0);
            let (lb, rb) = (l != [0, 0, 0], r != [0, 0, 0]);
            if lb != rb {
                coverage_mismatch += 1;
            }
            if lb && rb {
                covered += 1;
                if l.iter().zip(&r).any(|(a, b)| a.abs_diff(*b) > 8) {
                    differ += 1;
                }
            }
        }
    }
    assert!(covered > 1000, "the cloth covers only {covered} pixels");
    assert!(
        differ * 4 > covered,
        "BTF and plain texture differ on only {differ} of {covered}"
    );
    assert!(
        coverage_mismatch * 20 < covered,
        "{coverage_mismatch} pixels lit on one side only"
    );

    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("run-report.json")).unwrap())
            .unwrap();
    assert_eq!(
        json["effects"],
        serde_json::json!(["lighting", "self-shadowing", "btf", "shadow-volumes"])
    );
    let vis = json["stages"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["stage"] == "visibility")
        .unwrap();
    // A draped cloth shadows itself: some but not all (vertex, direction) pairs are visible.
    let share = vis["params"]["visible_share"].as_f64().unwrap();
    assert!(share > 0.05 && share < 0.5, "{vis}");
    assert_eq!(json["stages"].as_array().unwrap().len(), planned.len());
    // Cell-mean I_j preserves the sky's power (lightsphere's guarantee, seen through the facade).
    let light = json["stages"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["stage"] == "light-directions")
        .unwrap();
    for e in light["params"]["relative_power_error_rgb"]
        .as_array()
        .unwrap()
    {
        assert!(e.as_f64().unwrap().abs() < 1e-6, "{light}");
    }
    let table = std::fs::read_to_string(dir.path().join("run-report.txt")).unwrap();
    assert!(
        table.contains("light-directions") && table.contains("total"),
        "{table}"
    );
}

#[test]
fn fins_from_the_scene_fringe_the_btf_half_only() {
    if !gpu_available() {
        return;
    }
    let run = |fins: bool| {
        // One exposure for both runs: fins add light to the pixels automatic exposure reads.
        let mut scene = btf_only_cloth();
        if fins {
            scene.btf.fins = Some(cloth_vis::scene::FinsDesc {
                source: "synth:wool".to_owned(),
                height: None,
                size: None,
            });
        }
        run_btf(&scene)
    };
    let (plain, _) = run(false);
    let (fringed, stage) = run(true);
    assert!(
        stage["params"]["fins"]["fins"].as_u64().unwrap() > 10,
        "{stage}"
    );
    let (w, h) = (160, 128);
    let changed = |x0: u32| {
        (0..h)
            .flat_map(|y| (x0..x0 + w).map(move |x| (x, y)))
            .filter(|&(x, y)| plain.get_pixel(x, y) != fringed.get_pixel(x, y))
            .count()
    };
    assert!(changed(0) > 50, "fins changed only {} pixels", changed(0));
    assert_eq!(changed(w), 0, "the plain-texture half carries no fins");
}

#[test]
fn a_run_without_lighting_reports_no_lighting_stage() {
    if !gpu_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let text = format!(
        "[[object]]\nname = \"cloth\"\nsource = \"synth:cloth\"\n[camera]\nwidth = 64\nheight = 64\n{SMALL_SYNTH}"
    );
    let scene = Scene::from_toml(&text, ".".as_ref(), "no lighting").unwrap();
    let output = run_scene(&scene, dir.path(), &RunOptions::default()).unwrap();
    let ran: Vec<&str> = output
        .report
        .stages
        .iter()
        .map(|s| s.stage.as_str())
        .collect();
    assert_eq!(ran, ["geometry", "render"]);
    assert!(dir.path().join("render.png").exists());
}

#[test]
fn the_embedded_demo_scene_is_valid() {
    let scene = demo_scene().unwrap();
    let plan = Plan::for_scene(&scene).unwrap();
    assert!(plan.contains(cloth_vis::Stage::Lighting));
    assert!(scene.camera.width >= 512 && scene.camera.height >= 512);
}

#[test]
fn a_scene_lights_the_btf_by_its_environment_and_maps_agree_with_m() {
    if !gpu_available() {
        return;
    }
    use cloth_vis::scene::BtfIllumination;
    let run = |illumination: BtfIllumination, maps: Option<u32>| {
        let mut scene = btf_only_cloth();
        scene.btf.illumination = illumination;
        scene.btf.maps = maps;
        run_btf(&scene)
    };
    let (light, _) = run(BtfIllumination::Light, None);
    let (by_m, stage) = run(BtfIllumination::Environment, None);
    let (by_maps, stage_maps) = run(BtfIllumination::Environment, Some(16));
    let ill = &stage["params"]["illumination"];
    assert_eq!(ill["visibility"], "M at lightsphere level 3", "{stage}");
    assert!(
        ill["objects"][0]["vertices"].as_u64().unwrap() > 500,
        "{stage}"
    );
    assert!(
        stage_maps["params"]["illumination"]["visibility"]
            .as_str()
            .unwrap()
            .contains("16x16"),
        "{stage_maps}"
    );
    // Over the cloth's pixels (the BTF half): the environment is not the directional light,
    // and the two visibilities light it alike (mean within 4/255 on 8-bit sRGB; 1.7 measured).
    let cloth: Vec<(u32, u32)> = (0..128)
        .flat_map(|y| (0..160).map(move |x| (x, y)))
        .filter(|&(x, y)| by_m.get_pixel(x, y).0 != [0, 0, 0])
        .collect();
    assert!(cloth.len() > 1000, "{} cloth pixels", cloth.len());
    let mean_diff = |a: &image::RgbImage, b: &image::RgbImage| {
        cloth
            .iter()
            .map(|&(x, y)| {
                let (p, q) = (a.get_pixel(x, y).0, b.get_pixel(x, y).0);
                (0..3).map(|c| f64::from(p[c].abs_diff(q[c]))).sum::<f64>() / 3.0
            })
            .sum::<f64>()
            / cloth.len() as f64
    };
    let to_light = mean_diff(&by_m, &light);
    let to_maps = mean_diff(&by_m, &by_maps);
    eprintln!("mean |M − light| {to_light:.2}, |M − maps| {to_maps:.2} (8-bit)");
    assert!(to_light > 10.0, "{to_light}");
    assert!(to_maps < 4.0, "{to_maps}");
}

/// `[btf] parts` (garment parts, §5.6): the faces of an OBJ's `usemtl right` wear their own BTF
/// in both halves, the rest of the sheet is pixel for pixel the single-material render, and a
/// part no object has is named.
#[test]
fn scene_parts_dress_each_face_material_in_its_own_btf() {
    if !gpu_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("sheet.obj"), common::two_part_sheet(12)).unwrap();
    cloth_vis::btf_stage::synth_material(8, 1)
        .unwrap()
        .write(&dir.path().join("flat.btfpca"))
        .unwrap();
    let text = |parts: &str| {
        format!(
            "effects = [\"btf\"]\n[[object]]\nname = \"sheet\"\nsource = \"sheet.obj\"\n\
             [camera]\nwidth = 64\nheight = 64\ndirection = [0.0, 0.0, 1.0]\n\
             [output]\nbackground = \"black\"\nexposure = 0.0\n\
             [btf]\nres = 8\nlight_dir = [0.3, 0.4, 0.9]\n{parts}\n"
        )
    };
    let run = |parts: &str, out: &str| {
        let scene = Scene::from_toml(&text(parts), dir.path(), "parts").unwrap();
        let out = dir.path().join(out);
        run_scene(&scene, &out, &RunOptions::default())
            .map(|_| image::open(out.join("btf.png")).unwrap().to_rgb8())
    };
    let one = run("", "one").unwrap();
    let two = run("parts = { right = \"flat.btfpca\" }", "two").unwrap();
    // Each half of btf.png (BTF | plain) is 64 wide; the sheet's left material is x < 32.
    let (mut left, mut right) = (0, 0);
    for half in [0u32, 64] {
        for y in 12..52 {
            for x in 8..26 {
                left += usize::from(one.get_pixel(half + x, y) != two.get_pixel(half + x, y));
            }
            for x in 38..56 {
                right += usize::from(one.get_pixel(half + x, y) != two.get_pixel(half + x, y));
            }
        }
    }
    assert_eq!(left, 0, "the left material kept [btf] source");
    assert!(right > 300, "only {right} pixels of the right part changed");
    let err = run("parts = { sleeve = \"flat.btfpca\" }", "three")
        .unwrap_err()
        .to_string();
    assert!(err.contains("btf.parts.sleeve"), "{err}");
    let bad = Scene::from_toml(
        &text("parts = { right = \"none.btfpca\" }"),
        dir.path(),
        "p",
    )
    .map_err(|e| e.to_string())
    .and_then(|s| Plan::for_scene(&s).map(|_| ()).map_err(|e| e.to_string()))
    .unwrap_err();
    assert!(bad.contains("btf.parts.right"), "{bad}");
}
