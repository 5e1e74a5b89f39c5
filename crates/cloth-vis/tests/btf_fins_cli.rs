//! `cloth-vis btf fins synth | compress` and `btf render --fins` through the binary (thesis
//! §5.7): the synthetic wool at 32² in the fin folder layout, its PCA (c = 16 by default, exact
//! with every component), refused input naming the file, and fins that change only the pixels
//! along the silhouette; and `btf render --sky/--env` (§5.5.2).

mod common;

use std::path::Path;
use std::process::Output;

use btf::fin_pca::{FinDir, FinPca, fin_image_name};
use image::GenericImageView as _;

use common::{cli, text};

fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn synth(dir: &Path) -> Output {
    cli(&[
        "btf",
        "fins",
        "synth",
        "--size",
        "32x32",
        "--out",
        text(dir),
        "--quiet",
    ])
}

/// The synthetic woven BTF at `res`², compressed: `DIR/w.btfpca`.
fn woven_btf(dir: &Path, res: &str) -> std::path::PathBuf {
    let (woven, file) = (dir.join("w"), dir.join("w.btfpca"));
    let args = [
        "btf",
        "synth",
        "--res",
        res,
        "--out",
        text(&woven),
        "--quiet",
    ];
    assert!(cli(&args).status.success());
    let args = [
        "btf",
        "compress",
        text(&woven),
        "--out",
        text(&file),
        "--quiet",
    ];
    assert!(cli(&args).status.success());
    file
}

#[test]
fn synth_then_compress_keeps_16_components_and_all_80_reconstruct_exactly() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("wool");
    let out = synth(&dir);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stdout(&out).contains("81 images of 32x32"),
        "{}",
        stdout(&out)
    );
    let folder = FinDir::open(&dir).unwrap();
    assert_eq!((folder.width(), folder.height()), (32, 32));
    assert!(dir.join(fin_image_name(44, "png")).is_file());
    let names: Vec<_> = std::fs::read_dir(tmp.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names, vec![std::ffi::OsString::from("wool")]);
    // Alpha falls off at the tips: the base rows of the overhead-lit image are brighter.
    let overhead = image::open(dir.join(fin_image_name(0, "png")))
        .unwrap()
        .to_rgb8();
    let band = |rows: std::ops::Range<u32>| {
        rows.flat_map(|y| (0..32).map(move |x| (x, y)))
            .map(|(x, y)| {
                overhead
                    .get_pixel(x, y)
                    .0
                    .iter()
                    .map(|&c| u32::from(c))
                    .sum::<u32>()
            })
            .sum::<u32>()
    };
    assert!(
        band(24..32) > 3 * band(0..8),
        "base {} tips {}",
        band(24..32),
        band(0..8)
    );

    let file = tmp.path().join("wool.finpca");
    let out = cli(&["btf", "fins", "compress", text(&dir), "--out", text(&file)]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stdout(&out).contains("c = 16 (asked 16)"),
        "{}",
        stdout(&out)
    );
    let fins = FinPca::read(&file).unwrap();
    assert_eq!(fins.slot().components(), 16);

    let exact = tmp.path().join("exact.finpca");
    let out = cli(&[
        "btf",
        "fins",
        "compress",
        text(&dir),
        "--components",
        "80",
        "--storage",
        "f32",
        "--mean-storage",
        "f32",
        "--out",
        text(&exact),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let images = folder.load().unwrap();
    let stats = FinPca::read(&exact).unwrap().stats(&images).unwrap();
    assert!(stats.max_abs_srgb8 < 0.01, "{stats:?}");
}

#[test]
fn bad_fin_input_is_refused_naming_the_file_and_nothing_is_written() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("wool");
    assert!(synth(&dir).status.success());
    // Synthesising into a folder with files is refused.
    let out = synth(&dir);
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains("is a folder that holds files"),
        "{}",
        stderr(&out)
    );
    // A wrong output name, c = 0.
    let btfpca = tmp.path().join("wool.btfpca");
    let out = cli(&[
        "btf",
        "fins",
        "compress",
        text(&dir),
        "--out",
        text(&btfpca),
    ]);
    assert!(!out.status.success() && stderr(&out).contains(".finpca"));
    assert!(!btfpca.exists());
    let file = tmp.path().join("wool.finpca");
    let out = cli(&[
        "btf",
        "fins",
        "compress",
        text(&dir),
        "--components",
        "0",
        "--out",
        text(&file),
    ]);
    assert!(!out.status.success() && stderr(&out).contains("--components 0"));
    // A missing light image is named.
    std::fs::remove_file(dir.join(fin_image_name(20, "png"))).unwrap();
    let out = cli(&["btf", "fins", "compress", text(&dir), "--out", text(&file)]);
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains(&fin_image_name(20, "png")),
        "{}",
        stderr(&out)
    );
    assert!(!file.exists());
    // A .finpca that is not one, given to render: named.
    std::fs::write(&file, b"not a fin file").unwrap();
    let out = cli(&[
        "btf",
        "render",
        "synth:sphere",
        "--btf",
        text(&file),
        "--light-dir",
        "0,1,1",
        "--fins",
        text(&file),
        "--cpu",
        "--out",
        text(&tmp.path().join("x.png")),
    ]);
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains("--cpu"),
        "--fins conflicts with --cpu: {}",
        stderr(&out)
    );
}

#[test]
fn fins_change_only_the_pixels_along_the_silhouette() {
    if gpu_context::GpuContext::new(&gpu_context::GpuOptions::default()).is_err() {
        test_data::skip::<()>("no GPU adapter for the fin render test");
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let btf_file = woven_btf(tmp.path(), "16");
    let render = |extra: &[&str], out: &Path| {
        let mut args = vec![
            "btf",
            "render",
            "synth:sphere",
            "--btf",
            text(&btf_file),
            "--light-dir",
            "0.2,0.7,0.7",
            "--size",
            "128x128",
            "--out",
            text(out),
        ];
        args.extend_from_slice(extra);
        cli(&args)
    };
    let plain = tmp.path().join("plain.png");
    let out = render(&[], &plain);
    assert!(out.status.success(), "{}", stderr(&out));
    let both = tmp.path().join("both.png");
    let out = render(&["--fins", "synth:wool", "--beside-no-fins"], &both);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stdout(&out).contains("fins: "), "{}", stdout(&out));
    let plain = image::open(&plain).unwrap().to_rgb8();
    let both = image::open(&both).unwrap().to_rgb8();
    assert_eq!(both.dimensions(), (256, 128));
    let without = both.view(0, 0, 128, 128).to_image();
    let with = both.view(128, 0, 128, 128).to_image();
    assert_eq!(
        without.as_raw(),
        plain.as_raw(),
        "left half = the render without fins"
    );
    // Every changed pixel lies within 5 pixels of the sphere's outline, and some change.
    let covered = |x: i32, y: i32| {
        (0..128).contains(&x)
            && (0..128).contains(&y)
            && plain.get_pixel(x as u32, y as u32).0 != [0; 3]
    };
    let near_outline = |x: i32, y: i32| {
        let c = covered(x, y);
        (-5..=5).any(|dy| (-5..=5).any(|dx| covered(x + dx, y + dy) != c))
    };
    let mut changed = 0;
    for (x, y, p) in with.enumerate_pixels() {
        if p != without.get_pixel(x, y) {
            changed += 1;
            assert!(
                near_outline(x as i32, y as i32),
                "pixel ({x}, {y}) changed inside"
            );
        }
    }
    assert!(changed > 100, "only {changed} pixels carry fins");
}

/// `btf render --sky` / `--env` (thesis §5.5.2): the BTF through the mesh's own visibility
/// under an environment, with its costs printed; a missing map is named.
#[test]
fn render_under_an_environment_prints_its_costs_and_names_a_missing_map() {
    let tmp = tempfile::tempdir().unwrap();
    let btf_file = woven_btf(tmp.path(), "8");
    let png = tmp.path().join("sky.png");
    let out = cli(&[
        "btf",
        "render",
        "synth:sphere",
        "--btf",
        text(&btf_file),
        "--sky",
        "--level",
        "2",
        "--cpu",
        "--size",
        "48x48",
        "--out",
        text(&png),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let line = stdout(&out);
    assert!(line.contains("environment: 66 directions"), "{line}");
    assert!(line.contains("environment update"), "{line}");
    let image = image::open(&png).unwrap().to_rgb8();
    let lit = image.pixels().filter(|p| p.0 != [0, 0, 0]).count();
    assert!(lit > 300, "the sphere covers only {lit} pixels");
    let missing = tmp.path().join("nowhere.hdr");
    let out = cli(&[
        "btf",
        "render",
        "synth:sphere",
        "--btf",
        text(&btf_file),
        "--env",
        text(&missing),
        "--cpu",
        "--out",
        text(&tmp.path().join("x.png")),
    ]);
    assert!(!out.status.success());
    assert!(stderr(&out).contains("nowhere.hdr"), "{}", stderr(&out));
    assert!(!tmp.path().join("x.png").exists());

    // The deforming drape, frame by frame, each with its own visibility.
    let dir = tmp.path().join("frames");
    let args = [
        "btf",
        "render",
        "synth:cloth",
        "--btf",
        text(&btf_file),
        "--sky",
        "--level",
        "1",
        "--frames",
        "118..120",
        "--cpu",
        "--size",
        "32x32",
        "--quiet",
        "--out",
        text(&dir),
    ];
    let out = cli(&args);
    assert!(out.status.success(), "{}", stderr(&out));
    let mut names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    assert_eq!(names, ["frame-0118.png", "frame-0119.png"]);
    // Outside the drape's 120 frames, or a mesh that does not move: refused, nothing written.
    let bad = tmp.path().join("bad");
    let out = cli(&[
        "btf",
        "render",
        "synth:cloth",
        "--btf",
        text(&btf_file),
        "--sky",
        "--frames",
        "100..130",
        "--cpu",
        "--out",
        text(&bad),
    ]);
    assert!(
        !out.status.success() && stderr(&out).contains("100..130"),
        "{}",
        stderr(&out)
    );
    let out = cli(&[
        "btf",
        "render",
        "synth:sphere",
        "--btf",
        text(&btf_file),
        "--sky",
        "--frames",
        "0..2",
        "--cpu",
        "--out",
        text(&bad),
    ]);
    assert!(
        !out.status.success() && stderr(&out).contains("animated"),
        "{}",
        stderr(&out)
    );
    assert!(!bad.exists());
}

/// `btf render --maps RES` (static hemicube maps, the thesis's path) lights the sphere as M does,
/// `--decompose A,E` turns through eq. 5.13 and prints its error, and the flags that cannot
/// work together are refused before any work.
#[test]
fn maps_and_the_decomposition_from_the_cli() {
    let tmp = tempfile::tempdir().unwrap();
    let btf_file = woven_btf(tmp.path(), "8");
    let render = |extra: &[&str], png: &Path| {
        let mut args = vec![
            "btf",
            "render",
            "synth:sphere",
            "--btf",
            text(&btf_file),
            "--sky",
            "--rotation",
            "30",
            "--cpu",
            "--size",
            "48x48",
            "--out",
            text(png),
        ];
        args.extend_from_slice(extra);
        cli(&args)
    };
    let (m_png, maps_png, dec_png) = (
        tmp.path().join("m.png"),
        tmp.path().join("maps.png"),
        tmp.path().join("dec.png"),
    );
    let out = render(&["--level", "4"], &m_png);
    assert!(out.status.success(), "{}", stderr(&out));
    let out = render(&["--maps", "16"], &maps_png);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stdout(&out).contains("environment: 768 directions per vertex"),
        "{}",
        stdout(&out)
    );
    let (a, b) = (
        image::open(&m_png).unwrap().to_rgb8(),
        image::open(&maps_png).unwrap().to_rgb8(),
    );
    let (mut sum, mut n) = (0.0f64, 0usize);
    for (p, q) in a.pixels().zip(b.pixels()) {
        if p.0 != [0, 0, 0] {
            sum += (0..3).map(|c| f64::from(p[c].abs_diff(q[c]))).sum::<f64>() / 3.0;
            n += 1;
        }
    }
    let mean = sum / n as f64;
    eprintln!("mean |M − maps| on the sphere: {mean:.2} (8-bit)");
    assert!(
        n > 300 && mean < 6.0,
        "mean |M − maps| {mean} over {n} pixels"
    );

    let out = render(&["--level", "2", "--decompose", "6,3"], &dec_png);
    assert!(out.status.success(), "{}", stderr(&out));
    let line = stdout(&out);
    assert!(
        line.contains("decomposition (eq. 5.13): 6 turns") && line.contains("3 components"),
        "{line}"
    );
    assert!(line.contains("error against the direct update"), "{line}");

    // Refused: A = 1, a zero count, 10⁵ turns (memory), an odd map side, --decompose with
    // --frames.
    let bad = tmp.path().join("bad.png");
    for (extra, needle) in [
        (&["--decompose", "1,1"][..], "turns"),
        (&["--decompose", "100000,5"][..], "at most 360 turns"),
        (&["--decompose", "5,0"][..], "at least 1"),
        (&["--maps", "7"][..], "7"),
        (&["--decompose", "4,2", "--frames", "0..2"][..], "--frames"),
    ] {
        let out = render(extra, &bad);
        assert!(!out.status.success(), "{extra:?}");
        assert!(stderr(&out).contains(needle), "{extra:?}: {}", stderr(&out));
        assert!(!bad.exists(), "{extra:?} wrote a file");
    }
    let out = cli(&[
        "btf",
        "render",
        "synth:sphere",
        "--btf",
        text(&btf_file),
        "--sky",
        "--maps",
        "8",
        "--rotation",
        "nan",
        "--cpu",
        "--out",
        text(&bad),
    ]);
    assert!(
        !out.status.success() && stderr(&out).contains("must be finite"),
        "{}",
        stderr(&out)
    );
    assert!(!bad.exists());
}

/// `btf render --part NAME=FILE` (garment parts, §5.6): the faces of material NAME wear FILE,
/// every other face keeps --btf — pixel for pixel against the single-material render.
#[test]
fn parts_wear_their_own_btf_and_the_rest_is_untouched() {
    if gpu_context::GpuContext::new(&gpu_context::GpuOptions::default()).is_err() {
        test_data::skip::<()>("no GPU adapter for the parts render test");
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let woven = woven_btf(tmp.path(), "8");
    // The same material with one component: visibly different shading, same size.
    let flat = tmp.path().join("flat.btfpca");
    let out = cli(&[
        "btf",
        "compress",
        text(&tmp.path().join("w")),
        "--components",
        "1",
        "--out",
        text(&flat),
        "--quiet",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let mesh = tmp.path().join("sheet.obj");
    std::fs::write(&mesh, common::two_part_sheet(16)).unwrap();
    let render = |extra: &[&str], png: &Path| {
        let mut args = vec![
            "btf",
            "render",
            text(&mesh),
            "--btf",
            text(&woven),
            "--light-dir",
            "0.3,0.4,0.9",
            "--camera-dir",
            "0,0,1",
            "--size",
            "64x64",
            "--out",
            text(png),
        ];
        args.extend_from_slice(extra);
        cli(&args)
    };
    let (one, two) = (tmp.path().join("one.png"), tmp.path().join("two.png"));
    let out = render(&[], &one);
    assert!(out.status.success(), "{}", stderr(&out));
    let part = format!("right={}", text(&flat));
    let out = render(&["--part", &part], &two);
    assert!(out.status.success(), "{}", stderr(&out));
    let (a, b) = (
        image::open(&one).unwrap().to_rgb8(),
        image::open(&two).unwrap().to_rgb8(),
    );
    // The sheet fills the middle of the frame; its left half keeps the woven BTF exactly, its
    // right half changes. Columns near the border are left out (the camera frames the sheet).
    let (mut left_changed, mut right_changed) = (0, 0);
    for y in 16..48 {
        for x in 12..28 {
            left_changed += usize::from(a.get_pixel(x, y) != b.get_pixel(x, y));
        }
        for x in 36..52 {
            right_changed += usize::from(a.get_pixel(x, y) != b.get_pixel(x, y));
        }
    }
    assert_eq!(left_changed, 0, "the left part kept --btf");
    assert!(
        right_changed > 200,
        "only {right_changed} right pixels changed"
    );

    // Unknown material, a mesh without materials, the same part twice: named, nothing written.
    let bad = tmp.path().join("bad.png");
    let missing = format!("collar={}", text(&flat));
    let out = render(&["--part", &missing], &bad);
    assert!(
        !out.status.success() && stderr(&out).contains("\"left\", \"right\""),
        "{}",
        stderr(&out)
    );
    let out = render(&["--part", &part, "--part", &part], &bad);
    assert!(
        !out.status.success() && stderr(&out).contains("twice"),
        "{}",
        stderr(&out)
    );
    let out = cli(&[
        "btf",
        "render",
        "synth:sphere",
        "--btf",
        text(&woven),
        "--light-dir",
        "0,0,1",
        "--part",
        &part,
        "--out",
        text(&bad),
    ]);
    assert!(!out.status.success(), "{}", stderr(&out));
    assert!(!bad.exists());
}

/// `btf render --frames` on a real skinned clip (CesiumMan, 3,273 vertices): each frame its own
/// visibility under the environment; a static mesh is refused.
#[test]
fn frames_of_a_gltf_clip_under_an_environment() {
    let Some(clip) = test_data::shared_file("anim/gltf/CesiumMan.glb") else {
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    let btf_file = woven_btf(tmp.path(), "8");
    let dir = tmp.path().join("walk");
    let out = cli(&[
        "btf",
        "render",
        text(&clip),
        "--btf",
        text(&btf_file),
        "--sky",
        "--level",
        "1",
        "--frames",
        "3..5",
        "--cpu",
        "--size",
        "32x48",
        "--quiet",
        "--out",
        text(&dir),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stdout(&out).contains("3273 vertices"), "{}", stdout(&out));
    let a = image::open(dir.join("frame-0003.png")).unwrap().to_rgb8();
    let b = image::open(dir.join("frame-0004.png")).unwrap().to_rgb8();
    assert!(a.pixels().filter(|p| p.0 != [0, 0, 0]).count() > 40);
    assert_ne!(a, b, "the walk moves between frames");
    let obj = tmp.path().join("tri.obj");
    std::fs::write(
        &obj,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n",
    )
    .unwrap();
    let bad = tmp.path().join("bad");
    let out = cli(&[
        "btf",
        "render",
        text(&obj),
        "--btf",
        text(&btf_file),
        "--sky",
        "--frames",
        "0..1",
        "--cpu",
        "--out",
        text(&bad),
    ]);
    assert!(
        !out.status.success() && stderr(&out).contains("1 frame"),
        "{}",
        stderr(&out)
    );
    assert!(!bad.exists());
}
