//! Synthetic clips shared by the tests.
#![allow(dead_code)]

use glam::Vec3;
use std::f32::consts::TAU;

/// A `side × side` grid waving with period `period` frames: two travelling waves (the
/// fundamental and the second harmonic) whose amplitude grows by `drift` over the clip
/// (`drift = 0`: exactly periodic).
pub fn wave_clip(side: usize, frames: usize, period: f32, drift: f32) -> Vec<Vec<Vec3>> {
    (0..frames)
        .map(|t| {
            let amp = 1.0 + drift * t as f32 / frames as f32;
            let ph = t as f32 / period * TAU;
            (0..side * side)
                .map(|n| {
                    let (x, y) = ((n % side) as f32, (n / side) as f32);
                    let z = amp * (ph + 0.5 * x).sin() + 0.3 * (2.0 * ph + 0.7 * y).cos();
                    Vec3::new(x, y, z)
                })
                .collect()
        })
        .collect()
}

/// `wave_clip` followed by a `tail`-frame non-looping ending: the grid bends away and settles
/// into a pose that no other frame resembles.
pub fn wave_with_tail(side: usize, frames: usize, period: f32, tail: usize) -> Vec<Vec<Vec3>> {
    let mut clip = wave_clip(side, frames, period, 0.0);
    let last = clip[frames - 1].clone();
    for k in 1..=tail {
        let s = k as f32 / tail as f32;
        clip.push(
            last.iter()
                .map(|v| *v + Vec3::new(0.0, 0.0, 4.0 * s * (1.0 + 0.1 * v.x)))
                .collect(),
        );
    }
    clip
}

/// Asserts |a − b| ≤ tol.
#[track_caller]
pub fn assert_close(a: f64, b: f64, tol: f64) {
    assert!((a - b).abs() <= tol, "{a} vs {b} (tolerance {tol})");
}

/// The synthetic drape (20 × 20 cloth over a sphere, 90 frames) the jump-map tests play.
pub fn drape() -> Vec<Vec<Vec3>> {
    let params = synth::ClothParams {
        grid: 20,
        frames: 90,
        ..Default::default()
    };
    synth::simulate_cloth(&params).unwrap().frames
}

/// Asserts that every loop of `table` obeys the no-oscillation rule (`LoopTable::min_run`):
/// each stretch of natural play lasts at least R(n) key frames, so the loop shows at least
/// R(n) distinct clip frames. Returns how many loops the table holds.
pub fn assert_acceptable(name: &str, table: &anim_pca::LoopTable) -> usize {
    let mut count = 0;
    for lp in table.iter() {
        let r = table.min_run(lp.len());
        assert!(
            lp.shortest_run() >= r && lp.distinct_frames() >= r,
            "{name}: loop of {} frames has a stretch of {} and {} distinct frames (R = {r})",
            lp.len(),
            lp.shortest_run(),
            lp.distinct_frames()
        );
        count += 1;
    }
    count
}
