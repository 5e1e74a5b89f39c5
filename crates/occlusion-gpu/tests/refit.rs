//! Refitting the `cpu` backend's BVH to a deforming mesh: every frame of the synthetic drape
//! gives the same M as a tree built for that frame (packets and fans), the engine reports
//! refits while the tree stays good and rebuilds when the topology changes. The timed rule
//! (the default) is also run, for the identity of M only: its refit count depends on the clock.

mod common;

use common::{drape_frames, drape_scene, refits_over_frames};
use glam::Vec3;
use lightsphere::Lightsphere;
use occlusion_gpu::{BvhUpdate, CpuMethod, CpuParams, VisibilityEngine, VisibilityParams};

#[test]
fn a_refitted_tree_gives_every_frame_the_m_of_a_fresh_one() {
    let drape = drape_frames(24, 30, 2);
    let (frames, triangles, ball) = &drape;
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
        let what = format!("{method:?}");
        let refits = refits_over_frames(&mut refitting, &mut rebuilding, &drape, &sphere, &what);
        assert!(refits >= 5, "{method:?}: only {refits} refits");
        // The default, timed rule: whatever the clock decides, M is that of a fresh tree.
        let mut timed = VisibilityEngine::cpu(VisibilityParams::default().with_cpu(cpu));
        for positions in frames.iter().step_by(5) {
            let scene = drape_scene(positions, triangles, ball);
            let a = timed.compute(&scene, &sphere).unwrap();
            let b = rebuilding.compute(&scene, &sphere).unwrap();
            assert_eq!(a.bits(), b.bits(), "{method:?} timed");
        }
        // The same scene again: the tree is reused as it is.
        let last = drape_scene(frames.last().unwrap(), triangles, ball);
        refitting.compute(&last, &sphere).unwrap();
        refitting.compute(&last, &sphere).unwrap();
        assert_eq!(refitting.last_bvh().update, BvhUpdate::Reused);
        // Another topology: built afresh.
        let fewer = &triangles[..triangles.len() - 2];
        refitting
            .compute(&drape_scene(frames.last().unwrap(), fewer, ball), &sphere)
            .unwrap();
        assert_eq!(refitting.last_bvh().update, BvhUpdate::Built);
    }
}

/// A scene that grows threefold between calls crosses the power of two each tracer scales its
/// coordinates by: the refitted tree takes the new scale with the new boxes (the same M as a
/// fresh tree), and the refit is kept, as the SAH ratio does not depend on the scale.
#[test]
fn a_refit_across_a_change_of_scale_gives_the_m_of_a_fresh_tree() {
    let (frames, triangles, ball) = drape_frames(24, 30, 2);
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
            let scene = drape_scene(
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
