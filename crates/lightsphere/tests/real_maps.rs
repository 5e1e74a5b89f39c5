//! On the four real Poly Haven maps: Σ_j I_j·ω_j matches ∫L dω within 1 % for levels 0–5
//! with CellMean, against references computed without any cell assignment; and the power
//! error of the seed's prefiltered look-up is printed per level (run with `--nocapture`).

mod common;

use common::{bilinear_power, texel_power};
use lightsphere::{Environment, Lightsphere, RadianceMethod, matched_sigma_deg};

const MAPS: [&str; 4] = [
    "env/venice_sunset_1k.hdr",
    "env/studio_small_03_1k.hdr",
    "env/st_fagans_interior_1k.hdr",
    "env/kiara_1_dawn_1k.hdr",
];

fn max_abs_relative(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3)
        .map(|c| ((a[c] - b[c]) / b[c]).abs())
        .fold(0.0, f64::max)
}

#[test]
fn cell_mean_power_matches_the_integral_on_real_maps() {
    for name in MAPS {
        let Some(path) = test_data::shared_file(name) else {
            return;
        };
        let env = Environment::load(&path).unwrap();
        let per_texel = texel_power(&env);
        // A second, smoother reference: the bilinear map integrated with 2×2 supersampling.
        let bilinear = bilinear_power(&env, 2);
        let smooth_vs_texel = max_abs_relative(bilinear, per_texel);
        assert!(
            smooth_vs_texel < 0.01,
            "{name}: references disagree by {smooth_vs_texel}"
        );
        for level in 0..=5 {
            let s = Lightsphere::new(level).unwrap();
            let i = env
                .radiance_per_direction(&s, RadianceMethod::CellMean)
                .unwrap();
            assert!(i.iter().all(|v| v.is_finite()));
            let p = s.power(&i).unwrap();
            let e_texel = max_abs_relative(p, per_texel);
            let e_bilinear = max_abs_relative(p, bilinear);
            assert!(e_texel < 1e-5, "{name} level {level}: {e_texel}");
            assert!(e_bilinear < 0.01, "{name} level {level}: {e_bilinear}");
            println!(
                "{name} level {level}: CellMean power error {e_texel:.1e} (texel sum), {e_bilinear:.1e} (bilinear quadrature)"
            );
        }
    }
}

#[test]
fn prefiltered_lookup_power_error_per_level() {
    let Some(path) = test_data::shared_file(MAPS[0]) else {
        return;
    };
    let env = Environment::load(&path).unwrap();
    let exact = texel_power(&env);
    for level in 0..=5 {
        let s = Lightsphere::new(level).unwrap();
        let sigma = matched_sigma_deg(s.len());
        let i = env
            .radiance_per_direction(&s, RadianceMethod::PrefilteredLookup { sigma_deg: sigma })
            .unwrap();
        let p = s.power(&i).unwrap();
        let e: Vec<f64> = (0..3).map(|c| p[c] / exact[c] - 1.0).collect();
        println!(
            "{} level {level} (k = {}, σ = {sigma:.2}°): PrefilteredLookup power error R {:+.4} G {:+.4} B {:+.4}",
            MAPS[0],
            s.len(),
            e[0],
            e[1],
            e[2]
        );
        assert!(e.iter().all(|v| v.is_finite() && v.abs() < 0.5), "{e:?}");
    }
}
