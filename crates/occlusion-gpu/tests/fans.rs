//! Fans (64 rays from one origin, `RayCaster::unoccluded_fan`) against f64 brute-force ray
//! casting and against the single-ray query they replace.

mod common;

use common::*;
use glam::{DVec3, Vec3};
use lightsphere::Lightsphere;
use occlusion_gpu::{FAN_GROUP, FAN_SIZE, RayCaster, RayFan, Scene, SceneObject};

/// Every lane of every fan, from every vertex of the sphere over the plane (pushed off its
/// surface as the hemicube builder does) towards the level-3 lightsphere directions above
/// its tangent plane, equals an f64 brute-force cast over all triangles and the single-ray
/// query, except rays within float noise of an edge (≤ 1e-4 of the lanes).
#[test]
fn fans_match_brute_force_and_single_rays() {
    let scene = sphere_over_plane();
    let caster = RayCaster::new(&scene).unwrap();
    let positions: Vec<DVec3> = caster.triangles().flatten().map(|p| p.as_dvec3()).collect();
    let triangles: Vec<[u32; 3]> = (0..positions.len() as u32 / 3)
        .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
        .collect();
    let sphere = Lightsphere::new(3).unwrap();
    let offset = 1e-4 * caster.diagonal();
    let (mut lanes, mut vs_brute, mut vs_single, mut open) = (0usize, 0usize, 0usize, 0usize);
    let mut fan = RayFan::new();
    for (position, normal) in caster.receivers() {
        let origin = position + normal * offset;
        let above: Vec<Vec3> = sphere
            .directions_f64()
            .iter()
            .map(|d| d.as_vec3())
            .filter(|d| d.dot(normal) > 1e-3)
            .collect();
        for chunk in above.chunks(FAN_SIZE) {
            fan.clear();
            for d in chunk {
                // Directions of any length: t is in their units.
                fan.push(*d * 2.5);
            }
            let result = caster.unoccluded_fan(origin, &fan, fan.full_mask(), f32::INFINITY);
            for (lane, d) in chunk.iter().enumerate() {
                let escapes = result >> lane & 1 == 1;
                let brute =
                    !brute_force_hit(&positions, &triangles, origin.as_dvec3(), d.as_dvec3());
                let single = !caster.occluded(origin, *d, f32::INFINITY, &mut Default::default());
                lanes += 1;
                open += usize::from(escapes);
                vs_brute += usize::from(escapes != brute);
                vs_single += usize::from(escapes != single);
            }
        }
    }
    assert!(lanes > 100_000, "{lanes} lanes");
    assert!(
        vs_brute * 10_000 <= lanes && vs_single * 10_000 <= lanes,
        "{vs_brute} lanes differ from brute force, {vs_single} from single rays, of {lanes}"
    );
    assert!(open > lanes / 4 && open < lanes, "{open} of {lanes} open");
}

/// A unit square (two triangles) at height 1 over the origin, wound either way.
fn square(flip: bool) -> Scene {
    let positions = vec![
        Vec3::new(-0.5, -0.5, 1.0),
        Vec3::new(0.5, -0.5, 1.0),
        Vec3::new(0.5, 0.5, 1.0),
        Vec3::new(-0.5, 0.5, 1.0),
    ];
    let mut triangles = vec![[0, 1, 2], [0, 2, 3]];
    if flip {
        triangles.iter_mut().for_each(|t| t.swap(1, 2));
    }
    let mut scene = Scene::new();
    scene
        .push(SceneObject::new(positions, vec![Vec3::Z; 4], triangles).occluder_only())
        .unwrap();
    // A receiver below the square: the caster centres coordinates on the scene's box.
    scene
        .push(SceneObject::new(
            vec![Vec3::ZERO],
            vec![Vec3::Z],
            Vec::new(),
        ))
        .unwrap();
    scene
}

/// `max_distance` is in the directions' units and both faces occlude: rays of length-2
/// directions towards the square at distance 1 are blocked for max 0.51 and free for 0.49.
#[test]
fn max_distance_and_both_faces() {
    for flip in [false, true] {
        let caster = RayCaster::new(&square(flip)).unwrap();
        let origin = caster.centred(DVec3::ZERO);
        let mut fan = RayFan::new();
        for i in 0..FAN_SIZE {
            let (x, y) = ((i % 8) as f32 / 8.0 - 0.45, (i / 8) as f32 / 8.0 - 0.45);
            fan.push(2.0 * Vec3::new(x, y, 1.0));
        }
        let all = fan.full_mask();
        assert_eq!(all, u64::MAX);
        assert_eq!(
            caster.unoccluded_fan(origin, &fan, all, 0.49),
            all,
            "flip {flip}"
        );
        assert_eq!(
            caster.unoccluded_fan(origin, &fan, all, 0.51),
            0,
            "flip {flip}"
        );
        assert_eq!(caster.unoccluded_fan(origin, &fan, all, f32::INFINITY), 0);
        // Only the lanes asked about come back.
        assert_eq!(caster.unoccluded_fan(origin, &fan, 0b1010, 0.49), 0b1010);
    }
}

/// Directions through the square's diagonal (the edge its two triangles share) and through
/// its corners never leak; directions just outside its border escape. Groups left short by
/// `finish_group`, and zero or NaN directions, hold no ray.
#[test]
fn shared_edges_do_not_leak_and_short_groups_are_empty() {
    let caster = RayCaster::new(&square(false)).unwrap();
    let origin = caster.centred(DVec3::ZERO);
    let mut fan = RayFan::new();
    let mut inside = 0u64;
    for i in 0..40 {
        let t = -0.5 + (i as f32 + 0.5) / 40.0;
        inside |= 1 << fan.push(Vec3::new(t, t, 1.0));
    }
    for corner in [(-0.5, -0.5), (0.5, 0.5)] {
        inside |= 1 << fan.push(Vec3::new(corner.0, corner.1, 1.0));
    }
    fan.finish_group();
    assert_eq!(fan.len() % FAN_GROUP, 0);
    let mut outside = 0u64;
    for t in [-0.3f32, 0.0, 0.3] {
        outside |= 1 << fan.push(Vec3::new(0.5001, t, 1.0));
        outside |= 1 << fan.push(Vec3::new(t, -0.5001, 1.0));
    }
    // Directions that point nowhere take a lane but are never traced.
    let nowhere = [Vec3::ZERO, Vec3::new(f32::NAN, 0.0, 1.0)].map(|d| fan.push(d));
    fan.finish_group();
    assert_eq!(fan.full_mask(), inside | outside);
    assert!(nowhere.iter().all(|&l| fan.full_mask() >> l & 1 == 0));
    let open = caster.unoccluded_fan(origin, &fan, u64::MAX, f32::INFINITY);
    assert_eq!(open, outside, "open {open:#x}");
}

/// An origin in the plane of the triangles (det = 0 for every triangle): no ray crosses them,
/// and nothing becomes NaN.
#[test]
fn origin_in_the_plane_of_the_triangles() {
    let caster = RayCaster::new(&square(false)).unwrap();
    let origin = caster.centred(DVec3::new(2.0, 0.0, 1.0));
    let mut fan = RayFan::new();
    for d in [
        Vec3::NEG_X,
        Vec3::new(-1.0, 0.1, 0.0),
        Vec3::new(-1.0, 0.0, 1e-7),
    ] {
        fan.push(d);
    }
    let all = fan.full_mask();
    assert_eq!(caster.unoccluded_fan(origin, &fan, all, f32::INFINITY), all);
}
