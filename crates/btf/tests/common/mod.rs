//! An analytic BTF for tests: a per-texel albedo, shifted by the view direction, times the
//! light's cosine, plus a texel-dependent lobe toward +x so that a slot has rank > 1.
#![allow(dead_code)]

use std::path::Path;

use btf::{BtfPca, BtfPcaParams, DIRECTIONS, Sampling, ViewSlot};

/// Linear RGB of (view slot j, light i, texel x, y) of the analytic BTF.
pub fn analytic(s: Sampling, j: usize, i: usize, x: usize, y: usize, res: usize) -> [f32; 3] {
    let v = s.vector(j);
    let l = s.vector(i);
    // The view shifts the texture (parallax of a mesostructure) and brightens grazing views.
    let shift = (3.0 * v.x) as isize;
    let xs = (x as isize + shift).rem_euclid(res as isize) as usize;
    let albedo = |ch: usize| 0.15 + 0.6 * ((xs * 7 + y * 13 + ch * 5) % 17) as f32 / 17.0;
    let cos = l.z.max(0.0);
    let lobe = 0.3 * ((xs + 2 * y) % 5) as f32 / 5.0 * l.x.max(0.0);
    let gain = 1.0 + 0.2 * (1.0 - v.z);
    [0, 1, 2].map(|ch| (albedo(ch) * cos + lobe) * gain * 0.8)
}

/// View slot j of the analytic BTF at res × res.
pub fn analytic_slot(s: Sampling, j: usize, res: usize) -> ViewSlot {
    let mut data = Vec::with_capacity(DIRECTIONS * 3 * res * res);
    for i in 0..DIRECTIONS {
        for y in 0..res {
            for x in 0..res {
                data.extend(analytic(s, j, i, x, y, res));
            }
        }
    }
    ViewSlot::new(j, res, res, data).expect("valid analytic slot")
}

/// The analytic BTF compressed with `params`.
pub fn analytic_pca(s: Sampling, res: usize, params: &BtfPcaParams) -> BtfPca {
    let (pca, _) =
        BtfPca::compress_with(s, res, res, params, |j| Ok(analytic_slot(s, j, res)), None)
            .expect("compress");
    pca
}

/// Writes a BTF folder fast: one tiny PNG encoded once, copied to every name (no fsync).
pub fn write_tiny_dir(dir: &Path, s: Sampling, w: u32, h: u32) {
    let bytes = png_bytes(w, h);
    for j in 0..DIRECTIONS {
        for i in 0..DIRECTIONS {
            std::fs::write(dir.join(btf::image_file_name(s, j, i, "png")), &bytes).unwrap();
        }
    }
}

/// A grey w × h PNG in memory.
pub fn png_bytes(w: u32, h: u32) -> Vec<u8> {
    use image::ImageEncoder;
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(
            &vec![128u8; (3 * w * h) as usize],
            w,
            h,
            image::ExtendedColorType::Rgb8,
        )
        .unwrap();
    out
}

/// |a − b| ≤ tol, with a message naming the quantity.
#[track_caller]
pub fn assert_close(a: f64, b: f64, tol: f64, what: &str) {
    assert!((a - b).abs() <= tol, "{what}: {a} vs {b} (tolerance {tol})");
}
