//! The shared draped dress (4,589 vertices, the nearest we have to the thesis's 3,120-vertex
//! dress of §4.3.7): GPU atlas against exact rays pixel by pixel, and the hemicube's open
//! fraction against `occlusion-gpu`'s ambient term a_i (the same integral by another
//! discretisation). Skips without ../shared/data (fails under CI).

use std::sync::Arc;

use glam::Vec3;
use hemicube::{BuildParams, FormFactorRule, GpuBuilder, Model, PixelLayout, build_with_rays};
use occlusion_gpu::{Scene, SceneObject};

const DRESS: &str = "meshes/garments/dress-victor-iso-draped.obj";

fn dress() -> Option<meshio::Mesh> {
    let path = test_data::shared_file(DRESS)?;
    let (mesh, _) = meshio::load_mesh(&path, &meshio::LoadOptions::default()).unwrap();
    Some(mesh)
}

/// The dress as occluder, and every `step`-th used vertex as a receiver point (no triangles of
/// its own, so it occludes nothing twice).
fn sampled(step: usize) -> Option<Scene> {
    let meshio::Mesh {
        positions,
        normals,
        triangles,
        ..
    } = dress()?;
    let mut scene = Scene::new();
    scene
        .push(SceneObject::new(positions.clone(), normals.clone(), triangles).occluder_only())
        .unwrap();
    let picked: Vec<usize> = (0..positions.len())
        .filter(|&i| normals[i] != Vec3::ZERO)
        .step_by(step)
        .collect();
    scene
        .push(SceneObject::new(
            picked.iter().map(|&i| positions[i]).collect(),
            picked.iter().map(|&i| normals[i]).collect(),
            Vec::new(),
        ))
        .unwrap();
    Some(scene)
}

#[test]
fn gpu_atlas_agrees_with_exact_rays_except_at_occluder_edges() {
    let Some(scene) = sampled(15) else { return };
    let Some(gpu) = gpu_context::testing::gpu_or_skip() else {
        return;
    };
    for model in [
        Model::Hemicube { res: 16 },
        Model::SinglePlane {
            res: 16,
            aperture_deg: hemicube::DEFAULT_APERTURE_DEG,
        },
    ] {
        let layout = Arc::new(PixelLayout::new(model, FormFactorRule::Exact).unwrap());
        let (rays, _) = build_with_rays(&scene, layout.clone(), &BuildParams::default()).unwrap();
        let builder = GpuBuilder::new(&gpu, layout.clone()).unwrap();
        let (raster, _) = builder
            .build(&gpu, &scene, &BuildParams::default())
            .unwrap();
        let differing: u64 = rays
            .differing_pixels(&raster)
            .iter()
            .map(|&d| u64::from(d))
            .sum();
        let total = (rays.len() * layout.len()) as f64;
        let share = differing as f64 / total;
        eprintln!(
            "{}: {differing} of {total} pixels differ ({share:.2e})",
            model.label()
        );
        assert!(share < 2e-4, "{}: {share}", model.label());
        let (a, b) = (rays.open_fraction(), raster.open_fraction());
        let worst = a
            .iter()
            .zip(&b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0f32, f32::max);
        assert!(
            worst < 0.02,
            "{}: open fractions differ by {worst}",
            model.label()
        );
    }
}

#[test]
fn open_fraction_meets_the_lightsphere_ambient_term() {
    let Some(scene) = sampled(5) else { return };
    let layout =
        Arc::new(PixelLayout::new(Model::Hemicube { res: 64 }, FormFactorRule::Exact).unwrap());
    let (maps, _) = build_with_rays(&scene, layout, &BuildParams::default()).unwrap();
    let open = maps.open_fraction();
    let sphere = lightsphere::Lightsphere::new(5).unwrap();
    let mut engine =
        occlusion_gpu::VisibilityEngine::cpu(occlusion_gpu::VisibilityParams::default());
    let ambient = engine.compute(&scene, &sphere).unwrap().ambient();
    assert_eq!(open.len(), ambient.len());
    let (mut sum, mut worst, mut n) = (0.0f64, 0.0f32, 0usize);
    for (o, a) in open.iter().zip(&ambient) {
        assert!(o.is_finite() && (0.0..=1.0 + 1e-5).contains(o), "{o}");
        let d = (o - a).abs();
        sum += f64::from(d);
        worst = worst.max(d);
        n += 1;
    }
    let mean = sum / n as f64;
    eprintln!("HC 64 vs lightsphere level 5: mean |Δ| {mean:.2e}, max {worst:.2e} over {n}");
    assert!(mean < 2e-3 && worst < 0.02, "mean {mean}, max {worst}");
}
