//! The real sequences in ../shared/data/anim (skipped with a warning when absent, a failure
//! under CI). Prints the measured numbers: analysis time, E(c), E*(c), playback statistics.

use std::time::Instant;

mod common;

use anim_pca::jumpmap::metrics::{reconstruction_errors, sequence_stats};
use anim_pca::{JumpMap, JumpMapParams, PlaybackParams, Player, RootMotion};

fn load(rel: &str) -> Option<Vec<Vec<glam::Vec3>>> {
    let path = test_data::shared_file(rel)?;
    let (anim, _report) =
        meshio::load_animation(&path, &meshio::AnimationOptions::default()).unwrap();
    Some(anim.frames)
}

fn report(name: &str, frames: &[Vec<glam::Vec3>]) -> JumpMap {
    let t = Instant::now();
    let map = JumpMap::analyze(frames, &JumpMapParams::default()).unwrap();
    let analysis = t.elapsed();
    let errors = reconstruction_errors(frames, &[0, 2, 4, 6, 8, 10]).unwrap();
    let run = Player::new(&map, &PlaybackParams::default())
        .unwrap()
        .generate(10_000);
    println!(
        "{name}: {} frames × {} vertices, analysis {:.3} s, c = {}, c* = {}",
        frames.len(),
        frames[0].len(),
        analysis.as_secs_f64(),
        map.components(),
        map.velocity_components()
    );
    for e in &errors {
        println!(
            "  c = {:2}: E = {:.4}, E* = {:.4}",
            e.components, e.position, e.velocity
        );
    }
    println!("  10k frames: {:?}", sequence_stats(&map, &run));
    for w in errors.windows(2) {
        assert!(
            w[1].position <= w[0].position * (1.0 + 1e-9),
            "E(c) decreases: {errors:?}"
        );
    }
    map
}

#[test]
fn horse_gallop_loop_is_found() {
    let Some(frames) = load("anim/horse-gallop") else {
        return;
    };
    let map = report("horse-gallop", &frames);
    let last = frames.len() - 1;
    // One cycle plus a closing frame: the last frame is closest to frame 0 …
    let d = map.distances();
    let nearest = (0..last)
        .min_by(|&a, &b| d.get(last, a).total_cmp(&d.get(last, b)))
        .unwrap();
    assert_eq!(nearest, 0, "frame {last} ≈ frame 0");
    // … so the second-last frame's best jump is to frame 0, and the last frame goes on at 1.
    assert!(
        map.best_jump(last - 1).unwrap() <= 1,
        "{:?}",
        map.best_jump(last - 1)
    );
    assert_eq!(map.best_jump(last), Some(1));
}

#[test]
fn chicken_crossing_plays() {
    let Some(frames) = load("anim/chickenCrossing") else {
        return;
    };
    let map = report("chickenCrossing", &frames);
    assert!(map.core().iter().filter(|c| **c).count() >= 2);
}

#[test]
fn chicken_crossing_with_root_motion_extracted() {
    let Some(frames) = load("anim/chickenCrossing") else {
        return;
    };
    let core = |root_motion| {
        let params = JumpMapParams {
            root_motion,
            ..JumpMapParams::default()
        };
        let map = JumpMap::analyze(&frames, &params).unwrap();
        let run = Player::new(&map, &PlaybackParams::default())
            .unwrap()
            .generate(20_000);
        let stats = sequence_stats(&map, &run);
        let n = map.core().iter().filter(|c| **c).count();
        println!(
            "chickenCrossing {root_motion:?}: core {n}/{}, {stats:?}",
            frames.len()
        );
        (n, stats)
    };
    let (kept, _) = core(RootMotion::Keep);
    let (extracted, stats) = core(RootMotion::Extract);
    assert!(
        extracted >= kept,
        "extraction shrank the core: {extracted} < {kept}"
    );
    assert!(stats.transitions > 0);
}

/// The loop table on every real clip and the synthetic drape (issue #19): every loop obeys
/// the no-oscillation rule, and the table of lengths 2 … 96 is printed for the note (length:
/// jumps, distinct frames, shortest stretch, cost).
#[test]
fn loops_of_the_real_clips_never_oscillate() {
    use anim_pca::{Blend, LoopTable};
    let mut clips = vec![("synthetic drape".to_owned(), common::drape())];
    for rel in [
        "anim/chickenCrossing",
        "anim/horse-gallop",
        "anim/gltf/BrainStem.glb",
    ] {
        if let Some(frames) = load(rel) {
            clips.push((rel.to_owned(), frames));
        }
    }
    for (name, frames) in &clips {
        let map = JumpMap::analyze(frames, &JumpMapParams::default()).unwrap();
        let t = Instant::now();
        let table = LoopTable::build(&map, 0, 96, Blend::Fixed(3)).unwrap();
        let built = t.elapsed().as_secs_f64();
        let mut lines = Vec::new();
        for n in [12, 24, 30, 48, 60, 96] {
            lines.push(match table.get(n) {
                Some(lp) => format!(
                    "{n}: {} jumps, {} distinct, run ≥ {}, cost {:.2}",
                    lp.transitions.len(),
                    lp.distinct_frames(),
                    lp.shortest_run(),
                    lp.cost
                ),
                None => format!("{n}: none"),
            });
        }
        println!(
            "{name} ({} frames, core {}): table 2..=96 in {built:.2} s; {}",
            frames.len(),
            table.core_frames(),
            lines.join("; ")
        );
        assert!(
            common::assert_acceptable(name, &table) > 0,
            "{name}: no loop at all"
        );
    }
}
