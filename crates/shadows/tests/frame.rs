//! Stencil shadows in the shared frame against exact rays, pixel by pixel (tests/common/frame.rs):
//! a sphere over a ground quad seen from outside every volume; two lights accumulating, each
//! masked by its own stencil count, over an ambient term that stays in shadow — z-fail and
//! z-pass both equal the rays here. The eye inside a volume and the near plane cutting one, where
//! z-pass fails, are in `hard_cases.rs`. The same frame at scales 2⁻²⁴ and 2²⁰.

#![cfg(feature = "gpu")]

mod common;

use common::frame::*;
use glam::{DVec3, Vec3};
use render::Camera;
use shadows::{Counting, Light};

#[test]
fn seen_from_outside_every_volume_the_stencil_equals_rays() {
    let camera = Camera::look_at(
        Vec3::new(4.0, 5.0, 6.0),
        Vec3::new(-0.5, 0.0, -0.3),
        Vec3::Y,
        50.0,
        SIZE,
        SIZE,
    );
    check(
        "outside",
        camera,
        &[(sun(), std::f32::consts::PI)],
        0.0,
        true,
    );
}

/// The camera and lights of the two-lights frame for a scene scaled by `s` (the point light's
/// intensity by s², so that its radiance is the same).
fn two_lights_at(s: f32) -> (Camera, [(Light, f32); 2]) {
    let camera = Camera::look_at(
        Vec3::new(0.5, 7.0, 4.0) * s,
        Vec3::ZERO,
        Vec3::Y,
        60.0,
        SIZE,
        SIZE,
    );
    let point = Light::Point(DVec3::new(-1.5, 5.0, 0.5) * f64::from(s));
    (camera, [(sun(), 2.0), (point, 30.0 * s * s)])
}

#[test]
fn two_lights_accumulate_and_the_ambient_term_stays_in_shadow() {
    let (camera, lights) = two_lights_at(1.0);
    check("two lights", camera, &lights, 0.05, true);
}

/// The two lights' frame of a scene scaled by 2⁻²⁴ (the sphere 1.2 × 10⁻⁷ across) and by 2²⁰,
/// camera and point light with it and the point light's intensity by the square of the scale
/// (the same radiance), is the frame at scale 1 (relative 10⁻³, every pixel). The lit shader
/// once guarded the point light's 1/d² with an absolute floor of 10⁻¹² on d², which flattened
/// the falloff of every light nearer than 10⁻⁶ units.
#[test]
fn a_scene_at_any_scale_renders_the_same_frame() {
    let frame = |e: i32| {
        let s = 2f32.powi(e);
        let (camera, lights) = two_lights_at(s);
        render(&scenery_at(s), &camera, &lights, 0.05, Counting::ZFail)
    };
    let Some(reference) = frame(0) else { return };
    let lit = reference.iter().filter(|p| p[0] > 0.1).count();
    assert!(lit > (SIZE * SIZE / 4) as usize, "{lit} lit pixels");
    for e in [-24, 20] {
        let image = frame(e).unwrap();
        let differ = reference
            .iter()
            .zip(&image)
            .filter(|(a, b)| (a[0] - b[0]).abs() > 1e-3 * a[0].max(1e-2))
            .count();
        assert_eq!(differ, 0, "scale 2^{e}: {differ} pixels differ");
    }
}

/// Eq. 5.6's boundary (α = 15°) is the casters' own: a ground that casts nothing, under a sun
/// 10° up, is lit and shadowed exactly as without it (every pixel against the rays; the sphere
/// lowered to 0.2 above the ground, so that its long shadow starts on it). Applied to the
/// ground, the term blacked it out wherever light grazed it at under α — no shadow left to
/// see.
#[test]
fn a_low_sun_lights_a_ground_that_casts_nothing_despite_the_boundary() {
    use shadows::BoundaryMode;
    use shadows::frame::SmoothBoundary;
    let (camera, _) = two_lights_at(1.0);
    let low = DVec3::new(0.9, 10f64.to_radians().tan() * 0.9f64.hypot(0.3), 0.3).normalize();
    let lights = [(Light::Directional(low), 6.0)];
    let s = scenery_of(Vec3::new(0.0, 1.2, 0.0), 1.0);
    let boundary = SmoothBoundary {
        alpha_deg: 15.0,
        mode: BoundaryMode::Cosine,
    };
    let Some(gpu) = render_with(&s, &camera, &lights, 0.05, Counting::ZFail, Some(boundary)) else {
        return;
    };
    let exact = exact(&s, &camera, &lights, 0.05);
    let (compared, _) = agree("low sun", &gpu, &exact);
    let lit = exact.iter().flatten().filter(|&&e| e > 0.06).count();
    let dark = exact.iter().flatten().filter(|&&e| e <= 0.06).count();
    assert!(
        lit > compared / 4 && dark > 20,
        "{lit} lit, {dark} in shadow"
    );
}

/// The whole frame against [`shadows::exact_view_mask`]: a faceted sphere that casts on
/// itself and on the ground, both receivers (facet normals, so the light's term is dark
/// exactly where the facet faces away, as the exact mask's own-surface test is).
#[test]
fn the_frame_equals_the_exact_mask_of_its_view() {
    use render::{Background, DepthConvention, DrawMesh, FrameFormat, Renderer};
    use shadows::frame::{FrameLight, Receiver, StencilShadows};
    use shadows::volume::{CasterTopology, ShadowVolume, VolumeParams};
    use shadows::{BoundaryTexture, Counting};
    let Some(gpu) = gpu_context::testing::gpu_or_skip() else {
        return;
    };
    let s = scenery();
    // Unwelded sphere (facet normals) and the ground, drawn black; all receive.
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    for t in &s.caster.1 {
        let [a, b, c] = t.map(|i| s.caster.0[i as usize]);
        let n = (b - a).cross(c - a).normalize();
        positions.extend([a, b, c]);
        normals.extend([n; 3]);
    }
    let facets: Vec<[u32; 3]> = (0..s.caster.1.len() as u32)
        .map(|f| [3 * f, 3 * f + 1, 3 * f + 2])
        .collect();
    let meshes = [
        (&positions, &facets, normals.clone()),
        (&s.ground.0, &s.ground.1, vec![Vec3::Y; 4]),
    ];
    let format =
        FrameFormat::single_sample(&gpu.device).with_depth(DepthConvention::ReversedInfinite);
    let mut renderer = Renderer::new(&gpu.device, format);
    let blacks: Vec<Vec<Vec3>> = meshes.iter().map(|m| vec![Vec3::ZERO; m.0.len()]).collect();
    let draws: Vec<DrawMesh> = meshes
        .iter()
        .zip(&blacks)
        .map(|(m, b)| DrawMesh {
            positions: m.0,
            triangles: m.1,
            front: b,
            back: b,
        })
        .collect();
    renderer
        .gouraud
        .set_meshes(&gpu.device, &gpu.queue, &draws)
        .unwrap();
    let mut effect = StencilShadows::new(
        &gpu.device,
        &renderer.pass_context(),
        &BoundaryTexture::step(1024),
        Counting::ZFail,
    )
    .unwrap();
    let albedo: Vec<Vec<Vec3>> = meshes.iter().map(|m| vec![Vec3::ONE; m.0.len()]).collect();
    let receivers: Vec<Receiver> = meshes
        .iter()
        .zip(&albedo)
        .zip([true, false])
        .map(|((m, a), casts)| Receiver {
            positions: m.0,
            normals: &m.2,
            albedo: a,
            triangles: m.1,
            casts,
        })
        .collect();
    effect.set_receivers(&gpu.device, &receivers).unwrap();
    let light = Light::Point(DVec3::new(1.5, 5.0, 1.0));
    let mut volume = ShadowVolume::new();
    let topology = CasterTopology::new(s.caster.0.len(), &s.caster.1).unwrap();
    volume
        .build(&topology, &s.caster.0, &light, &VolumeParams::default())
        .unwrap();
    effect
        .set_lights(
            &gpu.device,
            &gpu.queue,
            &[FrameLight {
                light,
                intensity: Vec3::splat(30.0),
                volume: &volume,
                boundary: None,
            }],
        )
        .unwrap();
    let camera = Camera::look_at(
        Vec3::new(3.5, 4.0, 5.0),
        Vec3::new(-0.5, 0.8, -0.5),
        Vec3::Y,
        50.0,
        SIZE,
        SIZE,
    );
    let image = renderer
        .render(
            &gpu.device,
            &gpu.queue,
            &camera,
            Background::Color([0.0; 3]),
            &[&effect],
        )
        .unwrap();
    // The exact mask of the same view over the same triangles.
    let mut all_positions = positions.clone();
    let mut all_triangles = facets.clone();
    let base = all_positions.len() as u32;
    all_positions.extend(&s.ground.0);
    all_triangles.extend(s.ground.1.iter().map(|t| t.map(|i| i + base)));
    let exact = shadows::exact_view_mask(&all_positions, &all_triangles, &light, &camera).unwrap();
    let n = SIZE as usize;
    let (mut compared, mut lit, mut dark) = (0, 0, 0);
    for y in 1..n - 1 {
        for x in 1..n - 1 {
            let e = exact[y * n + x];
            let uniform =
                (y - 1..=y + 1).all(|yy| (x - 1..=x + 1).all(|xx| exact[yy * n + xx] == e));
            if e.is_nan() || !uniform {
                continue;
            }
            compared += 1;
            let gpu_shadowed = image.pixels()[y * n + x][0] <= 1e-6;
            assert_eq!(gpu_shadowed, e == 1.0, "pixel ({x}, {y}): exact {e}");
            if e == 1.0 { dark += 1 } else { lit += 1 }
        }
    }
    eprintln!("{compared} pixels equal ({lit} lit, {dark} in shadow)");
    assert!(lit > 1000 && dark > 300, "{lit} lit, {dark} dark");
}
