//! Shading of the procedural wool fin BTF, checked through the public API: exact oracles
//! on hand-built strands (straight fibres for the Kajiya–Kay and forward terms, a roof of
//! fibres casting a shadow) and statistics of the generated fur.

mod wool_fins_support;

use glam::Vec3;
use synth::{FinImage, WoolFinParams};
use wool_fins_support::*;

#[test]
fn diffuse_and_forward_terms_match_the_exact_oracle() {
    // No shadowing: every covered sub-sample contributes ρ·(k_d √(1 − (t·l)²) + k_f f(l)),
    // so a pixel of a single straight strand is exactly alpha times that.
    let base = WoolFinParams {
        width: 64,
        height: 64,
        shadow_sigma: 0.0,
        ..Default::default()
    };
    let (vertical_colour, tilted_colour) = (Vec3::new(0.8, 0.7, 0.55), Vec3::new(0.3, 0.5, 0.9));
    let tilt = 30f32.to_radians();
    let strands = vec![
        straight(
            Vec3::new(-0.1, 0.25, 0.0),
            Vec3::new(-0.1, 0.25, 0.9),
            10,
            0.01,
            vertical_colour,
        ),
        straight(
            Vec3::new(-0.2, 0.6, 0.0),
            Vec3::new(-0.2, 0.6 + 0.6 * tilt.sin(), 0.6 * tilt.cos()),
            10,
            0.01,
            tilted_colour,
        ),
    ];
    let tangents = [Vec3::Z, Vec3::new(0.0, tilt.sin(), tilt.cos())];
    for (k_d, k_f) in [(0.7, 0.0), (0.0, 1.0), (0.6, 0.4)] {
        let params = WoolFinParams {
            diffuse_weight: k_d,
            forward_weight: k_f,
            forward_exponent: 4.0,
            ..base
        };
        let fin = custom(&params, strands.clone());
        for (theta, phi) in [
            (0.0, 0.0),
            (40.0, 90.0),
            (60.0, 0.0),
            (75.0, 180.0),
            (89.0, 200.0),
        ] {
            let l = dir(theta, phi);
            let image = fin.image(l);
            let forward = k_f * (-l.x).max(0.0).powi(4);
            let mut checked = [0, 0];
            for row in 0..64 {
                for column in 0..64 {
                    let p = image.pixel(column, row).unwrap();
                    if p[3] == 0.0 {
                        continue;
                    }
                    // The vertical strand covers columns ≈ 16, the tilted one 38 ..= 58.
                    let s = usize::from(column > 27);
                    let colour = [vertical_colour, tilted_colour][s];
                    let kajiya_kay = (1.0 - tangents[s].dot(l).powi(2)).max(0.0).sqrt();
                    let expected = p[3] * (k_d * kajiya_kay + forward) * colour;
                    for c in 0..3 {
                        assert!(
                            (p[c] - expected[c]).abs() <= 1e-5 * (1.0 + expected[c]),
                            "({theta}, {phi}), k_d {k_d}, k_f {k_f}, pixel ({column}, {row}): {p:?} vs {expected}"
                        );
                    }
                    checked[s] += 1;
                }
            }
            assert!(checked[0] > 30 && checked[1] > 30, "{checked:?}");
        }
        // A vertical fibre under an overhead light reflects nothing diffusely (t ∥ l), and
        // the forward lobe is dark for a light on the viewer's side.
        let overhead = fin.image(Vec3::Z);
        if k_f == 0.0 {
            assert!((0..64).all(|row| overhead.pixel(16, row).unwrap()[..3] == [0.0; 3]));
        }
        if k_d == 0.0 {
            assert!(
                fin.image(dir(60.0, 0.0))
                    .rgba
                    .iter()
                    .all(|p| p[..3] == [0.0; 3])
            );
        }
    }
}

#[test]
fn back_light_scatters_forward() {
    let params = WoolFinParams::default();
    let fin = fins(&params);
    let mean = |image: &FinImage| band_mean(image, (0, image.height), luminance);
    let front = fin.image(dir(75.0, 0.0));
    let back = fin.image(dir(75.0, 180.0));
    assert!(
        mean(&back) > 1.15 * mean(&front),
        "{} vs {}",
        mean(&back),
        mean(&front)
    );
    // Strongest at the tips, where the back light is least shadowed: a bright rim.
    let top = |image: &FinImage| band_mean(image, (0, image.height / 2), luminance);
    assert!(
        top(&back) > 1.5 * top(&front),
        "{} vs {}",
        top(&back),
        top(&front)
    );

    // Without the lobe, light from behind is no brighter than light from the front.
    let diffuse_only = fins(&WoolFinParams {
        forward_weight: 0.0,
        shadow_sigma: 0.0,
        ..params
    });
    let (f, b) = (
        mean(&diffuse_only.image(dir(75.0, 0.0))),
        mean(&diffuse_only.image(dir(75.0, 180.0))),
    );
    assert!((b / f - 1.0).abs() < 0.05, "{b} vs {f}");
}

#[test]
fn self_shadowing_darkens_the_base() {
    let base = WoolFinParams::default();
    let ratio = |sigma: f32, phi: f64| {
        let fin = fins(&WoolFinParams {
            shadow_sigma: sigma,
            ..base
        });
        let image = fin.image(dir(60.0, phi));
        // Radiance per covered area, so that the coverage profile cancels.
        let per_alpha = |rows| {
            band_mean(&image, rows, luminance) / band_mean(&image, rows, |p| f64::from(p[3]))
        };
        per_alpha(bottom_quarter(&image)) / per_alpha((image.height / 4, image.height / 2))
    };
    // Light from the viewer's side leaves the layer through its front at once; light from
    // the side or from behind crosses the dense base.
    for (phi, most) in [(0.0, 0.9), (90.0, 0.6), (180.0, 0.75)] {
        let (none, default, dense) = (ratio(0.0, phi), ratio(0.5, phi), ratio(2.0, phi));
        assert!((none - 1.0).abs() < 0.05, "φ {phi}: {none}");
        assert!(default < most * none, "φ {phi}: {default} vs {none}");
        assert!(dense < 0.8 * default, "φ {phi}: {dense} vs {default}");
    }
}

#[test]
fn a_roof_of_fibres_shadows_what_lies_below_it() {
    let params = WoolFinParams {
        width: 64,
        height: 64,
        diffuse_weight: 1.0,
        forward_weight: 0.0,
        shadow_sigma: 2.0,
        ..Default::default()
    };
    let white = Vec3::ONE;
    // Strand 0: tilted along y, in front (x = 0), from the base to beyond the image's top.
    let mut strands = vec![straight(
        Vec3::new(0.0, 0.3, 0.0),
        Vec3::new(0.0, 0.5, 1.2),
        16,
        0.015,
        white,
    )];
    // A roof at z = 0.6: 40 fibres along y spread over x ∈ [−0.1, 0.1].
    for k in 0..40 {
        let x = -0.1 + 0.2 * (k as f32 + 0.5) / 40.0;
        strands.push(straight(
            Vec3::new(x, -0.25, 0.6),
            Vec3::new(x, 1.25, 0.6),
            12,
            0.01,
            white,
        ));
    }
    let fin = custom(&params, strands);
    let light = Vec3::Z;
    let image = fin.image(light);
    let tangent = Vec3::new(0.0, 0.2, 1.2).normalize();
    let unshadowed = (1.0 - tangent.dot(light).powi(2)).sqrt();
    let (mut below, mut above) = (0, 0);
    for row in 0..64 {
        let z = (64 - row) as f32 / 64.0;
        // The strand's pixels in this row: its axis is at y = 0.3 + 0.2 z/0.9.
        let centre = ((0.3 + 0.2 * z / 1.2) * 64.0) as usize;
        for column in centre - 2..=centre + 2 {
            let p = image.pixel(column, row).unwrap();
            if p[3] == 0.0 {
                continue;
            }
            let radiance = p[0] / p[3];
            if z < 0.45 {
                below += 1;
                assert!(
                    radiance < 0.25 * unshadowed,
                    "row {row}: {radiance} vs {unshadowed}"
                );
            } else if z > 0.72 {
                // Nothing above but the strand itself, which never shadows itself.
                above += 1;
                assert!(
                    (radiance - unshadowed).abs() < 1e-5,
                    "row {row}: {radiance} vs {unshadowed}"
                );
            }
        }
    }
    assert!(below > 20 && above > 10, "{below} {above}");
    // Without σ nothing is shadowed.
    let clear = custom(
        &WoolFinParams {
            shadow_sigma: 0.0,
            ..params
        },
        fin.strands().to_vec(),
    )
    .image(light);
    let centre = ((0.3 + 0.2 * 0.2 / 1.2) * 64.0) as usize;
    let p = (centre - 2..=centre + 2)
        .map(|column| clear.pixel(column, 51).unwrap())
        .find(|p| p[3] > 0.0)
        .expect("the strand crosses row 51");
    assert!((p[0] / p[3] - unshadowed).abs() < 1e-5);
}
