//! Output frames from the clip's own vertices (issue #19): every key frame of a generated run
//! is a clip frame bit for bit whatever c, blends are position-space cross-fades, and a run's
//! frame-to-frame steps stay within the clip's own.

mod common;

use common::drape;

use anim_pca::{
    Blend, GeneratedFrame, JumpMap, JumpMapParams, LoopTable, PlaybackParams, Player, RootMotion,
};
use glam::Vec3;

fn frames_of(map: &JumpMap, clip: &[Vec<Vec3>], run: &[GeneratedFrame]) -> Vec<Vec<Vec3>> {
    let refs: Vec<&[Vec3]> = clip.iter().map(Vec::as_slice).collect();
    let offsets = map.root_offsets(run);
    run.iter()
        .zip(&offsets)
        .map(|(f, o)| {
            let mut out = vec![Vec3::ZERO; map.n_vertices()];
            map.exact_frame_into(&refs, f, *o, &mut out).unwrap();
            out
        })
        .collect()
}

/// RMS vertex displacement between two frames.
fn step(a: &[Vec3], b: &[Vec3]) -> f64 {
    let s: f64 = a
        .iter()
        .zip(b)
        .map(|(p, q)| f64::from((*p - *q).length_squared()))
        .sum();
    (s / a.len() as f64).sqrt()
}

#[test]
fn key_frames_are_the_clips_own_bit_for_bit_whatever_c() {
    let clip = drape();
    for components in [2, 4, 10] {
        let params = JumpMapParams {
            components,
            ..JumpMapParams::default()
        };
        let map = JumpMap::analyze(&clip, &params).unwrap();
        let run = Player::new(
            &map,
            &PlaybackParams {
                blend: Blend::Fixed(3),
                seed: 7,
                ..PlaybackParams::default()
            },
        )
        .unwrap()
        .generate(3_000);
        assert!(
            run.transitions.len() > 20,
            "c = {components}: a run with jumps"
        );
        let frames = frames_of(&map, &clip, &run.frames);
        let mut keys = 0;
        for (f, out) in run.frames.iter().zip(&frames) {
            if f.is_key() {
                keys += 1;
                let same = out
                    .iter()
                    .zip(&clip[f.from])
                    .all(|(a, b)| a.to_array().map(f32::to_bits) == b.to_array().map(f32::to_bits));
                assert!(
                    same,
                    "c = {components}: key frame {} differs from the clip",
                    f.from
                );
            } else {
                // A blend is the f64 cross-fade of its two clip frames, rounded once.
                let (a, b) = (&clip[f.from], &clip[f.to]);
                for ((o, p), q) in out.iter().zip(a).zip(b) {
                    let want = p.as_dvec3() * (1.0 - f.alpha) + q.as_dvec3() * f.alpha;
                    assert!(
                        (o.as_dvec3() - want).abs().max_element()
                            <= 1e-6 * (1.0 + want.abs().max_element())
                    );
                }
            }
        }
        assert!(keys > frames.len() / 2);
        // The rank-c reconstruction of the same key frames is off: the output did not use it.
        if components == 2 {
            let mut w = vec![0.0; map.components()];
            let mut rec = vec![Vec3::ZERO; map.n_vertices()];
            let worst = run
                .frames
                .iter()
                .filter(|f| f.is_key())
                .map(|f| {
                    f.weights_into(&map, &mut w);
                    map.reconstructor().reconstruct(&w, &mut rec).unwrap();
                    step(&rec, &clip[f.from])
                })
                .fold(0.0, f64::max);
            assert!(
                worst > 1e-4,
                "c = 2 reconstructs the drape to {worst}: a weak test"
            );
        }
    }
}

#[test]
fn generated_steps_stay_within_the_clips() {
    // The drape's core is its slow middle; a run plays it forever. Its steps — natural play,
    // cross-fades and the landing after them — stay within the largest step the core itself
    // takes, with the margin a blend spreads over b + 1 = 4 frames.
    let clip = drape();
    let map = JumpMap::analyze(&clip, &JumpMapParams::default()).unwrap();
    let core: Vec<usize> = (0..clip.len() - 1)
        .filter(|&i| map.core()[i] && map.core()[i + 1])
        .collect();
    let clip_steps: Vec<f64> = core.iter().map(|&i| step(&clip[i], &clip[i + 1])).collect();
    let clip_max = clip_steps.iter().copied().fold(0.0, f64::max);
    let clip_mean = clip_steps.iter().sum::<f64>() / clip_steps.len() as f64;
    let params = PlaybackParams {
        blend: Blend::Fixed(3),
        seed: 11,
        start_frame: core[0],
        ..PlaybackParams::default()
    };
    let run = Player::new(&map, &params).unwrap().generate(4_000);
    let frames = frames_of(&map, &clip, &run.frames);
    let steps: Vec<f64> = frames.windows(2).map(|w| step(&w[0], &w[1])).collect();
    // Past the way in (frames before the core are played once).
    let settled = &steps[clip.len()..];
    let run_max = settled.iter().copied().fold(0.0, f64::max);
    let run_mean = settled.iter().sum::<f64>() / settled.len() as f64;
    println!(
        "core step mean {clip_mean:.3e} max {clip_max:.3e}; run mean {run_mean:.3e} max {run_max:.3e}"
    );
    assert!(
        run_max <= 1.5 * clip_max,
        "run step {run_max} > 1.5 × clip's {clip_max}"
    );
    assert!(
        (0.67..=1.5).contains(&(run_mean / clip_mean)),
        "run mean step {run_mean} against the core's {clip_mean}"
    );
}

#[test]
fn loops_and_root_motion_use_the_clips_frames() {
    // A walk across the scene with root motion: natural play from frame 0 reproduces the clip
    // (offsets integrate the root's steps), and a loop's key frames are clip frames moved by
    // their offset alone.
    let wave = common::wave_clip(6, 60, 12.0, 0.0);
    let clip: Vec<Vec<Vec3>> = wave
        .iter()
        .enumerate()
        .map(|(t, f)| f.iter().map(|p| *p + Vec3::X * (0.05 * t as f32)).collect())
        .collect();
    let params = JumpMapParams {
        root_motion: RootMotion::Extract,
        ..JumpMapParams::default()
    };
    let map = JumpMap::analyze(&clip, &params).unwrap();
    let straight: Vec<GeneratedFrame> = (0..clip.len()).map(GeneratedFrame::key).collect();
    for (out, original) in frames_of(&map, &clip, &straight).iter().zip(&clip) {
        assert!(
            step(out, original) < 1e-5,
            "natural play moved the clip by {}",
            step(out, original)
        );
    }
    let table = LoopTable::build(&map, 0, 24, Blend::Fixed(3)).unwrap();
    let lp = table.get(24).expect("a 24-frame loop of a 12-frame wave");
    let run = lp.play(96);
    let offsets = map.root_offsets(&run.frames);
    let frames = frames_of(&map, &clip, &run.frames);
    for ((f, out), o) in run.frames.iter().zip(&frames).zip(&offsets) {
        if f.is_key() {
            let shift = *o - map.root(f.from);
            for (a, b) in out.iter().zip(&clip[f.from]) {
                assert_eq!(*a, *b + shift);
            }
        }
    }
    // The loop walks on: after four periods the root has travelled, not snapped back.
    assert!(
        offsets[95].x - offsets[0].x > 1.0,
        "{:?}",
        offsets[95] - offsets[0]
    );
}

#[test]
fn mismatched_clips_are_refused() {
    let clip = common::wave_clip(4, 20, 6.0, 0.0);
    let map = JumpMap::analyze(&clip, &JumpMapParams::default()).unwrap();
    let refs: Vec<&[Vec3]> = clip.iter().map(Vec::as_slice).collect();
    let mut out = vec![Vec3::ZERO; map.n_vertices()];
    let key = GeneratedFrame::key(3);
    assert!(
        map.exact_frame_into(&refs[1..], &key, Vec3::ZERO, &mut out)
            .is_err()
    );
    assert!(
        map.exact_frame_into(&refs, &key, Vec3::ZERO, &mut out[1..])
            .is_err()
    );
    assert!(
        map.exact_frame_into(&refs, &GeneratedFrame::key(20), Vec3::ZERO, &mut out)
            .is_err()
    );
    let short = vec![Vec3::ZERO; 3];
    let mut bad = refs.clone();
    bad[3] = &short;
    assert!(
        map.exact_frame_into(&bad, &key, Vec3::ZERO, &mut out)
            .is_err()
    );
}
