//! Root motion (a clip that travels, like the chicken crossing the road): extracted before the
//! analysis and replayed by integration.

mod common;

use anim_pca::jumpmap::metrics::sequence_stats;
use anim_pca::{Blend, GeneratedFrame, JumpMap, JumpMapParams, PlaybackParams, Player, RootMotion};
use common::wave_clip;
use glam::Vec3;

const PERIOD: usize = 12;
/// Travel per frame along x (one grid spacing every two frames: the body moves far more
/// between periods than its shape changes).
const SPEED: f32 = 0.5;

fn walking() -> Vec<Vec<Vec3>> {
    wave_clip(6, 60, PERIOD as f32, 0.0)
        .into_iter()
        .enumerate()
        .map(|(t, f)| {
            f.into_iter()
                .map(|v| v + Vec3::X * SPEED * t as f32)
                .collect()
        })
        .collect()
}

fn params(root_motion: RootMotion) -> JumpMapParams {
    JumpMapParams {
        root_motion,
        ..JumpMapParams::default()
    }
}

#[test]
fn extracted_root_motion_finds_the_gait_period() {
    let clip = walking();
    let kept = JumpMap::analyze(&clip, &params(RootMotion::Keep)).unwrap();
    let extracted = JumpMap::analyze(&clip, &params(RootMotion::Extract)).unwrap();
    // How far off is the best jump of every frame, in units of the clip's own frame step?
    let best_residual = |map: &JumpMap| {
        (0..clip.len())
            .filter_map(|i| map.best_jump(i).map(|j| map.jump_residual(i, j)))
            .fold(0.0, f64::max)
            / map.mean_frame_distance()
    };
    let (k, e) = (best_residual(&kept), best_residual(&extracted));
    println!("worst best-jump residual: kept {k:.3} d̄, extracted {e:.5} d̄");
    assert!(e < 0.01, "extracted: the gait repeats exactly ({e})");
    assert!(
        k > 1.0,
        "kept: a jump a period back is a jump back in space ({k})"
    );
    // Random play with extraction actually loops, and jumps are good.
    let run = Player::new(&extracted, &PlaybackParams::default())
        .unwrap()
        .generate(5_000);
    let stats = sequence_stats(&extracted, &run);
    assert!(stats.transitions > 100, "{stats:?}");
    assert!(stats.max_jump_distance < 0.1, "{stats:?}");
}

#[test]
fn root_offsets_replay_the_clip_and_keep_walking() {
    let clip = walking();
    let map = JumpMap::analyze(&clip, &params(RootMotion::Extract)).unwrap();
    let mut w = vec![0.0; map.components()];
    let mut mesh = vec![Vec3::ZERO; map.n_vertices()];
    // Natural play of the clip: offset + shape is the clip itself.
    let keys: Vec<GeneratedFrame> = (0..clip.len()).map(GeneratedFrame::key).collect();
    let offsets = map.root_offsets(&keys);
    for (t, (f, o)) in keys.iter().zip(&offsets).enumerate() {
        f.weights_into(&map, &mut w);
        map.reconstructor().reconstruct(&w, &mut mesh).unwrap();
        for (a, b) in mesh.iter().zip(&clip[t]) {
            assert!(
                (*a + *o - *b).length() < 1e-3,
                "frame {t}: {a} + {o} vs {b}"
            );
        }
    }
    // A long generated run keeps moving forward at the clip's speed, through every jump and
    // blend: no snapping back to where a clip frame was recorded.
    let run = Player::new(
        &map,
        &PlaybackParams {
            blend: Blend::Fixed(3),
            ..PlaybackParams::default()
        },
    )
    .unwrap()
    .generate(2_000);
    let offsets = map.root_offsets(&run.frames);
    for (t, pair) in offsets.windows(2).enumerate() {
        let step = pair[1] - pair[0];
        assert!(
            (step.x - SPEED).abs() < 1e-3 && step.y.abs() < 1e-3,
            "frame {t}: step {step}"
        );
    }
    // Kept root motion: offsets are zero, the frames are already placed.
    let kept = JumpMap::analyze(&clip, &params(RootMotion::Keep)).unwrap();
    assert!(
        kept.root_offsets(&run.frames[..10])
            .iter()
            .all(|o| *o == Vec3::ZERO)
    );
}
