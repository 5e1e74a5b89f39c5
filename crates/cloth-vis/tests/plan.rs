//! The effect graph: a scene never builds the stages of effects it does not ask for, and every
//! problem that needs no work is reported before any work starts.

mod common;

use cloth_vis::{Plan, RunOptions, Scene, Stage, demo_scene, run_scene};
use common::scene;

const CLOTH: &str = r#"
[[object]]
name = "cloth"
source = "synth:cloth"
"#;

#[test]
fn a_scene_without_lighting_never_builds_lighting_stages() {
    let s = scene(CLOTH, ".".as_ref());
    let plan = Plan::for_scene(&s).unwrap();
    assert_eq!(plan.stages(), &[Stage::Geometry, Stage::Render]);
    assert!(plan.effects().is_empty());
    // An environment used only as backdrop loads the map but still builds no lighting stage.
    let with_env = format!("{CLOTH}\n[environment]\nsource = \"synth:sky\"\n");
    let plan = Plan::for_scene(&scene(&with_env, ".".as_ref())).unwrap();
    assert_eq!(
        plan.stages(),
        &[Stage::Geometry, Stage::Environment, Stage::Render]
    );
    let black = format!("{with_env}\n[output]\nbackground = \"black\"\n");
    let plan = Plan::for_scene(&scene(&black, ".".as_ref())).unwrap();
    assert_eq!(plan.stages(), &[Stage::Geometry, Stage::Render]);
}

#[test]
fn the_demo_scene_plans_lighting() {
    let plan = Plan::for_scene(&demo_scene().unwrap()).unwrap();
    assert_eq!(
        plan.stages(),
        &[
            Stage::Geometry,
            Stage::Environment,
            Stage::LightDirections,
            Stage::Visibility,
            Stage::Lighting,
            Stage::ShadowVolumes,
            Stage::Render,
            Stage::Btf
        ]
    );
}

#[test]
fn btf_alone_plans_its_stage_and_no_lighting() {
    let plan = Plan::for_scene(&scene(
        &format!("effects = [\"btf\"]\n{CLOTH}"),
        ".".as_ref(),
    ))
    .unwrap();
    assert_eq!(plan.stages(), &[Stage::Geometry, Stage::Render, Stage::Btf]);
    // Under environment light the map is loaded even on a black background.
    let text = format!(
        "effects = [\"btf\"]\n{CLOTH}\n[environment]\nsource = \"synth:sky\"\n\
         [output]\nbackground = \"black\"\n[btf]\nillumination = \"environment\"\n"
    );
    let plan = Plan::for_scene(&scene(&text, ".".as_ref())).unwrap();
    assert_eq!(
        plan.stages(),
        &[
            Stage::Geometry,
            Stage::Environment,
            Stage::Render,
            Stage::Btf
        ]
    );
}

#[test]
fn bad_btf_tables_are_named_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    for (table, key) in [
        ("source = \"missing.btfpca\"", "btf.source"),
        ("source = \"synth:silk\"", "btf.source"),
        ("objects = [\"shirt\"]", "btf.objects"),
        ("res = 0", "btf.res"),
        ("components = 0", "btf.components"),
        ("light_dir = [0.0, 0.0, 0.0]", "btf.light_dir"),
        ("uv_scale = -1.0", "btf.uv_scale"),
        ("png = \"../escape.png\"", "btf.png"),
        ("fins = { source = \"missing.finpca\" }", "btf.fins.source"),
        (
            "fins = { source = \"synth:wool\", height = 0.0 }",
            "btf.fins.height",
        ),
        (
            "fins = { source = \"synth:wool\", size = nan }",
            "btf.fins.size",
        ),
    ] {
        let text = format!("effects = [\"btf\"]\n{CLOTH}\n[btf]\n{table}\n");
        let err = Plan::for_scene(&scene(&text, dir.path()))
            .unwrap_err()
            .to_string();
        assert!(err.contains(key), "{table}: {err}");
    }
    // Environment light needs an environment; fins stay with the directional light.
    let env = "[environment]\nsource = \"synth:sky\"\n";
    for (table, with_env, key) in [
        ("illumination = \"environment\"", "", "btf.illumination"),
        ("illumination = \"sunlight\"", env, "illumination"),
        (
            "illumination = \"environment\"\nfins = { source = \"synth:wool\" }",
            env,
            "btf.fins",
        ),
        (
            "illumination = \"environment\"\nlevel = 9",
            env,
            "btf.level",
        ),
        ("illumination = \"environment\"\nmaps = 7", env, "btf.maps"),
        (
            "illumination = \"environment\"\nmaps = 4096",
            env,
            "btf.maps",
        ),
    ] {
        let text = format!("effects = [\"btf\"]\n{CLOTH}\n{with_env}\n[btf]\n{table}\n");
        let err = match Scene::from_toml(&text, dir.path(), "t") {
            Err(e) => e.to_string(),
            Ok(s) => Plan::for_scene(&s).unwrap_err().to_string(),
        };
        assert!(err.contains(key), "{table}: {err}");
    }
    // Without the effect, the table is not checked (nothing of it runs).
    let text = format!("{CLOTH}\n[btf]\nres = 0\n");
    assert!(Plan::for_scene(&scene(&text, dir.path())).is_ok());
}

#[test]
fn translucency_without_a_light_is_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let text = format!("effects = [\"translucency\"]\n{CLOTH}\n");
    let err = run_scene(&scene(&text, dir.path()), &out, &RunOptions::default()).unwrap_err();
    assert!(err.to_string().contains("translucency.light"), "{err}");
    assert!(
        !out.exists(),
        "no output folder may be created before validation passes"
    );
    // An environment light needs the scene's lighting.
    let text = format!(
        "effects = [\"translucency\"]\n{CLOTH}\n[translucency]\nlight = {{ environment = true }}\n"
    );
    let err = Plan::for_scene(&scene(&text, dir.path())).unwrap_err();
    assert!(err.to_string().contains("self-shadowing"), "{err}");
    let text = format!(
        "effects = [\"translucency\"]\n{CLOTH}\n[translucency]\nmaterial = \"jade\"\nlight = {{ direction = [0, 1, 0] }}\n"
    );
    let err = Plan::for_scene(&scene(&text, dir.path())).unwrap_err();
    assert!(
        err.to_string().contains("translucency.material") && err.to_string().contains("jade"),
        "{err}"
    );
    // A finite light beyond the world's bound is refused with the bound, not as "not finite".
    for light in ["position = [1e30, 0, 0]", "direction = [0, 0, 0]"] {
        let text = format!(
            "effects = [\"translucency\"]\n{CLOTH}\n[translucency]\nlight = {{ {light} }}\n"
        );
        let err = Plan::for_scene(&scene(&text, dir.path()))
            .unwrap_err()
            .to_string();
        let key = light.split(' ').next().unwrap();
        assert!(
            err.contains(&format!("translucency.light.{key}")) && err.contains("1e15"),
            "{light}: {err}"
        );
        assert_eq!(
            err.contains("non-zero"),
            key == "direction",
            "{light}: {err}"
        );
    }
}

#[test]
fn self_shadowing_plans_visibility_but_lighting_alone_does_not() {
    let sky = "[environment]\nsource = \"synth:sky\"\n";
    let lit = Plan::for_scene(&scene(
        &format!("effects = [\"lighting\"]\n{CLOTH}{sky}"),
        ".".as_ref(),
    ))
    .unwrap();
    assert!(lit.contains(Stage::Lighting) && !lit.contains(Stage::Visibility));
    let shadowed = Plan::for_scene(&scene(
        &format!("effects = [\"self-shadowing\"]\n{CLOTH}{sky}"),
        ".".as_ref(),
    ))
    .unwrap();
    assert!(shadowed.contains(Stage::Visibility) && shadowed.contains(Stage::Lighting));
}

#[test]
fn unknown_effects_list_the_known_ones() {
    let text = format!("effects = [\"ambient-occlusion\"]\n{CLOTH}");
    let err = Plan::for_scene(&scene(&text, ".".as_ref()))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("\"ambient-occlusion\"")
            && err.contains("self-shadowing")
            && err.contains("lighting"),
        "{err}"
    );
}

#[test]
fn missing_files_are_named_with_their_key() {
    let dir = tempfile::tempdir().unwrap();
    let text = "[[object]]\nname = \"bunny\"\nsource = \"no/such/bunny.ply\"\n";
    let err = Plan::for_scene(&scene(text, dir.path()))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("object[0] (bunny).source") && err.contains("no/such/bunny.ply"),
        "{err}"
    );
    let text = format!("{CLOTH}\n[environment]\nsource = \"sky.hdr\"\n");
    let err = Plan::for_scene(&scene(&text, dir.path()))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("environment.source") && err.contains("sky.hdr"),
        "{err}"
    );
}

#[test]
fn lighting_without_an_environment_is_refused() {
    let text = format!("effects = [\"lighting\"]\n{CLOTH}");
    let err = Plan::for_scene(&scene(&text, ".".as_ref()))
        .unwrap_err()
        .to_string();
    assert!(err.contains("[environment]"), "{err}");
}

#[test]
fn typos_and_bad_values_are_reported_with_location() {
    let err = cloth_vis::Scene::from_toml(
        "[[object]]\nname = \"a\"\nsourse = \"x\"\n",
        ".".as_ref(),
        "typo.toml",
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("typo.toml") && err.contains("sourse"), "{err}");
    let err = cloth_vis::Scene::from_toml(
        "[[object]]\nname = \"a\"\nsource = \"synth:cloth\"\n[output]\nbackground = \"pink\"\n",
        ".".as_ref(),
        "pink.toml",
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.contains("pink.toml") && err.contains("\"pink\"") && err.contains("transparent"),
        "{err}"
    );
    for (extra, key) in [
        ("[lighting]\nlevel = 9\n", "lighting.level"),
        ("[camera]\nwidth = 0\n", "camera.width"),
        ("[camera]\nfov_deg = 180.0\n", "camera.fov_deg"),
        ("[output]\nexposure = 100.0\n", "output.exposure"),
        (
            "[output]\nbackground = [0.0, -1.0, 0.0]\n",
            "output.background",
        ),
        ("[output]\nframes = \"3..1\"\n", "output.frames"),
        ("[ground]\ncells = 0\n", "ground.cells"),
        ("[ground]\nsize = -2.0\n", "ground.size"),
        ("[output]\npng = \"../escape.png\"\n", "output.png"),
        ("[synth]\ncloth_grid = 1\n", "synth.cloth_grid"),
    ] {
        let err = Plan::for_scene(&scene(&format!("{CLOTH}\n{extra}"), ".".as_ref()))
            .unwrap_err()
            .to_string();
        assert!(err.contains(key), "{key}: {err}");
    }
    let dup = format!("{CLOTH}{CLOTH}");
    let err = Plan::for_scene(&scene(&dup, ".".as_ref()))
        .unwrap_err()
        .to_string();
    assert!(err.contains("duplicate object name"), "{err}");
    let albedo = "[[object]]\nname = \"a\"\nsource = \"synth:cloth\"\nalbedo = [0.5, 1.5, 0.5]\n";
    let err = Plan::for_scene(&scene(albedo, ".".as_ref()))
        .unwrap_err()
        .to_string();
    assert!(err.contains("albedo") && err.contains("1.5"), "{err}");
}

#[test]
fn static_shadowing_plans_its_maps_and_no_light_directions() {
    let text = format!(
        "effects = [\"static-shadowing\"]\n{CLOTH}\n[environment]\nsource = \"synth:sky\"\n"
    );
    let plan = Plan::for_scene(&scene(&text, ".".as_ref())).unwrap();
    assert_eq!(
        plan.stages(),
        &[
            Stage::Geometry,
            Stage::Environment,
            Stage::StaticVisibility,
            Stage::Render
        ]
    );
}

#[test]
fn bad_static_shadowing_tables_are_named_before_any_work() {
    let base = format!("{CLOTH}\n[environment]\nsource = \"synth:sky\"\n");
    for (effects, table, key) in [
        (
            "\"static-shadowing\"",
            "model = \"cube\"",
            "static_shadowing.model",
        ),
        ("\"static-shadowing\"", "res = 7", "static_shadowing.res"),
        ("\"static-shadowing\"", "res = 0", "static_shadowing.res"),
        (
            "\"static-shadowing\"",
            "model = \"sp\"\naperture_deg = 180.0",
            "static_shadowing.aperture_deg",
        ),
        (
            "\"static-shadowing\"",
            "lookup = \"nearest\"",
            "static_shadowing.lookup",
        ),
        (
            "\"static-shadowing\"",
            "model = \"hs\"\nbuilder = \"gpu\"",
            "static_shadowing.builder",
        ),
        ("\"static-shadowing\", \"self-shadowing\"", "", "choose one"),
    ] {
        let text = format!("effects = [{effects}]\n{base}\n[static_shadowing]\n{table}\n");
        let err = Plan::for_scene(&scene(&text, ".".as_ref()))
            .unwrap_err()
            .to_string();
        assert!(err.contains(key), "{table}: {err}");
    }
    // Without an environment there is nothing to shadow.
    let text = format!("effects = [\"static-shadowing\"]\n{CLOTH}\n");
    let err = Plan::for_scene(&scene(&text, ".".as_ref()))
        .unwrap_err()
        .to_string();
    assert!(err.contains("environment"), "{err}");
}

#[test]
fn bad_shadow_volume_tables_are_named_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let sun = "[[shadow_volumes.light]]\nsun = true\n";
    let sky = "[environment]\nsource = \"synth:sky\"\n";
    for (table, key) in [
        (String::new(), "shadow_volumes.light"),
        (
            format!("{sun}direction = [0.0, 1.0, 0.0]\n{sky}"),
            "shadow_volumes.light[0]",
        ),
        (sun.to_owned(), "shadow_volumes.light[0].sun"),
        (
            "[[shadow_volumes.light]]\ndirection = [0.0, 0.0, 0.0]\nirradiance = [1.0, 1.0, 1.0]\n"
                .to_owned(),
            "shadow_volumes.light[0].direction",
        ),
        (
            "[[shadow_volumes.light]]\ndirection = [0.0, 1.0, 0.0]\n".to_owned(),
            "shadow_volumes.light[0].irradiance",
        ),
        (
            "[[shadow_volumes.light]]\nposition = [0.0, 1.0, 0.0]\nintensity = [-1.0, 1.0, 1.0]\n"
                .to_owned(),
            "shadow_volumes.light[0].intensity",
        ),
        (
            format!("[shadow_volumes]\ncasters = [\"shirt\"]\n{sun}{sky}"),
            "shadow_volumes.casters",
        ),
        (
            format!("[shadow_volumes]\nreceivers = [\"ground\"]\n{sun}{sky}"),
            "shadow_volumes.receivers",
        ),
        (
            format!("[shadow_volumes]\nlod = \"2.0\"\n{sun}{sky}"),
            "shadow_volumes.lod",
        ),
        (
            format!("[shadow_volumes]\nboundary = \"soft\"\n{sun}{sky}"),
            "shadow_volumes.boundary",
        ),
        (
            format!("[shadow_volumes]\nalpha_deg = 90.0\n{sun}{sky}"),
            "shadow_volumes.alpha_deg",
        ),
        (
            format!("[shadow_volumes]\nblur = 2.0\n{sun}{sky}"),
            "shadow_volumes.blur",
        ),
        (
            format!("[shadow_volumes]\nambient = -1.0\n{sun}{sky}"),
            "shadow_volumes.ambient",
        ),
    ] {
        let text = format!("effects = [\"shadow-volumes\"]\n{CLOTH}\n{table}");
        let err = Plan::for_scene(&scene(&text, dir.path()))
            .unwrap_err()
            .to_string();
        assert!(err.contains(key), "{table}: {err}");
    }
    let ok = format!("effects = [\"shadow-volumes\"]\n{CLOTH}\n{sun}{sky}");
    let plan = Plan::for_scene(&scene(&ok, dir.path())).unwrap();
    assert_eq!(
        plan.stages(),
        // The sky is drawn as the backdrop; nothing lights through it.
        &[
            Stage::Geometry,
            Stage::Environment,
            Stage::ShadowVolumes,
            Stage::Render
        ]
    );
}

#[test]
fn the_output_table_writes_the_images_it_names_and_both_when_it_names_none() {
    let names = |output: &str| {
        let s = scene(&format!("{CLOTH}\n{output}"), ".".as_ref());
        (s.output.png, s.output.exr)
    };
    let both = (Some("render.png".to_owned()), Some("render.exr".to_owned()));
    assert_eq!(names(""), both);
    assert_eq!(names("[output]\nbackground = \"black\"\n"), both);
    assert_eq!(
        names("[output]\npng = \"a.png\"\n"),
        (Some("a.png".to_owned()), None)
    );
    assert_eq!(
        names("[output]\nexr = \"a.exr\"\n"),
        (None, Some("a.exr".to_owned()))
    );
}
