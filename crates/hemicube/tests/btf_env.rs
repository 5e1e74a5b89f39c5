//! BTFs under environment light through static visibility maps (thesis §5.5.2, eq. 5.10):
//! the light channel equals the direct sum over each map's open pixels (mirrored tangent
//! frames included), a Lambertian BTF under a uniform sky with nothing in the way reflects ρL,
//! and the maps and occlusion-gpu's visibility matrix M give the same W — the same integral,
//! two discretisations — within the error measured here.

mod common;

use btf::Sampling;
use btf::env::{EnvLightWeights, EnvTransfer, relative_error};
use common::*;
use glam::Vec3;
use hemicube::{
    BtfLightChannel, BuildParams, Model, VertexFrame, VisibilityMaps, build_with_frames,
};
use occlusion_gpu::{RayCaster, Scene};

#[path = "../../btf/tests/common/env.rs"]
mod btf_env_common;

/// A floor under a tilted roof.
fn roofed() -> Scene {
    let roof = sheet(
        Vec3::new(-0.6, 0.5, 0.6),
        Vec3::new(1.2, 0.3, 0.0),
        Vec3::new(0.0, 0.0, -1.2),
        3,
    );
    scene(floor(2.0, 6), &[roof])
}

/// Per receiver vertex: the BTF tangent frame (t, ±n × t, n) turned by the vertex index, and
/// every third one mirrored.
fn tangent_frames(caster: &RayCaster) -> Vec<([Vec3; 3], bool)> {
    caster
        .receivers()
        .enumerate()
        .map(|(i, (_, n))| {
            let t0 = n.any_orthonormal_vector();
            let a = 0.7 * i as f32;
            let t = t0 * a.cos() + n.cross(t0) * a.sin();
            let mirrored = i % 3 == 0;
            let b = if mirrored { -n.cross(t) } else { n.cross(t) };
            ([t, b, n], mirrored)
        })
        .collect()
}

fn maps_in_tangent_frames(scene: &Scene, model: Model) -> (VisibilityMaps, Vec<([Vec3; 3], bool)>) {
    let caster = RayCaster::new(scene).unwrap();
    let frames = tangent_frames(&caster);
    let map_frames = frames
        .iter()
        .map(|([t, _, n], _)| Some(VertexFrame::from_normal_tangent(*n, *t)))
        .collect();
    let (maps, _) = build_with_frames(
        &caster,
        layout(model),
        &BuildParams::default(),
        map_frames,
        &|_| {},
    );
    (maps, frames)
}

fn sky(d: Vec3) -> Vec3 {
    Vec3::new(1.0 + d.x.max(0.0), 0.5 + d.y.abs(), 2.0 - d.z)
}

#[test]
fn the_light_channel_is_the_direct_sum_over_open_pixels_mirrored_frames_included() {
    let (maps, frames) = maps_in_tangent_frames(&roofed(), Model::Hemicube { res: 12 });
    let channel = BtfLightChannel::new(maps.layout(), Sampling::H2);
    let mirrored: Vec<bool> = frames.iter().map(|f| f.1).collect();
    let fast = channel.light_weights(&maps, &mirrored, sky);
    let dirs = maps.layout().directions();
    let omegas = maps.layout().solid_angles();
    let mut some_shadowed = false;
    for (i, w) in fast.iter().enumerate() {
        let frame = maps.frame(i).unwrap();
        let open: Vec<usize> = maps.open_pixels(i).collect();
        some_shadowed |= open.len() < maps.layout().len();
        let world: Vec<Vec3> = open.iter().map(|&p| frame.to_world(dirs[p])).collect();
        let l: Vec<Vec3> = open
            .iter()
            .zip(&world)
            .map(|(&p, &d)| sky(d) * omegas[p])
            .collect();
        let mut direct = EnvLightWeights::default();
        direct.add_samples(Sampling::H2, frames[i].0, &world, &l, |_| true);
        for (a, b) in w.weights.iter().zip(&direct.weights) {
            assert!(
                (*a - *b).abs().max_element() <= 2e-5 * (1.0 + b.abs().max_element()),
                "vertex {i}: {a} vs {b}"
            );
        }
    }
    assert!(some_shadowed, "the roof shadows some of the floor");
}

#[test]
fn a_lambertian_btf_under_a_uniform_sky_with_nothing_in_the_way_reflects_rho_l() {
    let (pca, lam) = btf_env_common::lambertian(Sampling::H1);
    let floor = scene(floor(2.0, 2), &[]);
    let l = Vec3::new(1.0, 0.8, 0.6);
    for model in [
        Model::Hemicube { res: 32 },
        Model::Hemisphere {
            phi: 64,
            theta: 16,
            spacing: hemicube::RingSpacing::EqualTheta,
        },
    ] {
        let (maps, frames) = maps_in_tangent_frames(&floor, model);
        let channel = BtfLightChannel::new(maps.layout(), Sampling::H1);
        let mirrored: Vec<bool> = frames.iter().map(|f| f.1).collect();
        let w = channel.light_weights(&maps, &mirrored, |_| l);
        for (i, wi) in w.iter().enumerate() {
            for view in [Vec3::Z, Vec3::new(0.5, -0.3, 0.8).normalize()] {
                for (u, v) in [(0.1, 0.1), (0.6, 0.1)] {
                    let rgb = pca.eval_env(view, wi, u, v);
                    let (x, y) = (
                        (u * btf_env_common::RES as f32) as usize,
                        (v * btf_env_common::RES as f32) as usize,
                    );
                    let want = lam.albedo(x, y) * l;
                    for (g, w) in rgb.iter().zip(want.to_array()) {
                        assert!(
                            (g - w).abs() <= 0.01 * w,
                            "{model:?} vertex {i}: {rgb:?} vs {want}"
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn maps_and_the_visibility_matrix_give_the_same_w_within_their_discretisation() {
    let scene = roofed();
    let mut errors = Vec::new();
    for (res, level) in [(8u32, 2u32), (16, 3), (32, 5)] {
        let (maps, frames) = maps_in_tangent_frames(&scene, Model::Hemicube { res });
        let channel = BtfLightChannel::new(maps.layout(), Sampling::H1);
        let mirrored: Vec<bool> = frames.iter().map(|f| f.1).collect();
        let from_maps = channel.light_weights(&maps, &mirrored, sky);

        let sphere = lightsphere::Lightsphere::new(level).unwrap();
        let mut engine =
            occlusion_gpu::VisibilityEngine::cpu(occlusion_gpu::VisibilityParams::default());
        let m = engine.compute(&scene, &sphere).unwrap();
        let omegas: Vec<f32> = sphere.solid_angles().iter().map(|&w| w as f32).collect();
        let tbn: Vec<[Vec3; 3]> = frames.iter().map(|f| f.0).collect();
        let transfer =
            EnvTransfer::build(Sampling::H1, &tbn, sphere.directions(), &omegas, |i, j| {
                m.is_visible(i, j)
            });
        let l: Vec<Vec3> = sphere.directions().iter().map(|&d| sky(d)).collect();
        let mut from_m = Vec::new();
        transfer.update(&l, &mut from_m);
        let totals = |w: &[EnvLightWeights]| -> Vec<EnvLightWeights> {
            w.iter()
                .map(|x| {
                    let mut t = EnvLightWeights::default();
                    t.weights[0] = x.total();
                    t
                })
                .collect()
        };
        errors.push((
            relative_error(&from_maps, &from_m),
            relative_error(&totals(&from_maps), &totals(&from_m)),
        ));
    }
    eprintln!("W maps vs M (whole W, Σ_m W): {errors:?}");
    // Both converge on the same integral: the difference shrinks as both refine.
    assert!(
        errors[2].0 < errors[0].0 && errors[2].1 < errors[0].1,
        "{errors:?}"
    );
    assert!(errors[2].0 < 0.03 && errors[2].1 < 0.012, "{errors:?}");
}

/// Hard case: a vertex whose every map pixel is occluded (a floor shut in a box) bins nothing —
/// W = 0 exactly, so the BTF renders black, not NaN.
#[test]
fn a_vertex_with_every_pixel_occluded_bins_nothing() {
    let s = 1.5;
    let walls = [
        // roof (normal down), four walls facing in
        sheet(
            Vec3::new(-s, 1.0, -s),
            Vec3::new(2.0 * s, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 2.0 * s),
            2,
        ),
        sheet(
            Vec3::new(-s, -0.1, -s),
            Vec3::new(0.0, 1.2, 0.0),
            Vec3::new(0.0, 0.0, 2.0 * s),
            2,
        ),
        sheet(
            Vec3::new(s, -0.1, -s),
            Vec3::new(0.0, 0.0, 2.0 * s),
            Vec3::new(0.0, 1.2, 0.0),
            2,
        ),
        sheet(
            Vec3::new(-s, -0.1, -s),
            Vec3::new(2.0 * s, 0.0, 0.0),
            Vec3::new(0.0, 1.2, 0.0),
            2,
        ),
        sheet(
            Vec3::new(-s, -0.1, s),
            Vec3::new(0.0, 1.2, 0.0),
            Vec3::new(2.0 * s, 0.0, 0.0),
            2,
        ),
    ];
    let shut = scene(floor(2.0, 2), &walls);
    let (maps, frames) = maps_in_tangent_frames(&shut, Model::Hemicube { res: 16 });
    assert!(
        maps.open_fraction().iter().all(|&f| f == 0.0),
        "the box is closed"
    );
    let channel = BtfLightChannel::new(maps.layout(), Sampling::H1);
    let mirrored: Vec<bool> = frames.iter().map(|f| f.1).collect();
    let w = channel.light_weights(&maps, &mirrored, |_| Vec3::splat(1e4));
    assert!(w.iter().all(|x| x.weights.iter().all(|v| *v == Vec3::ZERO)));
    let (pca, _) = btf_env_common::lambertian(Sampling::H1);
    let rgb = pca.eval_env(Vec3::Z, &w[0], 0.3, 0.3);
    assert_eq!(rgb, [0.0; 3]);
}
