//! Refitting the `cpu` backend's BVH to a deforming mesh: every frame of the synthetic drape
//! gives the same M as a tree built for that frame (packets and fans), the engine reports
//! refits while the tree stays good and rebuilds when the topology changes. The timed rule
//! (the default) is also run, for the identity of M only: its refit count depends on the clock.

use glam::Vec3;
use lightsphere::Lightsphere;
use occlusion_gpu::{
    BvhUpdate, CpuMethod, CpuParams, Scene, SceneObject, VisibilityEngine, VisibilityParams,
};

/// A mesh: positions and triangles.
type Mesh = (Vec<Vec3>, Vec<[u32; 3]>);

/// The drape's frames, its triangles, and its ball.
fn drape_frames() -> (Vec<Vec<Vec3>>, Vec<[u32; 3]>, Mesh) {
    let params = synth::ClothParams {
        grid: 24,
        frames: 30,
        ..Default::default()
    };
    let cloth = synth::simulate_cloth(&params).unwrap();
    let ball = synth::obstacle_mesh(&params.obstacle, 2);
    (cloth.frames, cloth.triangles, ball)
}

fn scene(positions: &[Vec3], triangles: &[[u32; 3]], ball: &Mesh) -> Scene {
    let normals = meshio::compute_normals(positions, triangles, meshio::NormalWeighting::Angle);
    let mut scene = Scene::new();
    scene
        .push(SceneObject::new(
            positions.to_vec(),
            normals,
            triangles.to_vec(),
        ))
        .unwrap();
    scene
        .push(
            SceneObject::new(ball.0.clone(), vec![Vec3::Y; ball.0.len()], ball.1.clone())
                .occluder_only(),
        )
        .unwrap();
    scene
}

#[test]
fn a_refitted_tree_gives_every_frame_the_m_of_a_fresh_one() {
    let (frames, triangles, ball) = drape_frames();
    let sphere = Lightsphere::new(2).unwrap();
    for method in [CpuMethod::Packets, CpuMethod::Fans] {
        let cpu = CpuParams::default().with_method(method);
        // By the SAH cap alone, so that the count of refits does not depend on the clock (the
        // default timed rule is tested on its own in the engine).
        let mut refitting = VisibilityEngine::cpu(
            VisibilityParams::default().with_cpu(cpu.with_refit_timed(false)),
        );
        let mut rebuilding =
            VisibilityEngine::cpu(VisibilityParams::default().with_cpu(cpu.with_refit(false)));
        let mut refits = 0;
        for (f, positions) in frames.iter().enumerate().step_by(3) {
            let scene = scene(positions, &triangles, &ball);
            let a = refitting.compute(&scene, &sphere).unwrap();
            let b = rebuilding.compute(&scene, &sphere).unwrap();
            assert_eq!(a.bits(), b.bits(), "{method:?} frame {f}");
            assert_eq!(rebuilding.last_bvh().update, BvhUpdate::Built);
            match refitting.last_bvh().update {
                BvhUpdate::Refitted { sah_ratio } => {
                    refits += 1;
                    assert!(sah_ratio > 0.0 && sah_ratio <= occlusion_gpu::REBUILD_SAH_RATIO);
                }
                BvhUpdate::Built => {}
                other => panic!("{method:?} frame {f}: {other:?}"),
            }
        }
        assert!(refits >= 5, "{method:?}: only {refits} refits");
        // The default, timed rule: whatever the clock decides, M is that of a fresh tree.
        let mut timed = VisibilityEngine::cpu(VisibilityParams::default().with_cpu(cpu));
        for positions in frames.iter().step_by(5) {
            let scene = scene(positions, &triangles, &ball);
            let a = timed.compute(&scene, &sphere).unwrap();
            let b = rebuilding.compute(&scene, &sphere).unwrap();
            assert_eq!(a.bits(), b.bits(), "{method:?} timed");
        }
        // The same scene again: the tree is reused as it is.
        let last = scene(frames.last().unwrap(), &triangles, &ball);
        refitting.compute(&last, &sphere).unwrap();
        refitting.compute(&last, &sphere).unwrap();
        assert_eq!(refitting.last_bvh().update, BvhUpdate::Reused);
        // Another topology: built afresh.
        let fewer = &triangles[..triangles.len() - 2];
        refitting
            .compute(&scene(frames.last().unwrap(), fewer, &ball), &sphere)
            .unwrap();
        assert_eq!(refitting.last_bvh().update, BvhUpdate::Built);
    }
}

/// A scene that grows threefold between calls crosses the power of two each tracer scales its
/// coordinates by: the refitted tree takes the new scale with the new boxes (the same M as a
/// fresh tree), and the refit is kept, as the SAH ratio does not depend on the scale.
#[test]
fn a_refit_across_a_change_of_scale_gives_the_m_of_a_fresh_tree() {
    let (frames, triangles, ball) = drape_frames();
    let sphere = Lightsphere::new(2).unwrap();
    let last = frames.last().unwrap();
    for method in [CpuMethod::Packets, CpuMethod::Fans] {
        let cpu = CpuParams::default()
            .with_method(method)
            .with_refit_timed(false);
        let mut refitting = VisibilityEngine::cpu(VisibilityParams::default().with_cpu(cpu));
        let mut rebuilding =
            VisibilityEngine::cpu(VisibilityParams::default().with_cpu(cpu.with_refit(false)));
        for grow in [1.0f32, 3.0, 0.2] {
            let scaled = |mesh: &[Vec3]| mesh.iter().map(|p| *p * grow).collect::<Vec<_>>();
            let scene = scene(
                &scaled(last),
                &triangles,
                &(scaled(&ball.0), ball.1.clone()),
            );
            let a = refitting.compute(&scene, &sphere).unwrap();
            let b = rebuilding.compute(&scene, &sphere).unwrap();
            assert_eq!(a.bits(), b.bits(), "{method:?} grown {grow}");
            if grow != 1.0 {
                assert!(
                    matches!(refitting.last_bvh().update, BvhUpdate::Refitted { .. }),
                    "{method:?} grown {grow}: {:?}",
                    refitting.last_bvh().update
                );
            }
        }
    }
}
