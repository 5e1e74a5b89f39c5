//! BTF folders: the writer, the loader's validation (errors name the file) and decoding.

mod common;

use btf::{BtfDir, BtfError, DIRECTIONS, Sampling, image_file_name, linear_to_srgb, write_btf_dir};
use common::{analytic, png_bytes, write_tiny_dir};

#[test]
fn round_trip_write_btf_dir_open_load_view() {
    let dir = tempfile::tempdir().unwrap();
    let (s, res) = (Sampling::H2, 16);
    let calls = std::sync::atomic::AtomicUsize::new(0);
    let progress = |done: usize, total: usize| {
        assert!(done <= total && total == DIRECTIONS * DIRECTIONS);
        calls.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    };
    write_btf_dir(
        dir.path(),
        s,
        res,
        |j, i| {
            (0..res * res)
                .map(|t| analytic(s, j, i, t % res, t / res, res))
                .collect()
        },
        Some(&progress),
    )
    .unwrap();
    assert_eq!(calls.into_inner(), DIRECTIONS * DIRECTIONS);
    // Only the 6,561 images remain (temporary files were renamed).
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        DIRECTIONS * DIRECTIONS
    );
    let btf = BtfDir::open(dir.path()).unwrap();
    assert_eq!((btf.sampling(), btf.width(), btf.height()), (s, res, res));
    assert!(
        btf.file(3, 4)
            .unwrap()
            .ends_with(image_file_name(s, 3, 4, "png"))
    );
    for j in [0, 19, 80] {
        let slot = btf.load_view(j).unwrap();
        for i in [0, 33, 80] {
            for (t, rgb) in slot.image(i).chunks_exact(3).enumerate() {
                let want = analytic(s, j, i, t % res, t / res, res);
                for c in 0..3 {
                    // 8-bit sRGB: within half a code after encoding.
                    let err =
                        (linear_to_srgb(rgb[c]) - linear_to_srgb(want[c].min(1.0))).abs() * 255.0;
                    assert!(
                        err <= 0.5 + 1e-3,
                        "slot {j} light {i} texel {t}: {err} codes"
                    );
                }
            }
        }
        assert_eq!(btf.load_image(j, 33).unwrap(), slot.image(33));
    }
}

#[test]
fn h1_names_with_underscores_and_a_prefix_are_accepted() {
    let dir = tempfile::tempdir().unwrap();
    let bytes = png_bytes(3, 2);
    for j in 0..DIRECTIONS {
        for i in 0..DIRECTIONS {
            let name = image_file_name(Sampling::H1, j, i, "PNG").replace(' ', "_");
            std::fs::write(dir.path().join(format!("WOOL_{name}")), &bytes).unwrap();
        }
    }
    std::fs::write(dir.path().join("README.txt"), "ignored").unwrap();
    std::fs::write(
        dir.path().join(".tl000 pl000 tv000 pv000.png.tmp"),
        "ignored",
    )
    .unwrap();
    let btf = BtfDir::open(dir.path()).unwrap();
    assert_eq!(
        (btf.sampling(), btf.width(), btf.height()),
        (Sampling::H1, 3, 2)
    );
    let px = btf.load_image(80, 80).unwrap();
    assert!((px[0] - linear_of(128)).abs() < 1e-6);
}

fn linear_of(code: u8) -> f32 {
    btf::srgb_to_linear(f32::from(code) / 255.0)
}

#[test]
fn missing_pair_names_the_expected_file() {
    let dir = tempfile::tempdir().unwrap();
    write_tiny_dir(dir.path(), Sampling::H1, 2, 2);
    let gone = image_file_name(Sampling::H1, 40, 7, "png");
    std::fs::remove_file(dir.path().join(&gone)).unwrap();
    let err = BtfDir::open(dir.path()).unwrap_err();
    assert!(
        matches!(
            err,
            BtfError::MissingImage {
                view: 40,
                light: 7,
                missing: 1,
                ..
            }
        ),
        "{err}"
    );
    assert!(err.to_string().contains(&gone), "{err}");
}

#[test]
fn duplicate_pair_names_both_files() {
    let dir = tempfile::tempdir().unwrap();
    write_tiny_dir(dir.path(), Sampling::H2, 2, 2);
    std::fs::write(
        dir.path().join("tl15_pl060_tv000_pv000.jpg"),
        png_bytes(2, 2),
    )
    .unwrap();
    let err = BtfDir::open(dir.path()).unwrap_err().to_string();
    assert!(
        err.contains("tl015 pl060 tv000 pv000.png") && err.contains("tl15_pl060_tv000_pv000.jpg"),
        "{err}"
    );
}

#[test]
fn mismatched_sizes_name_the_file_and_both_sizes() {
    let dir = tempfile::tempdir().unwrap();
    write_tiny_dir(dir.path(), Sampling::H1, 4, 4);
    let odd = image_file_name(Sampling::H1, 12, 50, "png");
    std::fs::write(dir.path().join(&odd), png_bytes(4, 3)).unwrap();
    let err = BtfDir::open(dir.path()).unwrap_err();
    let msg = err.to_string();
    assert!(matches!(
        err,
        BtfError::SizeMismatch {
            found_w: 4,
            found_h: 3,
            expected_w: 4,
            expected_h: 4,
            ..
        }
    ));
    assert!(
        msg.contains(&odd) && msg.contains("4 × 3") && msg.contains("4 × 4"),
        "{msg}"
    );
}

#[test]
fn bad_name_names_the_file() {
    let dir = tempfile::tempdir().unwrap();
    write_tiny_dir(dir.path(), Sampling::H1, 2, 2);
    std::fs::write(dir.path().join("tl017 pl060 tv000.png"), png_bytes(2, 2)).unwrap();
    let err = BtfDir::open(dir.path()).unwrap_err();
    assert!(matches!(err, BtfError::BadFileName { .. }));
    assert!(err.to_string().contains("tl017 pl060 tv000.png"), "{err}");
}

#[test]
fn unknown_or_mixed_theta_and_off_grid_phi_name_the_file() {
    let dir = tempfile::tempdir().unwrap();
    write_tiny_dir(dir.path(), Sampling::H1, 2, 2);
    let stray = dir.path().join("tl020 pl000 tv000 pv000.png");
    std::fs::write(&stray, png_bytes(2, 2)).unwrap();
    let err = BtfDir::open(dir.path()).unwrap_err().to_string();
    assert!(
        err.contains("tl020 pl000 tv000 pv000.png") && err.contains("20"),
        "{err}"
    );
    std::fs::remove_file(&stray).unwrap();

    let mixed = dir.path().join("tl015 pl000 tv000 pv000.png");
    std::fs::write(&mixed, png_bytes(2, 2)).unwrap();
    let err = BtfDir::open(dir.path()).unwrap_err().to_string();
    assert!(err.contains("H1") && err.contains("H2"), "{err}");
    std::fs::remove_file(&mixed).unwrap();

    let off_grid = dir.path().join("tl017 pl045 tv000 pv000.png");
    std::fs::write(&off_grid, png_bytes(2, 2)).unwrap();
    let err = BtfDir::open(dir.path()).unwrap_err();
    assert!(
        matches!(
            err,
            BtfError::NotADirection {
                theta: 17,
                phi: 45,
                ..
            }
        ),
        "{err}"
    );
    assert!(err.to_string().contains("tl017 pl045 tv000 pv000.png"));
}

#[test]
fn undecodable_header_names_the_file() {
    let dir = tempfile::tempdir().unwrap();
    write_tiny_dir(dir.path(), Sampling::H2, 2, 2);
    let name = image_file_name(Sampling::H2, 80, 0, "png");
    std::fs::write(dir.path().join(&name), b"\x89PNG\r\n\x1a\nnot really").unwrap();
    let err = BtfDir::open(dir.path()).unwrap_err();
    assert!(matches!(err, BtfError::Codec { .. }), "{err}");
    assert!(err.to_string().contains(&name), "{err}");
    assert!(BtfDir::open(dir.path().join("does-not-exist")).is_err());
    let empty = tempfile::tempdir().unwrap();
    assert!(matches!(
        BtfDir::open(empty.path()),
        Err(BtfError::EmptyDir { .. })
    ));
}

#[test]
fn exr_images_load_as_linear() {
    use exr::prelude::{Image, SpecificChannels, Vec2, WritableImage};
    let dir = tempfile::tempdir().unwrap();
    write_tiny_dir(dir.path(), Sampling::H1, 2, 2);
    let name = image_file_name(Sampling::H1, 3, 5, "png");
    std::fs::remove_file(dir.path().join(&name)).unwrap();
    let exr_path = dir.path().join(name.replace(".png", ".exr"));
    let values = [
        [0.125f32, 2.5, 0.0],
        [1.0, 0.5, 7.0],
        [0.01, 0.02, 0.03],
        [4.0, 3.0, 2.0],
    ];
    let channels = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
        let v = values[y * 2 + x];
        (v[0], v[1], v[2])
    });
    Image::from_channels((2, 2), channels)
        .write()
        .to_file(&exr_path)
        .unwrap();
    let btf = BtfDir::open(dir.path()).unwrap();
    let slot = btf.load_view(3).unwrap();
    assert_eq!(slot.image(5), values.concat().as_slice());
    assert!((slot.image(4)[0] - linear_of(128)).abs() < 1e-6);
}
