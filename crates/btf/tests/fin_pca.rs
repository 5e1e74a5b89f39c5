//! The fin BTF (thesis §5.7.2): the folder of 81 grazing-view images, its PCA (eq. 5.14 with
//! the mean) in a `.finpca` file, and the fragment colour of eq. 5.15 / Listing 5.1.

use btf::fin_pca::{
    ALPHA_CUT, FIN_SAMPLING, FinDir, FinPca, fin_alpha, fin_frame, fin_image_name, write_fin_dir,
};
use btf::render::{FinShading, fin_fragment};
use btf::{BtfError, BtfPca, BtfPcaParams, DIRECTIONS, Storage, ViewSlot};
use glam::Vec3;

const W: usize = 8;
const H: usize = 4;

/// An analytic fin set: fibres in alternate columns, dimmer towards the tips (row 0), lit by
/// cos θ_L plus a forward lobe towards −x (light behind the fibres), so the set has rank > 1.
fn texel(i: usize, x: usize, y: usize) -> [f32; 3] {
    let l = FIN_SAMPLING.vector(i);
    let cover = if x.is_multiple_of(2) { 1.0 } else { 0.3 } * (y + 1) as f32 / H as f32;
    let light = 0.25 * l.z + 0.2 * (-l.x).max(0.0);
    [0.9, 0.8, 0.6].map(|c| c * cover * light * (1.0 + 0.05 * x as f32))
}

fn images() -> ViewSlot {
    let data = (0..DIRECTIONS)
        .flat_map(|i| (0..H).flat_map(move |y| (0..W).flat_map(move |x| texel(i, x, y))))
        .collect();
    ViewSlot::new(0, W, H, data).unwrap()
}

fn exact_params(components: usize) -> BtfPcaParams {
    BtfPcaParams {
        components,
        storage: Storage::F32,
        mean_storage: Storage::F32,
        ..Default::default()
    }
}

#[test]
fn all_components_reconstruct_every_image_and_the_file_round_trips_bit_for_bit() {
    // Rank ≤ 80 after centring: asking for 81 keeps every component.
    let fins = FinPca::from_images(&images(), &exact_params(81)).unwrap();
    for i in 0..DIRECTIONS {
        let image = fins.image(i);
        for y in 0..H {
            for x in 0..W {
                let want = texel(i, x, y);
                let got = image[y * W + x];
                for c in 0..3 {
                    assert!(
                        (got[c] - want[c]).abs() < 2e-6,
                        "light {i} texel ({x}, {y}): {got:?} vs {want:?}"
                    );
                }
            }
        }
    }
    let back = FinPca::from_bytes(&fins.to_bytes()).unwrap();
    assert_eq!(back, fins);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("wool.finpca");
    fins.write(&path).unwrap();
    assert_eq!(FinPca::read(&path).unwrap(), fins);
}

#[test]
fn a_light_at_a_measured_direction_gives_that_image_and_the_default_c_is_16() {
    let fins = FinPca::from_images(&images(), &BtfPcaParams::default()).unwrap();
    assert_eq!(fins.requested_components(), 16);
    // The analytic set has rank 2 after centring: 16 asked, the rank kept.
    assert!(fins.slot().components() <= 16);
    for i in [0, 5, 30, 80] {
        let gamma = fins.gamma(FIN_SAMPLING.vector(i));
        for (x, y) in [(0, 0), (3, 2), (7, 3)] {
            let got = fins.texel(&gamma, x, y);
            let want = texel(i, x, y);
            for c in 0..3 {
                // u8 eigen-images, u16 mean: a few codes of the value range.
                assert!((got[c] - want[c]).abs() < 4e-3, "{i} {x} {y}");
            }
        }
    }
}

#[test]
fn fin_files_are_validated_like_btfpca_files() {
    let fins = FinPca::from_images(&images(), &BtfPcaParams::default()).unwrap();
    let bytes = fins.to_bytes();
    // A .btfpca is refused by its signature.
    let btf = common_btf();
    match FinPca::from_bytes(&btf.to_bytes()) {
        Err(BtfError::FinFormat { field, .. }) => assert_eq!(field, "magic"),
        other => panic!("{other:?}"),
    }
    // And a .finpca as a .btfpca (shorter than its 81-slot header, or the wrong signature).
    assert!(matches!(
        BtfPca::from_bytes(&bytes),
        Err(BtfError::Format {
            field: "magic" | "length",
            ..
        })
    ));
    // Every truncation and many single-byte edits fail cleanly, naming a field.
    for len in (0..bytes.len()).step_by(7) {
        assert!(FinPca::from_bytes(&bytes[..len]).is_err());
    }
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    for _ in 0..400 {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let at = (state >> 33) as usize % bytes.len();
        let mut edited = bytes.clone();
        edited[at] ^= 1 + (state >> 59) as u8;
        match FinPca::from_bytes(&edited) {
            Err(BtfError::FinFormat { .. }) => {}
            other => panic!("edit at {at}: {other:?}"),
        }
    }
}

fn common_btf() -> BtfPca {
    let s = btf::Sampling::H2;
    let load = |j| ViewSlot::new(j, 1, 1, vec![0.25; 3 * DIRECTIONS]);
    BtfPca::compress_with(s, 1, 1, &BtfPcaParams::default(), load, None)
        .unwrap()
        .0
}

#[test]
fn a_written_folder_opens_and_loads_within_8_bit_rounding() {
    let dir = tempfile::tempdir().unwrap();
    let set = images();
    write_fin_dir(dir.path(), W, H, |i| {
        set.image(i)
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect()
    })
    .unwrap();
    assert!(dir.path().join("tl045 pl200 tv090 pv000.png").is_file());
    let fin_dir = FinDir::open(dir.path()).unwrap();
    assert_eq!((fin_dir.width(), fin_dir.height()), (W, H));
    let loaded = fin_dir.load().unwrap();
    for (a, b) in loaded.data().iter().zip(set.data()) {
        // 8-bit sRGB: steps of at most 1/255 · (1/12.92)⁻¹ … well under 0.01 here.
        assert!((a - b).abs() < 6e-3, "{a} vs {b}");
    }
    // A missing light and a file of another view are named.
    std::fs::remove_file(dir.path().join(fin_image_name(12, "png"))).unwrap();
    match FinDir::open(dir.path()) {
        Err(e @ BtfError::FinDir { .. }) => {
            let text = e.to_string();
            assert!(text.contains("1 of the 81"), "{text}");
            assert!(text.contains(&fin_image_name(12, "png")), "{text}");
        }
        other => panic!("{other:?}"),
    }
    std::fs::copy(
        dir.path().join(fin_image_name(0, "png")),
        dir.path().join("tl030 pl030 tv075 pv000.png"),
    )
    .unwrap();
    match FinDir::open(dir.path()) {
        Err(e @ BtfError::FinDir { .. }) => {
            assert!(e.to_string().contains("tv075"), "{e}");
            assert!(e.to_string().contains("not the grazing"), "{e}");
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn the_fragment_is_listing_5_1_with_premultiplied_colour() {
    let fins = FinPca::from_images(&images(), &exact_params(81)).unwrap();
    let g1 = fins.gamma(FIN_SAMPLING.vector(0));
    let g2 = fins.gamma(FIN_SAMPLING.vector(40));
    let radiance = Vec3::new(2.0, 1.5, 1.0);
    let shading = FinShading::default();
    // s = 2.3 wraps to column 2; t = 0.9 is row 0 (the tips); half way between the ends.
    let got = fin_fragment(&fins, [&g1, &g2], radiance, [2.3, 0.9], 0.5, &shading);
    let (x, y) = (2, 0);
    let mut want = [0.0f32; 4];
    for i in [0, 40] {
        let t = texel(i, x, y);
        let rgb = [0.5 * 2.0 * t[0], 0.5 * 1.5 * t[1], 0.5 * t[2]];
        let a = rgb.iter().sum::<f32>();
        if a >= ALPHA_CUT {
            (0..3).for_each(|c| want[c] += rgb[c]);
            want[3] += a;
        }
    }
    for c in 0..4 {
        assert!((got[c] - want[c]).abs() < 1e-5, "{got:?} vs {want:?}");
    }
    // A dim end below the cut adds neither colour nor alpha.
    let dim = fin_fragment(
        &fins,
        [&g1, &g1],
        Vec3::splat(1e-3),
        [0.0, 0.1],
        0.0,
        &shading,
    );
    assert_eq!(dim, [0.0; 4]);
    assert_eq!(fin_alpha([0.5, 0.4, 0.3], ALPHA_CUT), 1.0);
    assert_eq!(fin_alpha([0.01, 0.01, 0.01], ALPHA_CUT), 0.0);
}

#[test]
fn the_fin_frame_puts_the_viewer_at_phi_0_and_the_normal_at_z() {
    let n = Vec3::new(0.0, 0.0, 2.0);
    let [x, y, z] = fin_frame(n, Vec3::new(3.0, 4.0, 7.0)).unwrap();
    assert!((x - Vec3::new(0.6, 0.8, 0.0)).length() < 1e-6);
    assert!((z - Vec3::Z).length() < 1e-6);
    assert!((y - z.cross(x)).length() < 1e-6);
    // Viewer along the normal: any tangent, still orthonormal.
    let [x, y, _] = fin_frame(Vec3::Y, Vec3::Y).unwrap();
    assert!(x.dot(Vec3::Y).abs() < 1e-6 && (x.cross(y) - Vec3::Y).length() < 1e-6);
    assert!(fin_frame(Vec3::ZERO, Vec3::X).is_none());
}
