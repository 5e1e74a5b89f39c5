//! The adaptive lightsphere level (paper 000 §4.2) on synthetic frame times: drops under load,
//! rises when fast, never leaves its bounds, does not oscillate, and idle refinement equals a
//! direct computation at the final level.

mod common;

use std::time::Duration;

use common::*;
use lightsphere::{Lightsphere, direction_count};
use occlusion_gpu::{
    LevelChange, LevelController, LevelParams, OcclusionError, VisibilityEngine, VisibilityParams,
};

fn ms(x: f64) -> Duration {
    Duration::from_secs_f64(x / 1000.0)
}

fn controller(target_ms: f64, initial: u32) -> LevelController {
    LevelController::new(LevelParams::new(ms(target_ms)), initial).unwrap()
}

/// Feeds `time(level)` for `frames` frames; returns the level of every frame.
fn run(c: &mut LevelController, frames: usize, time: impl Fn(u32) -> Duration) -> Vec<u32> {
    (0..frames)
        .map(|_| {
            let level = c.level();
            c.record_frame(time(level));
            level
        })
        .collect()
}

/// Number of direction reversals (up then down or down then up) in a level sequence.
fn reversals(levels: &[u32]) -> usize {
    let steps: Vec<i64> = levels
        .windows(2)
        .map(|w| i64::from(w[1]) - i64::from(w[0]))
        .filter(|d| *d != 0)
        .collect();
    steps
        .windows(2)
        .filter(|s| s[0].signum() != s[1].signum())
        .count()
}

#[test]
fn drops_under_load_to_the_level_predicted_to_fit() {
    let mut c = controller(10.0, 3);
    // 40 ms at k = 258: k = 66 predicts 10.2 ms (over), k = 18 predicts 2.8 ms.
    assert_eq!(
        c.record_frame(ms(40.0)),
        LevelChange::Drop { from: 3, to: 1 }
    );
    assert_eq!(c.level(), 1);
    // Slightly over budget drops exactly one level.
    let mut c = controller(10.0, 3);
    assert_eq!(
        c.record_frame(ms(11.0)),
        LevelChange::Drop { from: 3, to: 2 }
    );
    // At the minimum it stays.
    let mut c = controller(10.0, 0);
    assert_eq!(c.record_frame(ms(1000.0)), LevelChange::Stay);
}

#[test]
fn rises_one_level_after_consecutive_fast_frames() {
    let mut c = controller(100.0, 0);
    assert_eq!(c.record_frame(ms(1.0)), LevelChange::Stay);
    assert_eq!(c.record_frame(ms(1.0)), LevelChange::Stay);
    assert_eq!(
        c.record_frame(ms(1.0)),
        LevelChange::Rise { from: 0, to: 1 }
    );
    // A slow frame in between restarts the count.
    assert_eq!(c.record_frame(ms(1.0)), LevelChange::Stay);
    assert_eq!(c.record_frame(ms(30.0)), LevelChange::Stay); // 30 × 66/18 = 110 > 80
    assert_eq!(c.record_frame(ms(1.0)), LevelChange::Stay);
    assert_eq!(c.record_frame(ms(1.0)), LevelChange::Stay);
    assert_eq!(
        c.record_frame(ms(1.0)),
        LevelChange::Rise { from: 1, to: 2 }
    );
}

#[test]
fn never_exceeds_bounds() {
    let params = LevelParams::new(ms(20.0)).with_levels(1, 3, 4);
    let mut c = LevelController::new(params, 2).unwrap();
    // A deterministic pseudo-random series over four orders of magnitude.
    let mut x = 12345u64;
    for _ in 0..2000 {
        x = x
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let t = 0.01 * 10f64.powf((x >> 11) as f64 / (1u64 << 53) as f64 * 4.0);
        c.record_frame(ms(t));
        assert!((1..=3).contains(&c.level()), "level {}", c.level());
    }
}

#[test]
fn constant_time_series_does_not_oscillate() {
    for t in [0.5, 5.0, 9.0, 12.0, 50.0, 500.0] {
        let mut c = controller(10.0, 2);
        let levels = run(&mut c, 60, |_| ms(t));
        assert_eq!(reversals(&levels), 0, "t = {t}: {levels:?}");
        assert_eq!(
            levels[50..],
            levels[59..60].repeat(10)[..],
            "t = {t} settles"
        );
    }
}

#[test]
fn cost_proportional_to_k_settles_on_the_finest_level_that_fits() {
    // t = c·k: with target 10 ms and c = 0.1 ms per direction, k = 66 takes 6.6 ms (fits),
    // k = 258 takes 25.8 ms (does not).
    for initial in 0..=3 {
        let mut c = controller(10.0, initial);
        let levels = run(&mut c, 40, |s| ms(0.1 * direction_count(s) as f64));
        assert!(reversals(&levels) <= 1, "{levels:?}");
        assert_eq!(levels[30..], [2; 10], "from {initial}: {levels:?}");
    }
}

#[test]
fn predicts_from_direction_ratio() {
    let t = LevelController::predict(ms(66.0), 2, 1);
    assert!((t.as_secs_f64() - 0.018).abs() < 1e-12);
}

#[test]
fn invalid_parameters_are_errors() {
    let p = LevelParams::new(ms(10.0));
    assert!(LevelController::new(LevelParams::new(Duration::ZERO), 1).is_err());
    assert!(
        LevelController::new(p, 5).is_err(),
        "initial above max_level"
    );
    assert!(
        LevelController::new(p.with_levels(2, 3, 4), 1).is_err(),
        "initial below min"
    );
    assert!(
        LevelController::new(p.with_levels(0, 4, 3), 1).is_err(),
        "max above idle max"
    );
    assert!(
        LevelController::new(p.with_levels(0, 3, 9), 1).is_err(),
        "idle max above 8"
    );
    assert!(LevelController::new(p.with_rise(0.0, 3), 1).is_err());
    assert!(LevelController::new(p.with_rise(0.8, 0), 1).is_err());
    assert!(matches!(
        LevelController::new(p.with_rise(1.5, 3), 1),
        Err(OcclusionError::InvalidParameter { .. })
    ));
}

#[test]
fn idle_refinement_equals_direct_compute_at_the_final_level() {
    let scene = sphere_over_plane();
    let params = LevelParams::new(ms(10.0)).with_levels(0, 1, 3);
    let c = LevelController::new(params, 1).unwrap();
    let mut engine = VisibilityEngine::cpu(VisibilityParams::default());
    let mut matrix = engine.compute(&scene, &c.sphere().unwrap()).unwrap();
    let mut levels = Vec::new();
    while let Some(level) = c.refine_idle(&mut engine, &scene, &mut matrix).unwrap() {
        levels.push(level);
        assert!(levels.len() <= 2, "stops at max_idle_level");
    }
    assert_eq!(levels, [2, 3]);
    assert_eq!(
        c.level(),
        1,
        "idle refinement leaves the animated level alone"
    );
    let direct = engine
        .compute(&scene, &Lightsphere::new(3).unwrap())
        .unwrap();
    assert_eq!(matrix, direct);
    assert_eq!(matrix.ambient(), direct.ambient());
}

#[test]
fn idle_refinement_stops_at_the_maximum() {
    let scene = sphere_over_plane();
    let c = controller(10.0, 1);
    let mut engine = VisibilityEngine::cpu(VisibilityParams::default());
    let mut matrix = engine
        .compute(&scene, &Lightsphere::new(4).unwrap())
        .unwrap();
    // Already at the idle maximum (4): nothing to do.
    assert_eq!(
        c.refine_idle(&mut engine, &scene, &mut matrix).unwrap(),
        None
    );
}
