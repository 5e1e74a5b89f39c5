//! The shared frame with stencil shadows against exact rays, pixel by pixel: a sphere over a
//! ground quad. Pixels within one pixel of a shadow boundary, an object silhouette or the
//! sphere are not compared.

use super::sphere;
use glam::{DVec3, Vec3, Vec4};
use occlusion_gpu::{RayCaster, Scene};
use render::{Background, Camera, DepthConvention, DrawMesh, FrameFormat, Renderer};
use shadows::frame::{FrameLight, Receiver, SmoothBoundary, StencilShadows};
use shadows::volume::{CasterTopology, Extrusion, ShadowVolume, Sides, VolumeParams};
use shadows::{BoundaryTexture, Counting, Light};

pub const SIZE: u32 = 96;
pub const GROUND: f32 = 4.0;

pub struct Scenery {
    pub caster: (Vec<Vec3>, Vec<[u32; 3]>),
    pub ground: (Vec<Vec3>, Vec<[u32; 3]>),
    pub rays: RayCaster,
}

pub fn scenery() -> Scenery {
    scenery_at(1.0)
}

/// [`scenery`] with every coordinate multiplied by `scale`.
pub fn scenery_at(scale: f32) -> Scenery {
    scenery_of(Vec3::new(0.0, 2.0, 0.0), scale)
}

/// The sphere of radius 1 centred at `centre` over the ground, every coordinate multiplied by
/// `scale`.
pub fn scenery_of(centre: Vec3, scale: f32) -> Scenery {
    let (points, triangles) = sphere(centre, 1.0, 3);
    let caster = (
        points.iter().map(|p| *p * scale).collect::<Vec<_>>(),
        triangles,
    );
    let g = GROUND * scale;
    let ground = (
        vec![
            Vec3::new(-g, 0.0, -g),
            Vec3::new(g, 0.0, -g),
            Vec3::new(g, 0.0, g),
            Vec3::new(-g, 0.0, g),
        ],
        vec![[0, 2, 1], [0, 3, 2]],
    );
    let scene = Scene::single(
        caster.0.clone(),
        vec![Vec3::Y; caster.0.len()],
        caster.1.clone(),
    )
    .unwrap();
    let rays = RayCaster::new(&scene).unwrap();
    Scenery {
        caster,
        ground,
        rays,
    }
}

/// Renders the ground's direct light from `lights` (unit albedo, radiance = intensity/π · cos)
/// over an ambient radiance `ambient` on the ground; the sphere is black.
pub fn render(
    s: &Scenery,
    camera: &Camera,
    lights: &[(Light, f32)],
    ambient: f32,
    counting: Counting,
) -> Option<Vec<[f32; 4]>> {
    render_with(s, camera, lights, ambient, counting, None)
}

/// [`render`] with eq. 5.6's smooth boundary on every light (the ground casts nothing).
pub fn render_with(
    s: &Scenery,
    camera: &Camera,
    lights: &[(Light, f32)],
    ambient: f32,
    counting: Counting,
    boundary: Option<SmoothBoundary>,
) -> Option<Vec<[f32; 4]>> {
    let gpu = gpu_context::testing::gpu_or_skip()?;
    let format =
        FrameFormat::single_sample(&gpu.device).with_depth(DepthConvention::ReversedInfinite);
    let mut renderer = Renderer::new(&gpu.device, format);
    let black = vec![Vec3::ZERO; s.caster.0.len()];
    let ambient = vec![Vec3::splat(ambient); 4];
    renderer
        .gouraud
        .set_meshes(
            &gpu.device,
            &gpu.queue,
            &[
                DrawMesh {
                    positions: &s.ground.0,
                    triangles: &s.ground.1,
                    front: &ambient,
                    back: &ambient,
                },
                DrawMesh {
                    positions: &s.caster.0,
                    triangles: &s.caster.1,
                    front: &black,
                    back: &black,
                },
            ],
        )
        .unwrap();
    let mut effect = StencilShadows::new(
        &gpu.device,
        &renderer.pass_context(),
        &BoundaryTexture::step(1024),
        counting,
    )
    .unwrap();
    let normals = vec![Vec3::Y; 4];
    let albedo = vec![Vec3::ONE; 4];
    effect
        .set_receivers(
            &gpu.device,
            &[Receiver {
                positions: &s.ground.0,
                normals: &normals,
                albedo: &albedo,
                triangles: &s.ground.1,
                casts: false,
            }],
        )
        .unwrap();
    let topology = CasterTopology::new(s.caster.0.len(), &s.caster.1).unwrap();
    let volumes: Vec<ShadowVolume> = lights
        .iter()
        .map(|(light, _)| {
            let mut v = ShadowVolume::new();
            let params = VolumeParams {
                sides: Sides::One,
                extrusion: Extrusion::Infinite,
                origin: DVec3::ZERO,
                ..Default::default()
            };
            v.build(&topology, &s.caster.0, light, &params).unwrap();
            v
        })
        .collect();
    let frame_lights: Vec<FrameLight> = lights
        .iter()
        .zip(&volumes)
        .map(|((light, intensity), volume)| FrameLight {
            light: *light,
            intensity: Vec3::splat(*intensity),
            volume,
            boundary,
        })
        .collect();
    effect
        .set_lights(&gpu.device, &gpu.queue, &frame_lights)
        .unwrap();
    let image = renderer
        .render(
            &gpu.device,
            &gpu.queue,
            camera,
            Background::Color([0.0; 3]),
            &[&effect],
        )
        .unwrap();
    Some(image.pixels().to_vec())
}

/// The exact radiance of each pixel's ground point (None: sky, sphere in front, off the
/// ground): ambient + Σ lights not blocked · intensity/π · cos.
pub fn exact(
    s: &Scenery,
    camera: &Camera,
    lights: &[(Light, f32)],
    ambient: f32,
) -> Vec<Option<f32>> {
    let inverse = camera
        .clip_from_world_with(DepthConvention::ReversedInfinite)
        .unwrap()
        .inverse();
    let offset = f64::from(occlusion_gpu::DEFAULT_OFFSET_RELATIVE * s.rays.diagonal());
    let mut out = Vec::new();
    for y in 0..SIZE {
        for x in 0..SIZE {
            let ndc = |z: f32| {
                let p = inverse
                    * Vec4::new(
                        (x as f32 + 0.5) / SIZE as f32 * 2.0 - 1.0,
                        1.0 - (y as f32 + 0.5) / SIZE as f32 * 2.0,
                        z,
                        1.0,
                    );
                (p.truncate() / p.w).as_dvec3()
            };
            let (a, b) = (ndc(1.0), ndc(0.5));
            let dir = (b - a).normalize();
            let eye = camera.eye.as_dvec3();
            let t = -eye.y / dir.y;
            let p = eye + dir * t;
            let forward = (camera.target - camera.eye).normalize().as_dvec3();
            let in_front = (p - eye).dot(forward) > f64::from(camera.near) * 1.01;
            let on_ground = t > 0.0
                && in_front
                && p.x.abs() < f64::from(GROUND)
                && p.z.abs() < f64::from(GROUND);
            let hidden = on_ground
                && s.rays.occluded(
                    s.rays.centred(eye),
                    (p - eye).as_vec3(),
                    1.0,
                    &mut Default::default(),
                );
            if !on_ground || hidden {
                out.push(None);
                continue;
            }
            let mut radiance = ambient;
            for (light, intensity) in lights {
                let l = light.towards(p);
                let origin = p + l * offset;
                let blocked = match light {
                    Light::Point(q) => s.rays.occluded(
                        s.rays.centred(origin),
                        (*q - origin).as_vec3(),
                        1.0,
                        &mut Default::default(),
                    ),
                    Light::Directional(d) => s.rays.occluded(
                        s.rays.centred(origin),
                        d.as_vec3(),
                        f32::INFINITY,
                        &mut Default::default(),
                    ),
                };
                if !blocked {
                    let falloff = match light {
                        Light::Point(q) => 1.0 / (*q - p).length_squared(),
                        Light::Directional(_) => 1.0,
                    };
                    radiance +=
                        (f64::from(*intensity) / std::f64::consts::PI * l.y * falloff) as f32;
                }
            }
            out.push(Some(radiance));
        }
    }
    out
}

/// Asserts GPU = exact (relative 1e-3) on every pixel whose 3 × 3 neighbourhood is all on
/// the ground and in one exact shadow class; returns (compared, skipped) pixel counts.
pub fn agree(name: &str, gpu: &[[f32; 4]], exact: &[Option<f32>]) -> (usize, usize) {
    let n = SIZE as usize;
    let (mut compared, mut skipped) = (0, 0);
    for y in 0..n {
        for x in 0..n {
            let Some(e) = exact[y * n + x] else { continue };
            let uniform = (y.saturating_sub(1)..=(y + 1).min(n - 1)).all(|yy| {
                (x.saturating_sub(1)..=(x + 1).min(n - 1)).all(|xx| {
                    exact[yy * n + xx].is_some_and(|v| (v > e * 0.8 && v < e * 1.25) || v == e)
                })
            });
            if !uniform {
                skipped += 1;
                continue;
            }
            compared += 1;
            let g = gpu[y * n + x][0];
            assert!(
                (g - e).abs() <= 1e-3 * e.max(1e-2),
                "{name}: pixel ({x}, {y}) GPU {g}, exact {e}"
            );
        }
    }
    assert!(
        compared > n * n / 8,
        "{name}: only {compared} pixels compared"
    );
    (compared, skipped)
}

/// Z-fail must equal the rays; z-pass must too when `z_pass_right`, and must be wrong on
/// some pixels otherwise (the eye inside a volume, the near plane cutting one).
pub fn check(
    name: &str,
    camera: Camera,
    lights: &[(Light, f32)],
    ambient: f32,
    z_pass_right: bool,
) {
    let s = scenery();
    let Some(gpu) = render(&s, &camera, lights, ambient, Counting::ZFail) else {
        return;
    };
    let exact = exact(&s, &camera, lights, ambient);
    let (compared, skipped) = agree(name, &gpu, &exact);
    eprintln!("{name}: {compared} pixels equal, {skipped} at boundaries");
    let Some(z_pass) = render(&s, &camera, lights, ambient, Counting::ZPass) else {
        return;
    };
    let wrong = exact
        .iter()
        .zip(&z_pass)
        .filter(|(e, g)| e.is_some_and(|e| (g[0] - e).abs() > 0.1 * e.max(0.1)))
        .count();
    eprintln!("{name}: z-pass wrong on {wrong} pixels");
    if z_pass_right {
        let _ = agree(&format!("{name} (z-pass)"), &z_pass, &exact);
    } else {
        assert!(
            wrong > (SIZE * SIZE / 50) as usize,
            "{name}: z-pass wrong on only {wrong} pixels"
        );
    }
}

pub fn sun() -> Light {
    Light::Directional(DVec3::new(0.3, 1.0, 0.2).normalize())
}
