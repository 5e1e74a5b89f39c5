//! Motion control over cells (thesis §3.2.2 "Motion Control", Fig. 3.5) and the separate
//! attribute vector R_i ("Adding vertex attributes").

mod common;

use anim_pca::jumpmap::metrics::sequence_stats;
use anim_pca::{AnimPcaError, Clip, JumpMap, JumpMapParams, PlaybackParams, Player};
use common::{assert_close, wave_clip};
use glam::Vec3;

/// Two motion subtypes of one mesh: the same wave at two speeds ("walk" and "run"), so poses
/// recur across cells while velocities differ.
fn two_cells() -> (Vec<Vec<Vec3>>, Vec<Vec<Vec3>>) {
    (wave_clip(6, 48, 12.0, 0.0), wave_clip(6, 40, 8.0, 0.0))
}

#[test]
fn random_play_stays_in_its_cell() {
    let (a, b) = two_cells();
    let map =
        JumpMap::analyze_cells(&[Clip::new(&a), Clip::new(&b)], &JumpMapParams::default()).unwrap();
    assert_eq!(map.n_cells(), 2);
    assert_eq!(map.cell_range(0), 0..48);
    assert_eq!(map.cell_range(1), 48..88);
    assert_eq!(map.successor(47), None, "no natural play across cells");
    for (start, cell) in [(0, 0), (60, 1)] {
        let mut player = Player::new(
            &map,
            &PlaybackParams {
                start_frame: start,
                ..PlaybackParams::default()
            },
        )
        .unwrap();
        let run = player.generate(20_000);
        for f in &run.frames {
            assert_eq!(map.cell_of(f.from), cell);
            assert_eq!(map.cell_of(f.to), cell);
        }
        let stats = sequence_stats(&map, &run);
        assert!(stats.transitions > 100, "{stats:?}");
    }
}

#[test]
fn target_cell_is_reached_at_the_best_exit_within_the_horizon() {
    let (a, b) = two_cells();
    let map =
        JumpMap::analyze_cells(&[Clip::new(&a), Clip::new(&b)], &JumpMapParams::default()).unwrap();
    let params = PlaybackParams {
        control_horizon: 20,
        seed: 7,
        ..PlaybackParams::default()
    };
    let mut player = Player::new(&map, &params).unwrap();
    let mut frames = player.generate(500).frames;
    let mut cell = 0;
    for round in 0..6 {
        let target = 1 - cell;
        let from_key = player.current_key();
        player.set_target_cell(target).unwrap();
        assert_eq!(player.target_cell(), Some(target));
        let offset = frames.len(); // transition indices count from the player's start
        let run = player.generate(300);
        assert_eq!(player.target_cell(), None);
        // Exactly one transition crosses cells; it leaves from the natural path ahead of the
        // key frame at the request, within the horizon, and enters the target cell's core.
        let crossing: Vec<_> = run
            .transitions
            .iter()
            .filter(|t| map.cell_of(t.from) != map.cell_of(t.to))
            .collect();
        assert_eq!(crossing.len(), 1, "round {round}: {crossing:?}");
        let t = crossing[0];
        assert_eq!(map.cell_of(t.to), target);
        assert!(map.core()[t.to]);
        let ahead: Vec<usize> = std::iter::successors(Some(from_key), |&k| map.successor(k))
            .take(params.control_horizon + 1)
            .collect();
        assert!(
            ahead.contains(&t.from),
            "round {round}: exit {} not ahead",
            t.from
        );
        // Brute force over the same window: nothing scores better.
        let best = ahead
            .iter()
            .flat_map(|&k| {
                map.cell_range(target)
                    .filter(|&j| map.core()[j])
                    .map(move |j| (k, j))
            })
            .map(|(k, j)| map.transition_score(k, j))
            .fold(0.0, f64::max);
        assert_close(map.transition_score(t.from, t.to), best, 1e-12);
        // The same pose recurs in the other cell: the entry is a good match.
        assert!(
            map.jump_residual(t.from, t.to) < 0.5 * map.mean_frame_distance(),
            "round {round}: residual {}",
            map.jump_residual(t.from, t.to)
        );
        // Everything after the crossing plays in the target cell.
        let after = t.index - offset + t.blend_frames + 1;
        for f in &run.frames[after..] {
            assert_eq!(map.cell_of(f.from), target);
            assert_eq!(map.cell_of(f.to), target);
        }
        frames.extend(run.frames);
        cell = target;
    }
    assert!(frames.iter().all(|f| f.from < 88 && f.to < 88));
}

#[test]
fn cell_requests_are_checked() {
    let (a, b) = two_cells();
    let map =
        JumpMap::analyze_cells(&[Clip::new(&a), Clip::new(&b)], &JumpMapParams::default()).unwrap();
    let mut player = Player::new(&map, &PlaybackParams::default()).unwrap();
    assert!(matches!(
        player.set_target_cell(2),
        Err(AnimPcaError::InvalidCell { cell: 2, .. })
    ));
    player.set_target_cell(1).unwrap();
    player.set_target_cell(0).unwrap(); // the current cell cancels the request
    assert_eq!(player.target_cell(), None);
    let run = player.generate(2000);
    assert!(run.frames.iter().all(|f| map.cell_of(f.from) == 0));

    // Cells must share the mesh, and normals/attributes come for all cells or none.
    let small = wave_clip(5, 20, 8.0, 0.0);
    let err = JumpMap::analyze_cells(
        &[Clip::new(&a), Clip::new(&small)],
        &JumpMapParams::default(),
    )
    .unwrap_err();
    assert!(
        matches!(err, AnimPcaError::InvalidCell { cell: 1, .. }),
        "{err}"
    );
    assert!(err.to_string().contains("25 vertices"), "{err}");
    let r: Vec<Vec<f32>> = vec![vec![1.0]; a.len()];
    let err = JumpMap::analyze_cells(
        &[Clip::new(&a).with_attributes(&r), Clip::new(&b)],
        &JumpMapParams::default(),
    )
    .unwrap_err();
    assert!(
        matches!(err, AnimPcaError::InvalidCell { cell: 1, .. }),
        "{err}"
    );
    assert!(matches!(
        JumpMap::analyze_cells(&[], &JumpMapParams::default()),
        Err(AnimPcaError::InvalidCell { .. })
    ));
}

#[test]
fn a_single_clip_as_one_cell_is_the_plain_analysis() {
    let clip = wave_clip(6, 40, 10.0, 0.2);
    let plain = JumpMap::analyze(&clip, &JumpMapParams::default()).unwrap();
    let cell = JumpMap::analyze_cells(&[Clip::new(&clip)], &JumpMapParams::default()).unwrap();
    assert_eq!(plain.jump_map(), cell.jump_map());
    assert_eq!(plain.sampling_matrix(), cell.sampling_matrix());
}

/// A per-vertex attribute on a wildly different scale (a "wetness" in the thousands) and
/// unrelated to the geometry's frequency.
fn wetness(clip: &[Vec<Vec3>]) -> Vec<Vec<f32>> {
    (0..clip.len())
        .map(|t| {
            (0..clip[0].len())
                .map(|n| 5000.0 + 2000.0 * ((t as f32 * 0.37) + n as f32 * 0.05).sin())
                .collect()
        })
        .collect()
}

#[test]
fn attributes_have_their_own_pca_and_leave_the_motion_alone() {
    let clip = wave_clip(6, 40, 10.0, 0.2);
    let r = wetness(&clip);
    let params = JumpMapParams {
        attribute_components: 2,
        ..JumpMapParams::default()
    };
    let plain = JumpMap::analyze(&clip, &params).unwrap();
    let with = JumpMap::analyze_cells(&[Clip::new(&clip).with_attributes(&r)], &params).unwrap();
    // The jump structure is the motion's: D, P̂ and the geometry PCA are untouched.
    assert_eq!(plain.distances(), with.distances());
    assert_eq!(plain.jump_map(), with.jump_map());
    assert!(plain.attribute_reconstructor().is_none());
    assert!(plain.attribute_weights(3).is_empty());
    // sin(a + b) spans two components: R_i is rebuilt to f32 rounding of its scale.
    let rec = with.attribute_reconstructor().unwrap();
    assert_eq!(rec.len(), clip[0].len());
    assert_eq!(rec.components(), 2);
    let mut out = vec![0.0f32; rec.len()];
    for (i, truth) in r.iter().enumerate() {
        rec.reconstruct(with.attribute_weights(i), &mut out)
            .unwrap();
        for (x, y) in out.iter().zip(truth) {
            assert!((x - y).abs() < 0.05, "frame {i}: {x} vs {y}");
        }
    }
    // Generated frames carry blended attribute weights.
    let run = Player::new(&with, &PlaybackParams::default())
        .unwrap()
        .generate(500);
    let mut w = vec![0.0; 2];
    for f in &run.frames {
        f.attribute_weights_into(&with, &mut w);
        rec.reconstruct(&w, &mut out).unwrap();
        assert!(out.iter().all(|x| (2900.0..=7100.0).contains(x)));
    }
}
