//! Radiance per light direction I_j: power preservation, constant maps, rotation semantics.

mod common;

use common::{assert_close, assert_rel3, test_map, texel_power};
use glam::{Quat, Vec3};
use lightsphere::{
    CellMeanParams, CellNormalization, Environment, Lightsphere, LightsphereError, RadianceMethod,
};

#[test]
fn cell_mean_preserves_power_at_every_level() {
    let env = test_map(64, 32, 31).with_rotation(Quat::from_rotation_z(0.8));
    let exact = texel_power(&env);
    for level in 0..=5 {
        let s = Lightsphere::new(level).unwrap();
        let i = env
            .radiance_per_direction(&s, RadianceMethod::CellMean)
            .unwrap();
        assert!(i.iter().all(|v| v.is_finite() && v.min_element() >= 0.0));
        assert_rel3(s.power(&i).unwrap(), exact, 1e-6, &format!("level {level}"));
    }
}

#[test]
fn constant_map_gives_constant_radiance() {
    let env = Environment::from_latlong(128, 64, vec![[0.5, 1.0, 2.0]; 128 * 64]).unwrap();
    for level in 0..=4 {
        let s = Lightsphere::new(level).unwrap();
        let sampled = CellMeanParams {
            normalization: CellNormalization::SampledSolidAngle,
            ..CellMeanParams::default()
        };
        let cm = env.cell_mean(&s, &sampled).unwrap();
        assert_eq!(cm.empty_cells, 0);
        for v in &cm.radiance {
            assert!(
                (*v - Vec3::new(0.5, 1.0, 2.0)).abs().max_element() < 1e-5,
                "level {level}: {v}"
            );
        }
        // With the exact ω_j the values differ only by the sampling error of the cell area.
        let cm = env.cell_mean(&s, &CellMeanParams::default()).unwrap();
        for (j, (v, a)) in cm.radiance.iter().zip(&cm.sampled_solid_angle).enumerate() {
            let w = s.solid_angles()[j];
            assert_close(f64::from(v.y), a / w, 1e-5, "I_j = L·(sampled area/ω_j)");
            assert_close(
                a / w,
                1.0,
                0.1,
                &format!("sampled area of cell {j} at level {level}"),
            );
        }
        let prefiltered = env
            .radiance_per_direction(
                &s,
                RadianceMethod::PrefilteredLookup {
                    sigma_deg: lightsphere::matched_sigma_deg(s.len()),
                },
            )
            .unwrap();
        for v in &prefiltered {
            assert!(
                (*v - Vec3::new(0.5, 1.0, 2.0)).abs().max_element() < 1e-4,
                "{v}"
            );
        }
    }
}

/// Rotating the map by q and the lightsphere by q leaves every I_j unchanged.
#[test]
fn rotating_map_and_sphere_together_changes_nothing() {
    let env = test_map(64, 32, 5);
    let q = Quat::from_euler(glam::EulerRot::ZYX, 0.3, 1.2, -0.4);
    let s = Lightsphere::new(3).unwrap();
    let a = env
        .radiance_per_direction(&s, RadianceMethod::CellMean)
        .unwrap();
    let b = env
        .clone()
        .with_rotation(q)
        .radiance_per_direction(&s.rotated(q), RadianceMethod::CellMean)
        .unwrap();
    for (j, (x, y)) in a.iter().zip(&b).enumerate() {
        assert!(
            (*x - *y).abs().max_element() <= 2e-3 * x.max_element(),
            "direction {j}: {x} vs {y}"
        );
    }
    // The seed's look-up: rotating the map alone equals looking up rotated directions.
    let method = RadianceMethod::PrefilteredLookup { sigma_deg: 8.0 };
    let moved = env
        .clone()
        .with_rotation(q)
        .radiance_per_direction(&s.rotated(q), method)
        .unwrap();
    let still = env.radiance_per_direction(&s, method).unwrap();
    for (x, y) in moved.iter().zip(&still) {
        assert!((*x - *y).abs().max_element() <= 1e-4 * x.max_element());
    }
}

#[test]
fn supersampling_is_chosen_from_the_cell_size() {
    let env = test_map(64, 32, 2);
    let s = Lightsphere::new(4).unwrap();
    let cm = env.cell_mean(&s, &CellMeanParams::default()).unwrap();
    // 256 samples per cell × 1026 cells over 2048 texels → s = ⌈√128.25⌉ = 12.
    assert_eq!(cm.supersampling, 12);
    let fixed = CellMeanParams {
        supersampling: Some(2),
        ..CellMeanParams::default()
    };
    assert_eq!(env.cell_mean(&s, &fixed).unwrap().supersampling, 2);
    let zero = CellMeanParams {
        supersampling: Some(0),
        ..CellMeanParams::default()
    };
    assert!(matches!(
        env.cell_mean(&s, &zero),
        Err(LightsphereError::InvalidParameter {
            name: "supersampling",
            ..
        })
    ));
}

#[test]
fn power_helpers_check_lengths() {
    let env = test_map(8, 4, 2);
    let s = Lightsphere::new(1).unwrap();
    assert!(matches!(
        s.power(&[Vec3::ONE; 3]),
        Err(LightsphereError::RadianceCount {
            expected: 18,
            actual: 3
        })
    ));
    assert!(env.relative_power_error(&s, &[]).is_err());
    let i = env
        .radiance_per_direction(&s, RadianceMethod::CellMean)
        .unwrap();
    let e = env.relative_power_error(&s, &i).unwrap();
    assert!(e.iter().all(|v| v.abs() < 1e-6), "{e:?}");
}

/// The defining identity of the light term: an unoccluded vertex under a constant sky gets
/// Σ_j max(0, n·l_j)·ω_j·L = πL (cosine-weighted hemisphere), for any normal.
#[test]
fn light_weights_give_pi_for_an_open_vertex() {
    let env = Environment::from_latlong(64, 32, vec![[1.0; 3]; 64 * 32]).unwrap();
    let mut rng = common::Rng::new(9);
    for level in [2, 4, 5] {
        let s = Lightsphere::new(level).unwrap();
        let i = env
            .radiance_per_direction(&s, RadianceMethod::CellMean)
            .unwrap();
        let weights = s.light_weights(&i).unwrap();
        for _ in 0..20 {
            let n = rng.unit();
            let e: f64 = s
                .directions_f64()
                .iter()
                .zip(&weights)
                .map(|(l, w)| n.dot(*l).max(0.0) * f64::from(w.y))
                .sum();
            // Discretisation error of the hemisphere's cosine lobe falls with k.
            let tolerance = 3.0 / s.len() as f64 + 0.01;
            assert_close(
                e,
                std::f64::consts::PI,
                tolerance * std::f64::consts::PI,
                &format!("level {level} n {n}"),
            );
        }
    }
    assert!(
        Lightsphere::new(1)
            .unwrap()
            .light_weights(&[Vec3::ONE])
            .is_err()
    );
}
