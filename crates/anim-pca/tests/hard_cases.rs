//! Adversarial inputs: finite, documented results and never a panic.

mod common;

use anim_pca::jumpmap::metrics::{reconstruction_errors, sequence_stats};
use anim_pca::{
    AnimPcaError, Blend, Clip, JumpMap, JumpMapParams, LoopTable, PlaybackParams, Player,
};
use common::wave_clip;
use glam::Vec3;

/// Plays `n` frames with every blend mode and checks that all reconstructed frames are finite.
#[track_caller]
fn plays_finitely(map: &JumpMap, n: usize) {
    for blend in [Blend::None, Blend::Fixed(3), Blend::Smoothness(0.5)] {
        let params = PlaybackParams {
            blend,
            ..Default::default()
        };
        let run = Player::new(map, &params).unwrap().generate(n);
        let mut w = vec![0.0; map.components()];
        let mut mesh = vec![Vec3::ZERO; map.n_vertices()];
        for f in &run.frames {
            assert!(f.from < map.n_frames() && f.to < map.n_frames());
            f.weights_into(map, &mut w);
            map.reconstructor().reconstruct(&w, &mut mesh).unwrap();
            assert!(mesh.iter().all(|v| v.is_finite()));
        }
        for cell in 0..map.n_cells() {
            let table = LoopTable::build(map, cell, 30, blend).unwrap();
            for lp in table.iter() {
                assert!(lp.cost.is_finite() && lp.cost >= 0.0);
                assert!(lp.frames.iter().all(|f| map.cell_of(f.from) == cell));
            }
        }
    }
    for m in [
        map.distances(),
        map.velocity_distances(),
        map.jump_map(),
        map.sampling_matrix(),
    ] {
        assert!(m.as_slice().iter().all(|x| x.is_finite()));
    }
}

#[test]
fn clip_of_two_frames() {
    let clip = wave_clip(4, 2, 12.0, 0.0);
    let map = JumpMap::analyze(&clip, &JumpMapParams::default()).unwrap();
    assert_eq!(map.components(), 1);
    // Documented: the last frame of a 2-frame clip restarts at frame 0.
    assert_eq!(map.jump_map().row(1), &[1.0, 0.0]);
    plays_finitely(&map, 1000);
    let run = Player::new(&map, &PlaybackParams::default())
        .unwrap()
        .generate(100);
    assert_eq!(sequence_stats(&map, &run).coverage, 1.0);
}

#[test]
fn static_clip_all_distances_zero() {
    let frame: Vec<Vec3> = (0..20).map(|n| Vec3::new(n as f32, 1.0, 2.0)).collect();
    let clip = vec![frame; 15];
    let map = JumpMap::analyze(&clip, &JumpMapParams::default()).unwrap();
    // Documented: rank 0, no components, D = 0, distance unit 0, uniform rows.
    assert_eq!(map.components(), 0);
    assert_eq!(map.distance_unit(), 0.0);
    assert!(map.distances().as_slice().iter().all(|d| *d == 0.0));
    let row = map.jump_map().row(3);
    assert!(row.iter().all(|p| (p - 1.0 / 15.0).abs() < 1e-12));
    plays_finitely(&map, 1000);
    let errors = reconstruction_errors(&clip, &[0, 2]).unwrap();
    assert!(
        errors
            .iter()
            .all(|e| e.position < 1e-10 && e.velocity == 0.0)
    );
}

#[test]
fn more_components_than_frames() {
    let clip = wave_clip(5, 6, 4.3, 0.5);
    let params = JumpMapParams {
        components: 50,
        velocity_components: 50,
        ..Default::default()
    };
    let map = JumpMap::analyze(&clip, &params).unwrap();
    assert!(map.components() <= 5, "centred rank ≤ l − 1");
    plays_finitely(&map, 1000);
    let errors = reconstruction_errors(&clip, &[0, 3, 50]).unwrap();
    assert!(errors[2].position < 1e-8, "{errors:?}");
}

#[test]
fn sigma_towards_zero_and_infinity() {
    let clip = wave_clip(5, 40, 11.0, 0.3);
    for sigma in [1e-300, f64::MIN_POSITIVE, 1e-3, 1e3, 1e300, f64::INFINITY] {
        let params = JumpMapParams {
            sigma,
            sigma_velocity: sigma,
            ..Default::default()
        };
        let map = JumpMap::analyze(&clip, &params).unwrap();
        plays_finitely(&map, 2000);
        if sigma >= 1e300 {
            // σ → ∞: uniform rows (except the last frame's excluded targets).
            let row = map.jump_map().row(10);
            assert!(
                row.iter().all(|p| (p - 1.0 / 40.0).abs() < 1e-12),
                "{row:?}"
            );
        }
        if sigma <= 1e-300 {
            // σ → 0: only the natural successor keeps probability.
            assert_eq!(map.jump_map().get(10, 11), 1.0);
        }
    }
}

#[test]
fn single_outlier_frame() {
    let mut clip = wave_clip(6, 40, 10.0, 0.1);
    for v in &mut clip[17] {
        *v += Vec3::new(0.0, 0.0, 1000.0);
    }
    let map = JumpMap::analyze(&clip, &JumpMapParams::default()).unwrap();
    plays_finitely(&map, 5000);
    // Documented: nothing jumps into the outlier; it is reached only from frame 16.
    for i in (0..40).filter(|&i| i != 16) {
        assert!(map.jump_map().get(i, 17) < 1e-6, "frame {i} → outlier");
    }
}

#[test]
fn bad_parameters_name_the_parameter() {
    let clip = wave_clip(4, 10, 5.0, 0.0);
    let bad = |p: JumpMapParams, name: &str| {
        let e = JumpMap::analyze(&clip, &p).unwrap_err();
        assert!(
            matches!(&e, AnimPcaError::InvalidParameter { name: n, .. } if *n == name),
            "{e}"
        );
        assert!(e.to_string().contains(name));
    };
    let d = JumpMapParams::default();
    bad(JumpMapParams { sigma: 0.0, ..d }, "sigma");
    bad(JumpMapParams { sigma: -1.0, ..d }, "sigma");
    bad(
        JumpMapParams {
            sigma_velocity: f64::NAN,
            ..d
        },
        "sigma_velocity",
    );
    bad(JumpMapParams { components: 0, ..d }, "components");
    bad(
        JumpMapParams {
            velocity_components: 0,
            ..d
        },
        "velocity_components",
    );
    bad(JumpMapParams { q: 1.5, ..d }, "q");

    let map = JumpMap::analyze(&clip, &d).unwrap();
    let e = Player::new(
        &map,
        &PlaybackParams {
            memory: 5,
            ..Default::default()
        },
    )
    .unwrap_err();
    assert!(
        e.to_string().contains("memory") && e.to_string().contains('5'),
        "{e}"
    );
    let e = Player::new(
        &map,
        &PlaybackParams {
            blend: Blend::Smoothness(f64::NAN),
            ..Default::default()
        },
    )
    .unwrap_err();
    assert!(e.to_string().contains("smoothness"), "{e}");

    let e = Player::new(
        &map,
        &PlaybackParams {
            start_frame: 10,
            ..Default::default()
        },
    )
    .unwrap_err();
    assert!(e.to_string().contains("start_frame"), "{e}");
    let e = Player::new(
        &map,
        &PlaybackParams {
            blend: Blend::Fixed(33),
            ..Default::default()
        },
    )
    .unwrap_err();
    assert!(
        e.to_string().contains("blend") && e.to_string().contains("33"),
        "{e}"
    );

    let empty: Vec<Vec<Vec3>> = Vec::new();
    assert!(matches!(
        JumpMap::analyze(&empty, &d),
        Err(AnimPcaError::EmptyClip { .. })
    ));
    let one = vec![vec![Vec3::ONE; 3]];
    assert!(matches!(
        JumpMap::analyze(&one, &d),
        Err(AnimPcaError::TooFewFrames { frames: 1, .. })
    ));
    let mut ragged = clip.clone();
    ragged[4].pop();
    assert!(matches!(
        JumpMap::analyze(&ragged, &d),
        Err(AnimPcaError::VertexCountMismatch {
            frame: 4,
            expected: 16,
            found: 15,
            ..
        })
    ));
    let mut nan = clip.clone();
    nan[2][3].y = f32::NAN;
    assert!(matches!(
        JumpMap::analyze(&nan, &d),
        Err(AnimPcaError::NonFinite {
            frame: 2,
            vertex: 3,
            ..
        })
    ));
}

#[test]
fn loops_of_two_frame_and_static_clips() {
    // Two frames: the only jump, 1 → 0, is back-and-forth jitter, which loops never use.
    let two = wave_clip(4, 2, 12.0, 0.0);
    let map = JumpMap::analyze(&two, &JumpMapParams::default()).unwrap();
    let table = LoopTable::build(&map, 0, 10, Blend::Fixed(3)).unwrap();
    assert_eq!(table.iter().count(), 0);
    // Static: every frame equals every other, so loops of every length are free.
    let still = vec![wave_clip(3, 1, 12.0, 0.0)[0].clone(); 6];
    let map = JumpMap::analyze(&still, &JumpMapParams::default()).unwrap();
    let table = LoopTable::build(&map, 0, 12, Blend::None).unwrap();
    for len in 3..=12 {
        assert_eq!(table.get(len).map(|l| l.cost), Some(0.0), "length {len}");
    }
}

#[test]
fn cells_of_two_frames_static_and_outlier() {
    let wave = wave_clip(4, 30, 8.0, 0.0);
    let two = wave_clip(4, 2, 5.0, 0.0);
    let still = vec![wave[3].clone(); 5];
    let params = JumpMapParams {
        components: 50, // more than the 37 frames of all cells together
        ..JumpMapParams::default()
    };
    let map = JumpMap::analyze_cells(
        &[Clip::new(&wave), Clip::new(&two), Clip::new(&still)],
        &params,
    )
    .unwrap();
    assert_eq!(map.n_cells(), 3);
    plays_finitely(&map, 2_000);
    // Visit every cell from every cell; play always lands in the requested one.
    let mut player = Player::new(&map, &PlaybackParams::default()).unwrap();
    for target in [1, 2, 0, 2, 1, 0] {
        player.set_target_cell(target).unwrap();
        let run = player.generate(200);
        assert_eq!(player.current_cell(), target);
        assert_eq!(map.cell_of(run.frames.last().unwrap().from), target);
    }
}
