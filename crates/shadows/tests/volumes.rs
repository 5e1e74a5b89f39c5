//! Volume construction against exact identities: every volume is a closed, outward-wound
//! surface whose enclosed volume is the sum of its casting faces' prisms; silhouettes of a
//! closed solid are exactly its light-facing/back-facing edges; rebuilds allocate nothing.

mod common;

use std::collections::HashMap;

use common::*;
use glam::{DVec3, Vec3};
use shadows::Light;
use shadows::volume::{CasterTopology, Extrusion, ShadowVolume, Sides, VolumeParams};

/// A wavy open sheet (n × n quads) with folds, so some faces face away from the light.
fn sheet(n: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    height_field(n, 1.0, |x, z| 1.0 + 0.3 * (7.0 * x).sin() * (5.0 * z).cos())
}

fn build(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    light: &Light,
    sides: Sides,
    d: f64,
) -> ShadowVolume {
    let topology = CasterTopology::new(positions.len(), triangles).unwrap();
    let mut volume = ShadowVolume::new();
    let params = VolumeParams {
        sides,
        extrusion: Extrusion::Finite(d),
        origin: DVec3::ZERO,
        ..Default::default()
    };
    volume.build(&topology, positions, light, &params).unwrap();
    volume
}

fn corners(tri: &[[f32; 4]]) -> [DVec3; 3] {
    [0, 1, 2].map(|k| DVec3::new(tri[k][0].into(), tri[k][1].into(), tri[k][2].into()))
}

/// Signed volume enclosed by a triangle soup (divergence theorem), f64.
fn enclosed(volume: &ShadowVolume) -> f64 {
    volume
        .vertices()
        .chunks_exact(3)
        .map(|t| {
            let [a, b, c] = corners(t);
            a.dot(b.cross(c)) / 6.0
        })
        .sum()
}

#[test]
fn a_directional_volume_encloses_the_sum_of_its_prisms() {
    // Prism of face f along −d over distance D: |n_f·d|/2 · D (n_f the unnormalised normal).
    let d = DVec3::new(0.3, 1.0, -0.2).normalize();
    let light = Light::Directional(d);
    let depth = 3.0;
    for (name, (positions, triangles), sides) in [
        (
            "sphere, one-sided",
            sphere(Vec3::new(0.2, 1.5, -0.1), 0.7, 3),
            Sides::One,
        ),
        ("sheet, two-sided", sheet(24), Sides::Two),
        ("sheet, one-sided", sheet(24), Sides::One),
    ] {
        let volume = build(&positions, &triangles, &light, sides, depth);
        let expected: f64 = triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| positions[i as usize].as_dvec3());
                let s = (b - a).cross(c - a).dot(d) / 2.0 * depth;
                match sides {
                    Sides::One => s.max(0.0),
                    Sides::Two => s.abs(),
                }
            })
            .sum();
        let got = enclosed(&volume);
        assert!(
            (got - expected).abs() <= 1e-5 * expected,
            "{name}: enclosed {got}, prisms {expected}"
        );
    }
}

#[test]
fn every_volume_is_a_closed_surface() {
    // Each directed edge (by its end points' bits) is matched by the reverse edge.
    let light = Light::Point(DVec3::new(0.4, 3.0, 0.2));
    for (positions, triangles, sides) in [
        {
            let (p, t) = sphere(Vec3::new(0.0, 1.0, 0.0), 0.5, 2);
            (p, t, Sides::One)
        },
        {
            let (p, t) = sheet(12);
            (p, t, Sides::Two)
        },
    ] {
        let volume = build(&positions, &triangles, &light, sides, 5.0);
        let mut edges: HashMap<([u32; 3], [u32; 3]), i32> = HashMap::new();
        let key = |v: [f32; 4]| [v[0].to_bits(), v[1].to_bits(), v[2].to_bits()];
        for t in volume.vertices().chunks_exact(3) {
            for k in 0..3 {
                let (a, b) = (key(t[k]), key(t[(k + 1) % 3]));
                *edges.entry((a.min(b), a.max(b))).or_default() += if a < b { 1 } else { -1 };
            }
        }
        let open = edges.values().filter(|&&c| c != 0).count();
        assert_eq!(open, 0, "{open} unmatched edges of {}", edges.len());
    }
}

#[test]
fn silhouettes_of_a_closed_solid_are_its_light_facing_back_facing_edges() {
    let (positions, triangles) = sphere(Vec3::ZERO, 1.0, 3);
    let light = Light::Directional(DVec3::new(0.1, 0.9, 0.3));
    let volume = build(&positions, &triangles, &light, Sides::One, 1.0);
    let topology = CasterTopology::new(positions.len(), &triangles).unwrap();
    assert_eq!(topology.border_edge_count(), 0);
    // Brute force: edges whose two faces disagree on facing.
    let facing: Vec<bool> = triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| positions[i as usize].as_dvec3());
            (b - a).cross(c - a).dot(DVec3::new(0.1, 0.9, 0.3)) > 0.0
        })
        .collect();
    let mut faces: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
    for (f, t) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            faces.entry((a.min(b), a.max(b))).or_default().push(f);
        }
    }
    let silhouettes = faces
        .values()
        .filter(|fs| facing[fs[0]] != facing[fs[1]])
        .count();
    let stats = volume.stats();
    assert_eq!(stats.silhouette_edges, silhouettes);
    assert_eq!(stats.quads, silhouettes);
    assert_eq!(stats.casting_faces, facing.iter().filter(|&&f| f).count());
    assert_eq!(stats.triangles() * 3, volume.vertices().len());
}

#[test]
fn infinite_extrusion_puts_far_vertices_at_w_zero_along_the_light() {
    let (positions, triangles) = sphere(Vec3::new(0.0, 2.0, 0.0), 0.5, 1);
    let l = DVec3::new(0.5, 6.0, -0.5);
    let topology = CasterTopology::new(positions.len(), &triangles).unwrap();
    let mut volume = ShadowVolume::new();
    let params = VolumeParams {
        sides: Sides::One,
        extrusion: Extrusion::Infinite,
        origin: DVec3::ZERO,
        ..Default::default()
    };
    volume
        .build(&topology, &positions, &Light::Point(l), &params)
        .unwrap();
    let mut at_infinity = 0;
    for v in volume.vertices() {
        if v[3] == 0.0 {
            at_infinity += 1;
            // Direction away from the light through some caster vertex.
            let dir = DVec3::new(v[0].into(), v[1].into(), v[2].into());
            assert!(positions.iter().any(|p| {
                let e = p.as_dvec3() - l;
                (e - dir).length() < 1e-5
            }));
        } else {
            assert_eq!(v[3], 1.0);
        }
    }
    assert!(at_infinity > 0);
    // Back caps and far quad ends: winding needs a bounded volume.
    assert_eq!(volume.winding_number(DVec3::ZERO, DVec3::Y), None);
}

#[test]
fn rebuilding_a_deforming_caster_allocates_nothing() {
    let (mut positions, triangles) = sheet(20);
    let topology = CasterTopology::new(positions.len(), &triangles).unwrap();
    let light = Light::Point(DVec3::new(0.3, 4.0, 0.1));
    let params = VolumeParams {
        sides: Sides::Two,
        extrusion: Extrusion::Infinite,
        origin: DVec3::ZERO,
        ..Default::default()
    };
    let mut volume = ShadowVolume::new();
    // Worst case first: every face casts when the sheet is flat.
    let flat: Vec<Vec3> = positions.iter().map(|p| Vec3::new(p.x, 1.0, p.z)).collect();
    volume.build(&topology, &flat, &light, &params).unwrap();
    let address = volume.vertices().as_ptr();
    for frame in 0..10 {
        for p in &mut positions {
            p.y += 0.02 * ((frame as f32) + p.x * 9.0).sin();
        }
        volume
            .build(&topology, &positions, &light, &params)
            .unwrap();
        assert_eq!(
            volume.vertices().as_ptr(),
            address,
            "frame {frame} reallocated"
        );
    }
}

#[test]
fn bad_casters_and_lights_are_named() {
    let (positions, triangles) = sheet(2);
    assert!(
        CasterTopology::new(3, &triangles)
            .unwrap_err()
            .to_string()
            .contains("names a vertex")
    );
    let topology = CasterTopology::new(positions.len(), &triangles).unwrap();
    let mut volume = ShadowVolume::new();
    let params = VolumeParams::default();
    let mut bad = positions.clone();
    bad[4] = Vec3::new(f32::NAN, 0.0, 0.0);
    let e = volume
        .build(&topology, &bad, &Light::Directional(DVec3::Y), &params)
        .unwrap_err();
    assert!(e.to_string().contains("vertex 4"), "{e}");
    let e = volume
        .build(
            &topology,
            &positions,
            &Light::Directional(DVec3::ZERO),
            &params,
        )
        .unwrap_err();
    assert!(e.to_string().contains("direction"), "{e}");
    let e = volume
        .build(
            &topology,
            &positions[1..],
            &Light::Directional(DVec3::Y),
            &params,
        )
        .unwrap_err();
    assert!(e.to_string().contains("positions"), "{e}");
    let finite = VolumeParams {
        extrusion: Extrusion::Finite(-1.0),
        ..params
    };
    let e = volume
        .build(
            &topology,
            &positions,
            &Light::Directional(DVec3::Y),
            &finite,
        )
        .unwrap_err();
    assert!(e.to_string().contains("extrusion"), "{e}");
}
