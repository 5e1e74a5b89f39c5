//! `cloth-vis view` in a real window: each test runs the binary under Xvfb (`xvfb-run`, which
//! `.ci/run` installs) on the software adapter, in scripted mode (`--frames N --screenshot
//! FILE --events FILE`), and compares its picture with `cloth-vis render`'s still of the same
//! scene and camera. Without `xvfb-run` or a GPU adapter they skip, and fail under CI.
#![cfg(feature = "viewer")]

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use common::{SMALL_SYNTH, gpu_available, text};

/// The drape and its ball, explicit camera, level 2 so the CPU visibility stays quick.
fn scene_text(effects: &str, cloth_frame: i32, eye: [f32; 3]) -> String {
    scene_exposed(effects, cloth_frame, eye, "\"auto\"")
}

/// [`scene_text`] with `exposure` (TOML: "auto" or EV).
fn scene_exposed(effects: &str, cloth_frame: i32, eye: [f32; 3], exposure: &str) -> String {
    format!(
        r#"
effects = [{effects}]

[[object]]
name = "cloth"
source = "synth:cloth"
frame = {cloth_frame}
albedo = [0.72, 0.18, 0.12]
two_sided = true

[[object]]
name = "ball"
source = "synth:cloth-obstacle"

[environment]
source = "synth:sky"

[lighting]
level = 2

[camera]
width = 160
height = 120
eye = [{}, {}, {}]
target = [0.0, 0.4, 0.0]

[output]
png = "still.png"
exposure = {exposure}
{SMALL_SYNTH}"#,
        eye[0], eye[1], eye[2]
    )
}

const SHADOWED: &str = r#""lighting", "self-shadowing""#;
const EYE: [f32; 3] = [0.3, 1.6, 2.6];

/// `xvfb-run` on this machine, or the skip policy.
fn xvfb() -> bool {
    let found = Command::new("xvfb-run")
        .arg("--help")
        .output()
        .is_ok_and(|o| o.status.success() || !o.stdout.is_empty() || !o.stderr.is_empty());
    if found {
        return true;
    }
    test_data::skip::<()>("xvfb-run is not installed (apt-get install xvfb)").is_some()
}

/// `cloth-vis view ARGS` under Xvfb, whatever its exit.
fn view_output(args: &[&str]) -> Output {
    Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 800x600x24"])
        .arg(env!("CARGO_BIN_EXE_cloth-vis"))
        .arg("view")
        .args(args)
        .output()
        .unwrap()
}

/// `cloth-vis view ARGS` under Xvfb, which must succeed.
fn view(args: &[&str]) -> Output {
    let out = view_output(args);
    assert!(
        out.status.success(),
        "view {args:?} failed: {}\n{}",
        String::from_utf8_lossy(&out.stderr),
        String::from_utf8_lossy(&out.stdout)
    );
    out
}

/// A scripted 160×120 view of `scene` replaying `events` (one per frame, then one frame more),
/// its last frame written to `dir/NAME.png`. Returns the screenshot and the stdout line.
fn scripted(dir: &Path, scene: &Path, name: &str, events: &str) -> (PathBuf, String) {
    let script = dir.join(format!("{name}.txt"));
    std::fs::write(&script, events).unwrap();
    let frames = (events.lines().count() + 1).to_string();
    let shot = dir.join(format!("{name}.png"));
    let out = view(&[
        text(scene),
        "--frames",
        &frames,
        "--events",
        text(&script),
        "--screenshot",
        text(&shot),
        "--size",
        "160x120",
    ]);
    (shot, String::from_utf8_lossy(&out.stdout).into_owned())
}

/// Write `text` as `name` in `dir` and render its still with `cloth-vis render`.
fn render_still(dir: &Path, name: &str, text: &str) -> (PathBuf, PathBuf) {
    let scene = dir.join(format!("{name}.toml"));
    std::fs::write(&scene, text).unwrap();
    let out_dir = dir.join(format!("{name}-out"));
    let out = common::cli(&[
        "render",
        common::text(&scene),
        "--out",
        common::text(&out_dir),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    (scene, out_dir.join("still.png"))
}

fn rgba(path: &Path) -> (u32, u32, Vec<u8>) {
    let img = image::open(path).unwrap().to_rgba8();
    (img.width(), img.height(), img.into_raw())
}

/// Mean absolute difference over all channels, in 8-bit codes.
fn mean_diff(a: &Path, b: &Path) -> f64 {
    let (wa, ha, pa) = rgba(a);
    let (wb, hb, pb) = rgba(b);
    assert_eq!((wa, ha), (wb, hb), "{} vs {}", a.display(), b.display());
    let total: u64 = pa
        .iter()
        .zip(&pb)
        .map(|(x, y)| u64::from(x.abs_diff(*y)))
        .sum();
    total as f64 / pa.len() as f64
}

/// The viewer's picture equals `want` within a mean of 1/255 (the issue's target).
fn assert_matches(shot: &Path, want: &Path, what: &str) {
    let d = mean_diff(shot, want);
    assert!(d <= 1.0, "mean difference {d} codes to {what} (> 1/255)");
}

/// The change was visible: the picture is more than `codes` away from `before`.
fn assert_differs(shot: &Path, before: &Path, codes: f64, what: &str) {
    let d = mean_diff(shot, before);
    assert!(
        d > codes,
        "{what}: mean difference {d} codes, want > {codes}"
    );
}

fn ready() -> bool {
    xvfb() && gpu_available()
}

/// A file under `../shared/data` when it and a window are available (else the skip rule).
fn shared_and_ready(rel: &str) -> Option<PathBuf> {
    let path = test_data::shared_file(rel)?;
    ready().then_some(path)
}

#[test]
fn scripted_screenshot_equals_the_render_still() {
    if !ready() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let (scene, still) = render_still(dir.path(), "shadowed", &scene_text(SHADOWED, -1, EYE));
    let shot = dir.path().join("shot.png");
    let out = view(&[
        text(&scene),
        "--frames",
        "3",
        "--screenshot",
        text(&shot),
        "--size",
        "160x120",
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("3 frames presented (160×120)"), "{stdout}");
    let d = mean_diff(&shot, &still);
    assert!(d <= 1.0, "mean difference {d} codes > 1/255");
}

#[test]
fn self_shadowing_off_equals_the_unshadowed_render() {
    if !ready() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let (scene, shadowed) = render_still(dir.path(), "shadowed", &scene_text(SHADOWED, -1, EYE));
    let (_, plain) = render_still(dir.path(), "plain", &scene_text(r#""lighting""#, -1, EYE));
    let (shot, stdout) = scripted(dir.path(), &scene, "off", "off self-shadowing\n");
    assert!(stdout.contains("self-shadowing=off"), "{stdout}");
    let to_plain = mean_diff(&shot, &plain);
    assert!(
        to_plain <= 1.0,
        "mean difference {to_plain} codes to the unshadowed render"
    );
    // The toggle changed the picture: the shadowed still is measurably different.
    let to_shadowed = mean_diff(&shot, &shadowed);
    assert!(
        to_shadowed > 2.0 * to_plain.max(0.5),
        "{to_shadowed} vs {to_plain}"
    );
}

#[test]
fn replayed_orbit_gives_the_expected_camera() {
    if !ready() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    // A fixed exposure: automatic exposure is measured on the viewer's first frame (after
    // the first event), the still measures its own.
    let (scene, _) = render_still(
        dir.path(),
        "start",
        &scene_exposed(SHADOWED, -1, EYE, "-4.0"),
    );
    let (shot, stdout) = scripted(dir.path(), &scene, "orbit", "orbit 60 0\norbit 30 0\n");
    // 90° about +Y through the target [0, 0.4, 0]: (x, z) = (0.3, 2.6) → (2.6, −0.3).
    let expected = [2.6f32, 1.6, -0.3];
    let eye_text = stdout
        .split("eye [")
        .nth(1)
        .and_then(|s| s.split(']').next())
        .unwrap_or_else(|| panic!("no eye in {stdout}"));
    let eye: Vec<f32> = eye_text
        .split(',')
        .map(|v| v.trim().parse().unwrap())
        .collect();
    for (got, want) in eye.iter().zip(expected) {
        assert!(
            (got - want).abs() < 1e-4,
            "eye {eye:?}, expected {expected:?}"
        );
    }
    let (_, turned) = render_still(
        dir.path(),
        "turned",
        &scene_exposed(SHADOWED, -1, expected, "-4.0"),
    );
    assert_matches(&shot, &turned, "the render from the expected eye");
}

#[test]
fn an_animation_frame_is_lit_through_its_own_visibility() {
    if !ready() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let (scene, last) = render_still(dir.path(), "last", &scene_text(SHADOWED, -1, EYE));
    let (_, early) = render_still(dir.path(), "early", &scene_text(SHADOWED, 12, EYE));
    let (shot, _) = scripted(dir.path(), &scene, "frame12", "frame 12\n");
    assert_matches(&shot, &early, "the still of frame 12");
    assert_differs(&shot, &last, 2.0, "frame 12 looks like the last frame");
}

/// An event that parses but cannot apply to the scene (a map index past the choices) ends the
/// replay with an error that quotes it as its line in the file.
#[test]
fn a_failing_event_is_quoted_as_written() {
    if !ready() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.toml");
    std::fs::write(&scene, scene_text(SHADOWED, -1, EYE)).unwrap();
    let script = dir.path().join("events.txt");
    std::fs::write(&script, "orbit 10 0\nenvironment 3\n").unwrap();
    let out = view_output(&[
        text(&scene),
        "--frames",
        "3",
        "--events",
        text(&script),
        "--size",
        "160x120",
    ]);
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("event 2 (`environment 3`): environment 3 does not exist"),
        "{stderr}"
    );
}

#[test]
fn no_display_is_refused_before_any_work() {
    let out = Command::new(env!("CARGO_BIN_EXE_cloth-vis"))
        .args(["view", "demo"])
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("there is no display"), "{stderr}");
    assert!(stderr.contains("xvfb-run"), "{stderr}");
}

#[test]
fn bad_scripts_and_flags_are_refused_naming_the_value() {
    let dir = tempfile::tempdir().unwrap();
    let events = dir.path().join("bad.txt");
    std::fs::write(&events, "orbit 10 0\ntoggle sparkle\n").unwrap();
    let run = |args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_cloth-vis"))
            .arg("view")
            .args(args)
            .env("DISPLAY", ":7777")
            .output()
            .unwrap();
        assert!(!out.status.success(), "{args:?} was accepted");
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    let e = run(&["demo", "--events", text(&events)]);
    assert!(
        e.contains("bad.txt") && e.contains("line 2") && e.contains("sparkle"),
        "{e}"
    );
    std::fs::write(&events, "orbit 10 0\norbit 10 0\n").unwrap();
    let e = run(&["demo", "--events", text(&events), "--frames", "2"]);
    assert!(e.contains("--frames 2 is too few (at least 3)"), "{e}");
    let e = run(&["demo", "--frames", "1", "--screenshot", "x.jpg"]);
    assert!(e.contains("x.jpg") && e.contains(".png or .exr"), "{e}");
    let e = run(&["demo", "--adaptive=-3"]);
    assert!(e.contains("--adaptive -3"), "{e}");
    let e = run(&["demo", "--record", text(dir.path())]);
    assert!(
        e.contains("--record") && e.contains("new or empty folder"),
        "{e}"
    );
    let e = run(&["demo", "--size", "0x10"]);
    assert!(e.contains("\"0\""), "{e}");
    // A jump map needs an animation; a still mesh is refused by name.
    let tri = dir.path().join("tri.obj");
    std::fs::write(&tri, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let e = run(&[text(&tri), "--jumpmap"]);
    assert!(
        e.contains("tri.obj") && e.contains("needs an animation") && e.contains("1 frame"),
        "{e}"
    );
    // A .cpca that is not one is named before any window or GPU work.
    let cpca = dir.path().join("cut.cpca");
    std::fs::write(&cpca, b"CPCA").unwrap();
    let e = run(&[text(&cpca)]);
    assert!(e.contains("cut.cpca"), "{e}");
    // An --env map that does not exist is named once, before the GPU is asked for.
    let e = run(&["demo", "--env", "/nonexistent/sky.hdr"]);
    assert!(e.contains("/nonexistent/sky.hdr: cannot open"), "{e}");
    assert!(!e.contains("GPU"), "{e}");
}

/// The cloth with the synthetic woven BTF beside plain texturing (the demo's `btf` effect,
/// small), at a fixed exposure so both halves share it as `render`'s btf.png does.
fn btf_scene() -> String {
    let base = scene_exposed(r#""lighting", "btf""#, -1, EYE, "-1.0");
    format!(
        "{base}\n[btf]\nsource = \"synth:woven\"\nobjects = [\"cloth\"]\nres = 16\n\
         components = 4\nlight_dir = [0.2, 0.9, 0.6]\nuv_scale = 4.0\npng = \"btf.png\"\n"
    )
}

/// One half of a side-by-side PNG, written as its own PNG.
fn half(path: &Path, right: bool, out: &Path) {
    let img = image::open(path).unwrap().to_rgba8();
    let w = img.width() / 2;
    let x = if right { w } else { 0 };
    image::imageops::crop_imm(&img, x, 0, w, img.height())
        .to_image()
        .save(out)
        .unwrap();
}

#[test]
fn btf_and_plain_texture_equal_the_halves_of_the_render() {
    if !ready() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let (scene, still) = render_still(dir.path(), "btf", &btf_scene());
    let pair = still.with_file_name("btf.png");
    let (left, right) = (dir.path().join("left.png"), dir.path().join("right.png"));
    half(&pair, false, &left);
    half(&pair, true, &right);
    let (with_btf, _) = scripted(dir.path(), &scene, "with", "btf-plain off\n");
    let (plain, _) = scripted(dir.path(), &scene, "plain", "btf-plain on\n");
    let (off, _) = scripted(dir.path(), &scene, "off", "off btf\n");
    for (shot, want, what) in [
        (&with_btf, &left, "BTF"),
        (&plain, &right, "plain texture"),
        (&off, &still, "btf off: the still"),
    ] {
        let d = mean_diff(shot, want);
        assert!(d <= 1.0, "{what}: mean difference {d} codes");
    }
    // The switch changes the cloth: BTF and plain texture differ.
    assert!(mean_diff(&with_btf, &plain) > 1.0);
}

#[test]
fn a_btf_screenshot_in_exr_holds_no_negative_radiance() {
    if !ready() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    // The demo's material, 16 components of a 32² woven BTF, rings below zero in a few dark
    // texels seen from the demo's camera (25 pixels at 480×360 before the clamp).
    let shot = dir.path().join("demo.exr");
    let out = view(&[
        "demo",
        "--frames",
        "3",
        "--screenshot",
        text(&shot),
        "--size",
        "480x360",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let image = exr::prelude::read_first_rgba_layer_from_file(
        &shot,
        |size, _| vec![[0f32; 3]; size.width() * size.height()],
        |pixels, at, (r, g, b, _a): (f32, f32, f32, f32)| pixels[at.y() * 480 + at.x()] = [r, g, b],
    )
    .unwrap();
    let pixels = &image.layer_data.channel_data.pixels;
    let negative = pixels.iter().flatten().filter(|v| **v < 0.0).count();
    let lit = pixels.iter().filter(|p| p.iter().any(|v| *v > 0.0)).count();
    assert_eq!(negative, 0, "{negative} negative radiance values");
    assert!(lit > 10_000, "only {lit} lit pixels");
}

#[test]
fn btf_fins_follow_the_view_as_in_the_render() {
    if !ready() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let fins = btf_scene() + "fins = { source = \"synth:wool\" }\n";
    let (scene, with_fins) = render_still(dir.path(), "fins", &fins);
    let (_, bare) = render_still(dir.path(), "bare", &btf_scene());
    let (left, left_bare) = (
        dir.path().join("left.png"),
        dir.path().join("left-bare.png"),
    );
    half(&with_fins.with_file_name("btf.png"), false, &left);
    half(&bare.with_file_name("btf.png"), false, &left_bare);
    let (shot, _) = scripted(dir.path(), &scene, "fins", "btf-plain off\n");
    assert_matches(&shot, &left, "the BTF half of the render with fins");
    assert_differs(&shot, &left_bare, 0.1, "the fins changed nothing");
}

#[test]
fn a_turned_sky_relights_the_btf_through_the_same_visibility() {
    if !ready() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let env_btf = |rotation: &str| {
        btf_scene().replace(
            "[environment]\nsource = \"synth:sky\"\n",
            &format!("[environment]\nsource = \"synth:sky\"\nrotation_deg = {rotation}\n"),
        ) + "illumination = \"environment\"\nlevel = 2\n"
    };
    let (scene, before) = render_still(dir.path(), "env0", &env_btf("0.0"));
    let (_, turned) = render_still(dir.path(), "env120", &env_btf("120.0"));
    let (left, left_before) = (dir.path().join("left.png"), dir.path().join("left0.png"));
    half(&turned.with_file_name("btf.png"), false, &left);
    half(&before.with_file_name("btf.png"), false, &left_before);
    let (shot, _) = scripted(dir.path(), &scene, "turned", "rotation 120\n");
    assert_matches(
        &shot,
        &left,
        "the BTF half of the render with the sky turned 120°",
    );
    assert_differs(
        &shot,
        &left_before,
        0.5,
        "turning the sky left the BTF as it was",
    );
}

/// A scene of one clip file (relative to the scene), explicit camera on the chicken.
fn clip_scene(source: &str, frame: usize) -> String {
    placed_clip_scene(source, frame, "")
}

/// [`clip_scene`] with more keys of the object (`translation = …`).
fn placed_clip_scene(source: &str, frame: usize, placement: &str) -> String {
    format!(
        r#"
effects = ["lighting", "self-shadowing"]

[[object]]
name = "clip"
source = "{source}"
frame = {frame}
two_sided = true
{placement}

[environment]
source = "synth:sky"

[lighting]
level = 1

[camera]
width = 160
height = 120
eye = [28.0, 1.85, 11.4]
target = [26.0, 0.7, 8.8]

[output]
png = "still.png"
exposure = -2.5
background = "black"
"#
    )
}

/// The value after `key` in the summary line, up to the next `,` or `;`.
fn after<'a>(stdout: &'a str, key: &str) -> Option<&'a str> {
    let rest = stdout.split(key).nth(1)?;
    rest.split([',', ';']).next()
}

#[test]
fn a_cpca_streams_through_the_gpu_decoder_with_its_own_visibility() {
    let Some(chicken) = shared_and_ready("anim/chickenCrossing") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let cpca = dir.path().join("chicken.cpca");
    let out = common::cli(&[
        "anim",
        "compress",
        text(&chicken),
        "--out",
        text(&cpca),
        "--quiet",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (scene, first) = render_still(dir.path(), "first", &clip_scene("chicken.cpca", 0));
    let (_, later) = render_still(dir.path(), "later", &clip_scene("chicken.cpca", 90));
    // Frame 90 decoded on the GPU = the CPU decoder's frame 90, lit through its own M.
    let (shot, stdout) = scripted(dir.path(), &scene, "seek", "frame 90\n");
    assert!(
        stdout.contains("cpca frame 90 of 170 (GPU decoder)"),
        "{stdout}"
    );
    assert_matches(&shot, &later, "the still of frame 90");
    assert_differs(&shot, &first, 1.0, "frame 90 looks like frame 0");
    // Playing advances one decoded frame per presented frame.
    let (_, stdout) = scripted(dir.path(), &scene, "play", "play\n");
    assert!(stdout.contains("cpca frame 1 of 170"), "{stdout}");
    // A placed object: the decoded poses land where the loaded frame did (they were drawn
    // without the object's transform, so a moved .cpca left the picture).
    let moved = "translation = [0.4, 0.2, -0.3]";
    let (scene, _) = render_still(
        dir.path(),
        "moved",
        &placed_clip_scene("chicken.cpca", 0, moved),
    );
    let (_, moved_later) = render_still(
        dir.path(),
        "moved-later",
        &placed_clip_scene("chicken.cpca", 90, moved),
    );
    let (shot, _) = scripted(dir.path(), &scene, "moved-seek", "frame 90\n");
    assert_matches(&shot, &moved_later, "the moved still of frame 90");
    assert_differs(&shot, &later, 1.0, "the moved frame 90 looks unmoved");
}

#[test]
fn a_jump_map_plays_clip_frames_lit_through_their_own_visibility() {
    let Some(chicken) = shared_and_ready("anim/chickenCrossing") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let source = chicken.to_str().unwrap();
    let (scene, _) = render_still(dir.path(), "jump", &clip_scene(source, 0));
    let script = dir.path().join("jump.txt");
    std::fs::write(&script, "play\nnext-cell\n").unwrap();
    let shot = dir.path().join("jump.png");
    // Long enough to take jumps; the last frame is compared when it is a clip frame.
    for frames in ["61", "62", "63"] {
        let out = view(&[
            text(&scene),
            "--jumpmap",
            "--seed",
            "7",
            "--frames",
            frames,
            "--events",
            text(&script),
            "--screenshot",
            text(&shot),
            "--size",
            "160x120",
        ]);
        let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
        assert!(stdout.contains("jump map: "), "{stdout}");
        let Some(frame) = after(&stdout, "jump map: clip frame ") else {
            continue; // a blend frame: try one frame later
        };
        let (_, still) = render_still(
            dir.path(),
            &format!("clip{frame}"),
            &clip_scene(source, frame.trim().parse().unwrap()),
        );
        let d = mean_diff(&shot, &still);
        assert!(d <= 1.0, "clip frame {frame}: mean difference {d} codes");
        return;
    }
    panic!("three consecutive blend frames at the end of the run");
}

/// The drape under the sky whose sun casts shadow volumes onto a ground, the environment
/// turned by `rotation_deg`, at a fixed exposure (a turn must not re-measure it).
fn sun_scene(rotation_deg: f32) -> String {
    scene_exposed(r#""lighting", "shadow-volumes""#, -1, EYE, "-3.5").replace(
        "[environment]\nsource = \"synth:sky\"\n",
        &format!("[environment]\nsource = \"synth:sky\"\nrotation_deg = {rotation_deg:.1}\n"),
    ) + "\n[ground]\nsize = 5.0\ncells = 16\n\n[shadow_volumes]\n\n[[shadow_volumes.light]]\nsun = true\n"
}

#[test]
fn turning_the_sky_turns_its_suns_shadows() {
    if !ready() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let (scene, before) = render_still(dir.path(), "sun0", &sun_scene(0.0));
    let (_, want) = render_still(dir.path(), "sun90", &sun_scene(90.0));
    let (shot, _) = scripted(dir.path(), &scene, "turned", "rotation 90\n");
    assert_matches(&shot, &want, "the render with the sky turned by 90°");
    assert_differs(&shot, &before, 1.0, "turning the sky moved nothing");
}

#[test]
fn backend_switch_equals_the_render_through_that_backend() {
    if !ready() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let (scene, _) = render_still(dir.path(), "cpu", &scene_text(SHADOWED, -1, EYE));
    let depth = scene_text(SHADOWED, -1, EYE)
        + "\n[visibility]\nbackend = \"depth\"\ndepth_resolution = 128\n";
    let (_, want) = render_still(dir.path(), "depth", &depth);
    let (shot, _) = scripted(dir.path(), &scene, "to-depth", "backend depth 128\n");
    assert_matches(&shot, &want, "the depth-backend render");
}

/// The drape on the ground under a point light casting shadow volumes, light at `light`.
fn point_light_scene(light: [f32; 3]) -> String {
    let base = scene_exposed(r#""lighting", "shadow-volumes""#, -1, EYE, "-4.0");
    format!(
        "{base}\n[ground]\ncells = 8\n\n[[shadow_volumes.light]]\nposition = [{}, {}, {}]\n\
         intensity = [60.0, 60.0, 60.0]\n",
        light[0], light[1], light[2]
    )
}

#[test]
fn a_moved_point_light_equals_the_render_with_the_light_there() {
    if !ready() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let (scene, before) = render_still(dir.path(), "before", &point_light_scene([1.5, 2.5, 1.0]));
    let (_, want) = render_still(dir.path(), "after", &point_light_scene([-1.5, 2.0, -0.5]));
    let (shot, _) = scripted(dir.path(), &scene, "moved", "light -1.5 2 -0.5\n");
    assert_matches(&shot, &want, "the render with the light moved");
    assert_differs(&shot, &before, 1.0, "moving the light changed nothing");
}

#[test]
fn another_environment_and_tone_curve_equal_the_render_with_them() {
    let Some(venice) = shared_and_ready("env/venice_sunset_1k.hdr") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let sky = scene_exposed(SHADOWED, -1, EYE, "-4.0");
    let (scene, _) = render_still(dir.path(), "sky", &sky);
    let map = sky.replace(
        "source = \"synth:sky\"",
        &format!("source = {:?}", venice.to_str().unwrap()),
    );
    let (_, want) = render_still(dir.path(), "venice", &map);
    let script = dir.path().join("env.txt");
    std::fs::write(&script, "environment 1\n").unwrap();
    let shot = dir.path().join("env.png");
    view(&[
        text(&scene),
        "--env",
        text(&venice),
        "--frames",
        "2",
        "--events",
        text(&script),
        "--screenshot",
        text(&shot),
        "--size",
        "160x120",
    ]);
    assert_matches(&shot, &want, "the render under the map");
    // The tone curve: clamp + γ 2.2 as the scene's [output] would set it.
    let (_, clamped) = render_still(
        dir.path(),
        "clamped",
        &sky.replace("exposure = -4.0", "exposure = -4.0\ntone = \"clamp\""),
    );
    let (shot, _) = scripted(dir.path(), &scene, "tone", "tone clamp\n");
    assert_matches(&shot, &clamped, "the clamped render");
}
