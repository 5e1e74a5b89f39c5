//! Defining properties of the jump map (thesis §3.2): the period is found, play never dead-ends,
//! blended transitions are smooth, reconstruction is the PCA's, and runs are seeded.

mod common;

use anim_pca::jumpmap::metrics::{
    clip_max_velocity_change, sequence_stats, transition_velocity_change,
};
use anim_pca::{AnimPcaError, Blend, JumpMap, JumpMapParams, PlaybackParams, Player};
use common::{assert_close, wave_clip, wave_with_tail};
use faer::Mat;
use glam::Vec3;

const PERIOD: usize = 12;

#[test]
fn most_probable_jump_finds_the_period() {
    // A slowly growing amplitude (the aperiodic part) makes the nearest period the best match.
    let clip = wave_clip(10, 50, PERIOD as f32, 0.2);
    let map = JumpMap::analyze(&clip, &JumpMapParams::default()).unwrap();
    for i in 0..clip.len() {
        let j = map.best_jump(i).unwrap() as isize;
        let (fwd, back) = (i as isize + PERIOD as isize, i as isize - PERIOD as isize);
        assert!(
            (j - fwd).abs() <= 1 || (j - back).abs() <= 1,
            "frame {i}: best jump {j}, expected within one frame of {back} or {fwd}"
        );
    }
    // Exactly periodic: every multiple of the period matches equally well.
    let clip = wave_clip(10, 50, PERIOD as f32, 0.0);
    let map = JumpMap::analyze(&clip, &JumpMapParams::default()).unwrap();
    for i in 0..clip.len() {
        let j = map.best_jump(i).unwrap() as isize;
        let off = (j - i as isize).rem_euclid(PERIOD as isize);
        assert!(
            off <= 1 || off == PERIOD as isize - 1,
            "frame {i}: best jump {j}"
        );
    }
}

#[test]
fn hundred_thousand_frames_without_a_dead_end() {
    for (name, clip) in [
        ("drifting wave", wave_clip(8, 60, PERIOD as f32, 0.3)),
        (
            "wave with a non-looping tail",
            wave_with_tail(8, 48, PERIOD as f32, 10),
        ),
    ] {
        let l = clip.len();
        let map = JumpMap::analyze(&clip, &JumpMapParams::default()).unwrap();
        let mut player = Player::new(&map, &PlaybackParams::default()).unwrap();
        let run = player.generate(100_000);
        let stats = sequence_stats(&map, &run);
        // Never trapped among the last tenth of the clip for longer than one clip length.
        let end_zone = l - l / 10;
        let mut streak = 0usize;
        let mut longest = 0usize;
        for f in &run.frames {
            streak = if f.from >= end_zone { streak + 1 } else { 0 };
            longest = longest.max(streak);
        }
        println!("{name}: {stats:?}, longest stay in the last tenth {longest}");
        assert!(
            longest <= l,
            "{name}: stuck near the end for {longest} frames"
        );
        assert!(stats.transitions > 1000, "{name}: {stats:?}");
        // Every frame of the looping part is played.
        let looping = if name.contains("tail") { 48 } else { l };
        let mut seen = vec![false; l];
        for f in run.frames.iter().filter(|f| f.is_key()) {
            seen[f.from] = true;
        }
        let covered = seen[..looping].iter().filter(|s| **s).count();
        assert!(
            covered as f64 >= 0.9 * looping as f64,
            "{name}: {covered}/{looping} covered"
        );
    }
}

#[test]
fn blended_transitions_keep_velocity_changes_small() {
    let clip = wave_clip(8, 60, PERIOD as f32, 0.3);
    let map = JumpMap::analyze(&clip, &JumpMapParams::default()).unwrap();
    let reference = clip_max_velocity_change(&map);
    let play = |blend| {
        let params = PlaybackParams {
            blend,
            seed: 7,
            ..Default::default()
        };
        Player::new(&map, &params).unwrap().generate(20_000)
    };
    let cut = play(Blend::None);
    let blended = play(Blend::Fixed(3));
    let variable = play(Blend::Smoothness(0.25));
    // Blending never changes which key frames are visited.
    let keys = |g: &anim_pca::Generated| -> Vec<(usize, usize)> {
        g.transitions.iter().map(|t| (t.from, t.to)).collect()
    };
    assert_eq!(keys(&cut)[..100], keys(&blended)[..100]);
    let (vc, vb, vv) = (
        transition_velocity_change(&map, &cut),
        transition_velocity_change(&map, &blended),
        transition_velocity_change(&map, &variable),
    );
    println!("clip {reference:.4}, cut {vc:.4}, b = 3 {vb:.4}, s = 0.25 d̄ {vv:.4}");
    assert!(vb <= 2.0 * reference, "b = 3: {vb} > 2 × {reference}");
    assert!(vv <= 2.0 * reference, "s = 0.25: {vv} > 2 × {reference}");
}

#[test]
fn blending_hides_poor_jumps() {
    // σ = 0.3 admits jumps with a real residual; blending must spread it out.
    let clip = wave_clip(8, 60, PERIOD as f32, 0.6);
    let params = JumpMapParams {
        sigma: 0.3,
        sigma_velocity: 0.3,
        ..Default::default()
    };
    let map = JumpMap::analyze(&clip, &params).unwrap();
    let play = |blend| {
        let p = PlaybackParams {
            blend,
            seed: 11,
            ..Default::default()
        };
        Player::new(&map, &p).unwrap().generate(20_000)
    };
    let (cut, blended) = (play(Blend::None), play(Blend::Fixed(3)));
    let (vc, vb) = (
        transition_velocity_change(&map, &cut),
        transition_velocity_change(&map, &blended),
    );
    let stats = sequence_stats(&map, &cut);
    println!("σ = 0.3: {stats:?}; velocity change cut {vc:.4}, b = 3 {vb:.4}");
    assert!(stats.max_jump_distance > 0.5, "{stats:?}");
    assert!(vb < vc, "blending {vb} ≥ cut {vc}");
}

#[test]
fn reconstruction_equals_the_pca_reconstruction() {
    let clip = wave_clip(10, 40, 9.5, 0.2);
    let map = JumpMap::analyze(&clip, &JumpMapParams::default()).unwrap();
    let c = map.components();
    let n = map.n_vertices();
    let mut out = vec![Vec3::ZERO; n];
    let scale = clip
        .iter()
        .flatten()
        .map(|v| v.abs().max_element())
        .fold(0.0f32, f32::max);
    for i in [0, 7, 39] {
        let w = map.weights(i);
        map.reconstructor().reconstruct(w, &mut out).unwrap();
        let reference = map
            .pca()
            .reconstruct(Mat::from_fn(1, c, |_, k| w[k]).as_ref())
            .unwrap();
        for (v, p) in out.iter().enumerate() {
            for k in 0..3 {
                assert_close(
                    f64::from(p[k]),
                    reference[(0, 3 * v + k)],
                    1e-5 * f64::from(scale) * (c + 1) as f64,
                );
            }
        }
        // The clip has rank ≤ 6 < c: reconstruction gives the frame back.
        for (p, q) in out.iter().zip(&clip[i]) {
            assert!((*p - *q).length() <= 1e-4 * scale, "frame {i}: {p} vs {q}");
        }
    }
    // Fewer weights than components: the leading ones only.
    map.reconstructor()
        .reconstruct(&map.weights(3)[..2], &mut out)
        .unwrap();
    assert!(matches!(
        map.reconstructor().reconstruct(&vec![0.0; c + 1], &mut out),
        Err(AnimPcaError::LengthMismatch { .. })
    ));
}

#[test]
fn normals_are_reconstructed_as_unit_vectors() {
    let clip = wave_clip(6, 30, 10.0, 0.0);
    let normals: Vec<Vec<Vec3>> = clip
        .iter()
        .map(|f| {
            f.iter()
                .map(|v| Vec3::new(-0.3 * v.z, 0.1, 1.0).normalize())
                .collect()
        })
        .collect();
    let map = JumpMap::analyze_with_normals(&clip, &normals, &JumpMapParams::default()).unwrap();
    let mut out = vec![Vec3::ZERO; 36];
    map.reconstructor()
        .reconstruct_normals(map.weights(4), &mut out)
        .unwrap();
    for (a, b) in out.iter().zip(&normals[4]) {
        assert!((*a - *b).length() < 1e-3, "{a} vs {b}");
    }
}

#[test]
fn play_is_deterministic_for_a_seed() {
    let clip = wave_clip(6, 50, PERIOD as f32, 0.3);
    let map = JumpMap::analyze(&clip, &JumpMapParams::default()).unwrap();
    let run = |seed| {
        let params = PlaybackParams {
            seed,
            ..Default::default()
        };
        Player::new(&map, &params).unwrap().generate(5000)
    };
    assert_eq!(run(3), run(3));
    assert_ne!(run(3).transitions, run(4).transitions);
    // Analysis is deterministic too.
    let again = JumpMap::analyze(&clip, &JumpMapParams::default()).unwrap();
    assert_eq!(map.jump_map(), again.jump_map());
}

#[test]
fn memory_forbids_back_and_forth() {
    let clip = wave_clip(6, 50, PERIOD as f32, 0.3);
    let map = JumpMap::analyze(&clip, &JumpMapParams::default()).unwrap();
    for m in 1..5 {
        let params = PlaybackParams {
            memory: m,
            blend: Blend::None,
            ..Default::default()
        };
        let run = Player::new(&map, &params).unwrap().generate(20_000);
        let keys: Vec<usize> = run.frames.iter().map(|f| f.from).collect();
        // A key frame never comes back within m steps, unless the fallback had to allow it.
        let repeats = keys
            .windows(m + 1)
            .filter(|w| w[1..].contains(&w[0]))
            .count();
        assert!(repeats * 1000 <= keys.len(), "m = {m}: {repeats} repeats");
    }
}

#[test]
fn probabilities_are_row_stochastic() {
    let clip = wave_clip(6, 40, PERIOD as f32, 0.3);
    let map = JumpMap::analyze(&clip, &JumpMapParams::default()).unwrap();
    for m in [
        map.position_probabilities(),
        map.velocity_probabilities(),
        map.jump_map(),
        map.sampling_matrix(),
    ] {
        for i in 0..m.n() {
            assert_close(m.row(i).iter().sum(), 1.0, 1e-12);
            assert!(m.row(i).iter().all(|p| (0.0..=1.0).contains(p)));
        }
    }
    // The natural successor is the most probable target (eq. 3.3: D_{i+1,i+1} = 0).
    for i in 0..39 {
        let row = map.position_probabilities().row(i);
        assert!(row.iter().all(|p| *p <= row[i + 1]));
    }
    // Normalised D has mean off-diagonal 1.
    let d = map.distances();
    let mean = d.as_slice().iter().sum::<f64>() / (40.0 * 39.0);
    assert_close(mean, 1.0, 1e-12);
}
