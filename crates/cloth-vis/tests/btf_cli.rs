//! `cloth-vis btf synth | compress | stats` through the binary: the synthetic woven BTF at 64²
//! (the CI size) written in the UBO2003 layout, compressed by per-view PCA and compared
//! with its images; and refused input (a missing image, a wrong output name, a folder that is
//! not empty, a `.btfpca` of another BTF) with the file named and nothing written.

mod common;

use std::path::Path;
use std::process::Output;

use btf::{BtfDir, BtfPca, Sampling};
use image::GenericImageView as _;

use common::{cli, text};

fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

#[test]
fn synth_compress_stats_round_trip_at_64() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("woven");
    let out = cli(&[
        "btf",
        "synth",
        "--res",
        "64",
        "--out",
        text(&dir),
        "--quiet",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stdout(&out).contains("6561 images of 64x64 (H1)"),
        "{}",
        stdout(&out)
    );
    // The folder is a real UBO2003 folder: the loader finds every pair at 64².
    let folder = BtfDir::open(&dir).unwrap();
    assert_eq!(
        (folder.sampling(), folder.width(), folder.height()),
        (Sampling::H1, 64, 64)
    );
    assert!(dir.join("tl000 pl000 tv000 pv000.png").is_file());
    // Nothing but the finished folder is left beside it.
    let names: Vec<_> = std::fs::read_dir(tmp.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names, vec![std::ffi::OsString::from("woven")]);

    let file = tmp.path().join("woven.btfpca");
    let out = cli(&[
        "btf",
        "compress",
        text(&dir),
        "--components",
        "16",
        "--out",
        text(&file),
        "--quiet",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let line = stdout(&out);
    let raw = 81 * 81 * 3 * 64 * 64;
    assert!(
        line.contains(&format!("{:.1} MB of 8-bit images", raw as f64 / 1e6)),
        "{line}"
    );
    let pca = BtfPca::read(&file).unwrap();
    assert!(pca.slots().iter().all(|s| s.components() == 16));
    let size = std::fs::metadata(&file).unwrap().len();
    assert!(
        line.contains(&format!("{:.1} MB (", size as f64 / 1e6)),
        "{line}"
    );
    // c = 16 of ≤ 80 components per slot, 8-bit bases: at least 4:1 over the 8-bit images.
    assert!((raw as f64) / (size as f64) > 4.0, "{raw} / {size}");

    let out = cli(&["btf", "stats", text(&dir), text(&file)]);
    assert!(out.status.success(), "{}", stderr(&out));
    let line = stdout(&out);
    // The binary prints what the library measures.
    let error = pca.stats(&folder, None).unwrap();
    assert_eq!(error.images, 6561);
    assert!(
        line.contains(&format!(
            "RMS {:.3} (8-bit sRGB), PSNR {:.2} dB",
            error.rms_srgb8, error.psnr_db
        )),
        "{line}"
    );
    // More components, less error (the per-view PCA is a truncation, eq. 5.1).
    let file32 = tmp.path().join("woven32.btfpca");
    let out = cli(&[
        "btf",
        "compress",
        text(&dir),
        "--components",
        "32",
        "--out",
        text(&file32),
        "--quiet",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let more = BtfPca::read(&file32).unwrap().stats(&folder, None).unwrap();
    assert!(more.rms_srgb8 < error.rms_srgb8, "{more:?} vs {error:?}");
}

#[test]
fn bad_input_is_refused_naming_the_file_and_nothing_is_written() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("w");
    let out = cli(&["btf", "synth", "--res", "8", "--out", text(&dir), "--quiet"]);
    assert!(out.status.success(), "{}", stderr(&out));

    // A synth into a folder that holds files is refused.
    let out = cli(&["btf", "synth", "--res", "8", "--out", text(&dir), "--quiet"]);
    assert!(!out.status.success());
    assert!(stderr(&out).contains(text(&dir)), "{}", stderr(&out));
    // Bad generator parameters name the field.
    let out = cli(&[
        "btf",
        "synth",
        "--res",
        "0",
        "--out",
        text(&tmp.path().join("zero")),
        "--quiet",
    ]);
    assert!(!out.status.success());
    assert!(stderr(&out).contains("res"), "{}", stderr(&out));
    assert!(!tmp.path().join("zero").exists());

    // A wrong output name is refused before any work.
    let bad = tmp.path().join("w.bin");
    let out = cli(&[
        "btf",
        "compress",
        text(&dir),
        "--out",
        text(&bad),
        "--quiet",
    ]);
    assert!(!out.status.success());
    assert!(stderr(&out).contains("w.bin"));
    assert!(!bad.exists());

    // A missing image: the error names the file that should be there.
    let file = tmp.path().join("w.btfpca");
    let missing = dir.join("tl015 pl060 tv030 pv090.png");
    let missing = if missing.exists() {
        missing
    } else {
        dir.join("tl017 pl060 tv034 pv090.png")
    };
    std::fs::remove_file(&missing).unwrap();
    let out = cli(&[
        "btf",
        "compress",
        text(&dir),
        "--out",
        text(&file),
        "--quiet",
    ]);
    assert!(!out.status.success());
    let name = missing.file_name().unwrap().to_str().unwrap();
    assert!(stderr(&out).contains(name), "{}", stderr(&out));
    assert!(!file.exists());

    // A .btfpca of another BTF is refused by stats, naming both.
    let a = tmp.path().join("a");
    let b = tmp.path().join("b");
    for (d, res) in [(&a, "8"), (&b, "4")] {
        let out = cli(&["btf", "synth", "--res", res, "--out", text(d), "--quiet"]);
        assert!(out.status.success(), "{}", stderr(&out));
    }
    let fa = tmp.path().join("a.btfpca");
    let out = cli(&["btf", "compress", text(&a), "--out", text(&fa), "--quiet"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let out = cli(&["btf", "stats", text(&b), text(&fa)]);
    assert!(!out.status.success());
    let e = stderr(&out);
    assert!(e.contains("a.btfpca") && e.contains(text(&b)), "{e}");
    // A corrupt .btfpca names the file.
    let mut bytes = std::fs::read(&fa).unwrap();
    let mid = bytes.len() / 2;
    bytes[mid] ^= 0xff;
    let corrupt = tmp.path().join("c.btfpca");
    std::fs::write(&corrupt, bytes).unwrap();
    let out = cli(&["btf", "stats", text(&a), text(&corrupt)]);
    assert!(!out.status.success());
    assert!(stderr(&out).contains("c.btfpca"), "{}", stderr(&out));
    // The two files the wrong way round: the order, and the command that was meant.
    let out = cli(&["btf", "stats", text(&fa), text(&a)]);
    assert!(!out.status.success());
    let meant = format!("`cloth-vis btf stats {} {}`", a.display(), fa.display());
    assert!(stderr(&out).contains(&meant), "{}", stderr(&out));
}

#[test]
fn render_on_the_gpu_matches_the_cpu_reference_and_bad_requests_are_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("w");
    let file = tmp.path().join("w.btfpca");
    assert!(
        cli(&[
            "btf",
            "synth",
            "--res",
            "16",
            "--out",
            text(&dir),
            "--quiet"
        ])
        .status
        .success()
    );
    assert!(
        cli(&[
            "btf",
            "compress",
            text(&dir),
            "--out",
            text(&file),
            "--quiet"
        ])
        .status
        .success()
    );
    let render = |extra: &[&str], out: &Path| {
        let mut args = vec![
            "btf",
            "render",
            "synth:cloth",
            "--btf",
            text(&file),
            "--light-dir",
            "0.2,0.9,0.6",
            "--size",
            "96x96",
            "--out",
            text(out),
        ];
        args.extend_from_slice(extra);
        cli(&args)
    };
    let cpu = tmp.path().join("cpu.png");
    let out = render(&["--cpu"], &cpu);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stdout(&out).contains("(cpu)"));
    let cpu_image = image::open(&cpu).unwrap().to_rgb8();
    assert_eq!(cpu_image.dimensions(), (96, 96));
    let lit = cpu_image.pixels().filter(|p| p.0 != [0, 0, 0]).count();
    assert!(lit > 1000, "the cloth covers only {lit} pixels");

    if gpu_context::GpuContext::new(&gpu_context::GpuOptions::default()).is_err() {
        test_data::skip::<()>("no GPU adapter for the GPU half of the render test");
    } else {
        let gpu = tmp.path().join("gpu.png");
        let out = render(&[], &gpu);
        assert!(out.status.success(), "{}", stderr(&out));
        assert!(stdout(&out).contains("(gpu)"));
        let gpu_image = image::open(&gpu).unwrap().to_rgb8();
        let diff: u64 = gpu_image
            .as_raw()
            .iter()
            .zip(cpu_image.as_raw())
            .map(|(a, b)| u64::from(a.abs_diff(*b)))
            .sum();
        let mean = diff as f64 / gpu_image.as_raw().len() as f64;
        assert!(mean <= 1.0, "GPU and CPU differ by {mean} codes on average");
        // Beside plain texturing: twice as wide, and the halves differ.
        let both = tmp.path().join("both.png");
        let out = render(&["--beside-plain"], &both);
        assert!(out.status.success(), "{}", stderr(&out));
        let both = image::open(&both).unwrap().to_rgb8();
        assert_eq!(both.dimensions(), (192, 96));
        assert_eq!(
            both.view(0, 0, 96, 96).to_image().as_raw(),
            gpu_image.as_raw()
        );
        assert_ne!(
            both.view(96, 0, 96, 96).to_image().as_raw(),
            gpu_image.as_raw()
        );
    }

    // No light, a wrong extension, a mesh without UVs: refused, nothing written.
    let bad = tmp.path().join("bad.png");
    let out = cli(&[
        "btf",
        "render",
        "synth:cloth",
        "--btf",
        text(&file),
        "--out",
        text(&bad),
    ]);
    assert!(!out.status.success());
    assert!(stderr(&out).contains("--light-dir"), "{}", stderr(&out));
    let jpg = tmp.path().join("x.jpg");
    let out = render(&["--cpu"], &jpg);
    assert!(!out.status.success());
    assert!(stderr(&out).contains("x.jpg"));
    let obj = tmp.path().join("plain.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let out = cli(&[
        "btf",
        "render",
        text(&obj),
        "--btf",
        text(&file),
        "--light-dir",
        "0,0,1",
        "--cpu",
        "--out",
        text(&bad),
    ]);
    assert!(!out.status.success());
    let e = stderr(&out);
    assert!(
        e.contains("plain.obj") && e.contains("texture coordinates"),
        "{e}"
    );
    assert!(!bad.exists() && !jpg.exists());

    // --up-axis z: a Z-up copy of a mesh (every point and the light turned by +90° about X,
    // taking +Y to +Z) renders as the Y-up original does, the camera turned with it.
    let grid = |turn: bool| -> String {
        let mut obj = String::new();
        let n = 12;
        for j in 0..=n {
            for i in 0..=n {
                let (u, v) = (i as f32 / n as f32, j as f32 / n as f32);
                let (x, y, z) = (u - 0.5, 0.15 * (6.0 * u).sin() * (4.0 * v).cos(), v - 0.5);
                let (x, y, z) = if turn { (x, -z, y) } else { (x, y, z) };
                obj += &format!("v {x} {y} {z}\nvt {u} {v}\n");
            }
        }
        for j in 0..n {
            for i in 0..n {
                let a = j * (n + 1) + i + 1;
                let (b, c, d) = (a + 1, a + n + 1, a + n + 2);
                obj += &format!("f {a}/{a} {c}/{c} {b}/{b}\nf {b}/{b} {c}/{c} {d}/{d}\n");
            }
        }
        obj
    };
    let images: Vec<image::RgbImage> = [(false, "y", "0.2,0.9,0.6"), (true, "z", "0.2,-0.6,0.9")]
        .iter()
        .map(|&(turn, axis, light)| {
            let mesh = tmp.path().join(format!("grid-{axis}.obj"));
            std::fs::write(&mesh, grid(turn)).unwrap();
            let png = tmp.path().join(format!("grid-{axis}.png"));
            let out = cli(&[
                "btf",
                "render",
                text(&mesh),
                "--btf",
                text(&file),
                "--light-dir",
                light,
                "--up-axis",
                axis,
                "--size",
                "96x96",
                "--cpu",
                "--out",
                text(&png),
            ]);
            assert!(out.status.success(), "{}", stderr(&out));
            image::open(&png).unwrap().to_rgb8()
        })
        .collect();
    let lit = images[0].pixels().filter(|p| p.0 != [0, 0, 0]).count();
    assert!(lit > 1000, "the grid covers only {lit} pixels");
    let diff: u64 = images[0]
        .as_raw()
        .iter()
        .zip(images[1].as_raw())
        .map(|(a, b)| u64::from(a.abs_diff(*b)))
        .sum();
    let mean = diff as f64 / images[0].as_raw().len() as f64;
    assert!(
        mean <= 0.5,
        "the Z-up copy differs by {mean} codes on average"
    );
}
