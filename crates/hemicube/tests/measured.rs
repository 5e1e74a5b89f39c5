//! The measured-direction channel (thesis §5.5.2, Fig. 5.12): four of the 81 directions of
//! Table 5.1 per pixel, weights summing to 1, and the per-direction split of a vertex's light
//! adding up to its radiance.

mod common;

use btf::sampling::Sampling;
use common::*;
use glam::Vec3;
use hemicube::lighting::radiance_from;
use hemicube::{BuildParams, MeasuredChannel, Model, RingSpacing, build_with_rays};

#[test]
fn every_pixel_gets_at_most_four_measured_directions_weighing_one() {
    for model in [
        Model::Hemicube { res: 16 },
        Model::SinglePlane {
            res: 9,
            aperture_deg: 150.0,
        },
        Model::Hemisphere {
            phi: 32,
            theta: 8,
            spacing: RingSpacing::EqualTheta,
        },
    ] {
        let layout = layout(model);
        for sampling in Sampling::ALL {
            let channel = MeasuredChannel::new(&layout, sampling);
            for p in 0..layout.len() {
                let w = channel.pixel(p);
                assert!(w.len() <= 4);
                assert!(
                    (w.sum() - 1.0).abs() < 1e-5,
                    "{model:?} pixel {p}: {}",
                    w.sum()
                );
                assert!(w.iter().all(|(i, x)| i < 81 && x >= 0.0));
            }
        }
    }
    // The centre pixel of an odd single plane looks along the normal: the pole, weight 1.
    let sp = layout(Model::SinglePlane {
        res: 9,
        aperture_deg: 150.0,
    });
    let channel = MeasuredChannel::new(&sp, Sampling::H2);
    let centre: Vec<(usize, f32)> = channel.pixel(40).iter().filter(|(_, w)| *w > 0.0).collect();
    assert_eq!(centre, vec![(0, 1.0)]);
}

#[test]
fn per_direction_light_sums_to_the_vertex_radiance() {
    let roof = sheet(
        Vec3::new(-0.5, 0.6, 0.5),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 0.0, -1.0),
        2,
    );
    let (maps, _) = build_with_rays(
        &scene(floor(2.0, 4), &[roof]),
        layout(Model::Hemicube { res: 16 }),
        &BuildParams::default(),
    )
    .unwrap();
    let sky = |d: Vec3| Vec3::new(1.0 + d.x.max(0.0), 0.5 + d.y, 2.0 - d.z);
    let total = radiance_from(&maps, Vec3::ONE, sky);
    let channel = MeasuredChannel::new(maps.layout(), Sampling::H1);
    let split = channel.per_direction_radiance(&maps, sky);
    assert_eq!(split.len(), maps.len() * 81);
    for (i, t) in total.iter().enumerate() {
        let sum: Vec3 = split[i * 81..(i + 1) * 81].iter().copied().sum();
        assert!(
            (sum - *t).abs().max_element() < 1e-5,
            "vertex {i}: {sum} vs {t}"
        );
    }
}
