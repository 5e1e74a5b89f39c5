//! The eight-lane (AVX2) traversal and packing against the four-lane and scalar ones.

use glam::{Vec3, Vec3A};
use obvhs::BvhBuildParams;

use super::{FanTracer, Packed, PreparedDirections, RayFan, Stacks, fan_groups};
use crate::scene::{Prepared, Scene};

/// A crumpled sheet: a 40 × 40 grid with pseudo-random heights, so rays from it graze,
/// hit and escape in every proportion (the packets' AVX2 test reads it too).
pub(crate) fn crumpled() -> Scene {
    let n = 40u32;
    let mut state = 0x2545_f491_u32;
    let mut noise = || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        state as f32 / u32::MAX as f32
    };
    let positions: Vec<Vec3> = (0..n * n)
        .map(|i| {
            let (x, z) = ((i % n) as f32, (i / n) as f32);
            Vec3::new(x, 6.0 * noise() + (x * 0.3).sin() * 4.0, z)
        })
        .collect();
    let mut triangles = Vec::new();
    for z in 0..n - 1 {
        for x in 0..n - 1 {
            let i = z * n + x;
            triangles.push([i, i + 1, i + n]);
            triangles.push([i + 1, i + n + 1, i + n]);
        }
    }
    let normals = vec![Vec3::Y; positions.len()];
    Scene::single(positions, normals, triangles).unwrap()
}

/// The crumpled sheet, its fan tracer and the fans of the level-3 lightsphere.
fn sheet_and_fans() -> (Prepared, FanTracer, Vec<RayFan>) {
    let prepared = Prepared::new(&crumpled()).unwrap();
    let tracer = FanTracer::new(&prepared, BvhBuildParams::medium_build());
    let sphere = lightsphere::Lightsphere::new(3).unwrap();
    let directions: Vec<Vec3> = sphere.directions().to_vec();
    let fans = fan_groups(&directions)
        .iter()
        .map(|g| RayFan::from_group(&directions, g))
        .collect();
    (prepared, tracer, fans)
}

/// The AVX2 traversal answers every lane exactly as the four-lane one: same bits for
/// every vertex of a crumpled sheet, every fan of the level-3 lightsphere, to infinity
/// and within a finite distance.
#[test]
fn eight_lanes_answer_as_four_lanes() {
    if !std::is_x86_feature_detected!("avx2") {
        eprintln!("skipping: this CPU has no AVX2");
        return;
    }
    let (prepared, tracer, fans) = sheet_and_fans();
    let (mut lanes, mut open, mut differ) = (0u32, 0u32, 0u32);
    let mut stacks = Stacks::default();
    for receiver in &prepared.receivers {
        let origin = Vec3A::from(receiver.position) + Vec3A::Y * 1e-3;
        for fan in &fans {
            let mask = fan.full_mask();
            for max_t in [f32::INFINITY, 5.0] {
                let (o, t) = tracer.local(origin, max_t);
                let four = if max_t == f32::INFINITY {
                    tracer.traverse::<false>(o, fan, mask, t, &mut stacks)
                } else {
                    tracer.traverse::<true>(o, fan, mask, t, &mut stacks)
                };
                let eight = tracer.unoccluded(origin, fan, mask, max_t);
                lanes += mask.count_ones();
                open += four.count_ones();
                differ += (four ^ eight).count_ones();
            }
        }
    }
    assert_eq!(differ, 0, "{differ} of {lanes} lanes differ");
    assert!(
        open > lanes / 10 && open < lanes * 9 / 10,
        "{open} of {lanes} open"
    );
}

/// The lanes a fan hands to lone walks (four or fewer live in a subtree, four boxes per
/// step, the `single` module) answer as the lane groups do: same bits for every vertex of the crumpled sheet (from the
/// vertex itself, where the grid's integer coordinates put origins on box faces and the
/// lightsphere's axis directions make 0·∞, and from just above it), every fan of the level-3
/// lightsphere, to infinity and within a finite distance.
#[test]
fn single_lane_answers_as_lane_groups() {
    let (prepared, mut tracer, fans) = sheet_and_fans();
    let trace = |tracer: &FanTracer| {
        let mut out = Vec::new();
        for receiver in &prepared.receivers {
            for lift in [0.0, 1e-3] {
                let origin = Vec3A::from(receiver.position) + Vec3A::Y * lift;
                for fan in &fans {
                    for max_t in [f32::INFINITY, 5.0] {
                        out.push(tracer.unoccluded(origin, fan, fan.full_mask(), max_t));
                    }
                }
            }
        }
        out
    };
    assert!(tracer.single);
    let alone = trace(&tracer);
    tracer.single = false;
    let groups = trace(&tracer);
    let lanes: u32 = groups.iter().map(|m| m.count_ones()).sum();
    let differ: u32 = alone
        .iter()
        .zip(&groups)
        .map(|(a, b)| (a ^ b).count_ones())
        .sum();
    assert_eq!(differ, 0, "{differ} lanes differ");
    assert!(lanes > 0);
}

/// The AVX2 packing of each vertex's facing directions gives the scalar packing's lanes and
/// indices, for the level-4 lightsphere (1,026 directions, a partial last block) under 200
/// normals, and the fans filled from it hold exactly the facing directions, in order.
#[test]
fn packing_eight_at_a_time_answers_as_one_at_a_time() {
    if !std::is_x86_feature_detected!("avx2") {
        eprintln!("skipping: this CPU has no AVX2");
        return;
    }
    let sphere = lightsphere::Lightsphere::new(4).unwrap();
    let directions = sphere.directions();
    let mut wide = PreparedDirections::new(directions);
    assert!(wide.wide);
    let (mut facing, mut eight, mut one) = (Vec::new(), Packed::default(), Packed::default());
    let mut fan = RayFan::new();
    for i in 0..200 {
        let t = i as f32 * 0.731;
        let normal = Vec3::new(t.sin() * (1.3 * t).cos(), t.cos(), (0.7 * t).sin()).normalize();
        wide.facing(normal, &mut facing);
        wide.wide = true;
        wide.compact(&facing, &mut eight);
        wide.wide = false;
        wide.compact(&facing, &mut one);
        let expected: Vec<u32> = (0..directions.len() as u32)
            .filter(|&j| directions[j as usize].dot(normal) > 0.0)
            .collect();
        assert_eq!(one.len, expected.len());
        assert_eq!(eight.len, one.len);
        assert_eq!(&one.index[..one.len], &expected[..]);
        assert_eq!(&eight.index[..eight.len], &expected[..]);
        for k in 0..6 {
            assert_eq!(eight.lanes[k][..eight.len], one.lanes[k][..one.len]);
        }
        for start in (0..one.len).step_by(64) {
            let run = start..(start + 64).min(one.len);
            fan.fill(&eight, run.clone());
            assert_eq!(fan.full_mask().count_ones() as usize, run.len());
            for (lane, j) in run.enumerate() {
                assert_eq!(fan.direction(lane), directions[expected[j] as usize]);
            }
        }
    }
}
