//! Shapes and a frame harness for the translucency tests.
#![allow(dead_code)]

use glam::{DVec3, Vec3};

/// A mesh: positions, normals, triangles.
pub struct Shape {
    pub positions: Vec<DVec3>,
    pub normals: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
}

impl Shape {
    /// The same shape moved by `offset`.
    pub fn offset(mut self, offset: DVec3) -> Self {
        for p in &mut self.positions {
            *p += offset;
        }
        self
    }

    /// Append another shape.
    pub fn merged(mut self, other: Shape) -> Self {
        let base = self.positions.len() as u32;
        self.positions.extend(other.positions);
        self.normals.extend(other.normals);
        self.triangles
            .extend(other.triangles.iter().map(|t| t.map(|i| i + base)));
        self
    }
}

/// A UV sphere of radius `r` (outward normals, counter-clockwise from outside).
pub fn sphere(r: f64, rings: u32, segments: u32) -> Shape {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for i in 0..=rings {
        let theta = std::f64::consts::PI * f64::from(i) / f64::from(rings);
        for j in 0..segments {
            let phi = 2.0 * std::f64::consts::PI * f64::from(j) / f64::from(segments);
            positions.push(
                DVec3::new(
                    theta.sin() * phi.cos(),
                    theta.cos(),
                    theta.sin() * phi.sin(),
                ) * r,
            );
        }
    }
    let idx = |i: u32, j: u32| i * segments + j % segments;
    for i in 0..rings {
        for j in 0..segments {
            let (a, b, c, d) = (idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1));
            triangles.push([a, c, b]);
            triangles.push([a, d, c]);
        }
    }
    let normals = positions.iter().map(|p| (*p / r).as_vec3()).collect();
    Shape {
        positions,
        normals,
        triangles,
    }
}

/// An axis-aligned box from `lo` to `hi` with flat faces (24 vertices, outward normals).
pub fn cuboid(lo: DVec3, hi: DVec3) -> Shape {
    let mut s = Shape {
        positions: Vec::new(),
        normals: Vec::new(),
        triangles: Vec::new(),
    };
    for axis in 0..3 {
        for side in [-1.0, 1.0] {
            let mut n = DVec3::ZERO;
            n[axis] = side;
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let base = s.positions.len() as u32;
            for (a, b) in [(0, 0), (1, 0), (1, 1), (0, 1)] {
                let mut p = DVec3::ZERO;
                p[axis] = if side > 0.0 { hi[axis] } else { lo[axis] };
                p[u] = if a == 0 { lo[u] } else { hi[u] };
                p[v] = if b == 0 { lo[v] } else { hi[v] };
                s.positions.push(p);
                s.normals.push(n.as_vec3());
            }
            // (u, v, n) is right-handed, so (0,0),(1,0),(1,1) winds counter-clockwise about +n.
            if side > 0.0 {
                s.triangles.push([base, base + 1, base + 2]);
                s.triangles.push([base, base + 2, base + 3]);
            } else {
                s.triangles.push([base, base + 2, base + 1]);
                s.triangles.push([base, base + 3, base + 2]);
            }
        }
    }
    s
}

#[cfg(feature = "gpu")]
mod gpu_frame {
    use super::*;
    use render::{Background, Camera, DrawMesh, FrameFormat, Renderer};
    use translucency::gpu::{PipelineParams, TranslucencyPass, TranslucentMesh};
    use translucency::model::{self, AccumulationFrame, Light};
    use translucency::{Material, Window};

    /// A pass built for `renderer`'s frame.
    pub fn pass(
        gpu: &gpu_context::GpuContext,
        renderer: &Renderer,
        params: PipelineParams,
    ) -> TranslucencyPass {
        TranslucencyPass::new(&gpu.device, &renderer.pass_context(), params).unwrap()
    }

    /// The world direction of a pixel's ray (NDC in [−1, 1]²).
    pub fn camera_ray(camera: &Camera, ndc: glam::DVec2) -> DVec3 {
        let inv = camera.clip_from_world().unwrap().as_dmat4().inverse();
        let near = inv * glam::DVec4::new(ndc.x, ndc.y, 0.5, 1.0);
        let far = inv * glam::DVec4::new(ndc.x, ndc.y, 0.9, 1.0);
        (far.truncate() / far.w - near.truncate() / near.w).normalize()
    }

    /// What [`render_black`] leaves: the context, the pass (for read-backs), the image, the camera.
    pub struct Rendered {
        pub gpu: gpu_context::GpuContext,
        pub pass: TranslucencyPass,
        pub image: gpu_context::HdrImage,
        pub camera: Camera,
    }

    /// Render `s` in black (single sample) with translucency added: E_t from `light` at unit
    /// power, the camera at `eye` looking at `target`, `size`² pixels.
    pub fn render_black(
        s: &Shape,
        light: Light,
        material: &Material,
        eye: DVec3,
        target: DVec3,
        params: PipelineParams,
        size: u32,
    ) -> Rendered {
        let gpu = gpu_context::testing::gpu_or_skip().expect("checked by the caller");
        let mut renderer = Renderer::new(&gpu.device, FrameFormat::single_sample(&gpu.device));
        let mut p = pass(&gpu, &renderer, params);
        let irr = model::transmitted_irradiance(
            &s.positions,
            &s.normals,
            &light,
            [1.0; 3],
            material.eta,
            |_| 1.0,
        );
        let mesh = TranslucentMesh {
            positions: &s.positions,
            normals: &s.normals,
            triangles: &s.triangles,
            irradiance: &irr,
        };
        p.prepare(&gpu.device, &gpu.queue, &mesh, light, material, eye, false)
            .unwrap();
        let world: Vec<Vec3> = s.positions.iter().map(|p| p.as_vec3()).collect();
        let black = vec![Vec3::ZERO; world.len()];
        renderer
            .gouraud
            .set_meshes(
                &gpu.device,
                &gpu.queue,
                &[DrawMesh {
                    positions: &world,
                    triangles: &s.triangles,
                    front: &black,
                    back: &black,
                }],
            )
            .unwrap();
        let camera = Camera::look_at(eye.as_vec3(), target.as_vec3(), Vec3::Y, 40.0, size, size);
        let image = renderer
            .render(
                &gpu.device,
                &gpu.queue,
                &camera,
                Background::Color([0.0; 3]),
                &[&p],
            )
            .unwrap();
        Rendered {
            gpu,
            pass: p,
            image,
            camera,
        }
    }

    /// Render `shape` in black with translucency added; compare every interior pixel of the slab's
    /// far face (z = −w/2, facing the camera) with eq. 12 evaluated in f64 with the GPU's own E_lm.
    /// `point`: a point light this many × scale behind the slab instead of a directional one.
    pub fn slab_frame_against_cpu(offset: DVec3, scale: f64, point: Option<f64>) -> (f64, usize) {
        let params = PipelineParams {
            window: Window::Gaussian { width: 5.0 },
            ..Default::default()
        };
        // Metres × scale; the material's millimetres follow.
        let w = 0.01 * scale;
        let s = cuboid(
            DVec3::new(-0.05 * scale, -0.05 * scale, -w / 2.0),
            DVec3::new(0.05 * scale, 0.05 * scale, w / 2.0),
        )
        .offset(offset);
        let material = Material::preset("skimmilk")
            .unwrap()
            .with_scale(1000.0 / scale)
            .unwrap();
        let light_dir = DVec3::new(0.2, 0.1, 1.0).normalize();
        let light = match point {
            Some(distance) => Light::Point(offset + light_dir * distance * scale),
            None => Light::Directional(light_dir),
        };
        let eye = DVec3::new(0.03, -0.02, -0.3) * scale + offset;
        let size = 64;
        let Rendered {
            gpu,
            pass: p,
            image,
            camera,
        } = render_black(&s, light, &material, eye, offset, params, size);
        let sh = p
            .read_coefficients(&gpu.device, &gpu.queue)
            .unwrap()
            .windowed(params.window);
        let frame = AccumulationFrame::of_points(s.positions.iter().copied()).unwrap();
        let (mut worst, mut count) = (0.0f64, 0usize);
        for y in 0..size as usize {
            for x in 0..size as usize {
                // The pixel's ray in f64 against the plane z = −w/2 (offset).
                let ndc = glam::DVec2::new(
                    (x as f64 + 0.5) / size as f64 * 2.0 - 1.0,
                    1.0 - (y as f64 + 0.5) / size as f64 * 2.0,
                );
                let dir = camera_ray(&camera, ndc);
                let plane_z = offset.z - w / 2.0;
                let t = (plane_z - eye.z) / dir.z;
                let hit = eye + t * dir;
                let local = hit - offset;
                if local.x.abs() > 0.035 * scale || local.y.abs() > 0.035 * scale {
                    continue;
                }
                // The chord along the oblique light ray through the hit point: w / |cos|.
                let towards = light.towards(hit);
                let chord = w / towards.z.abs();
                let want = model::scattered_radiance(
                    &material,
                    &sh,
                    &frame,
                    hit,
                    DVec3::NEG_Z,
                    eye - hit,
                    chord,
                    false,
                );
                let got = image.pixels()[y * size as usize + x];
                for c in 0..3 {
                    let rel = (f64::from(got[c]) - want[c]).abs() / want[c].abs().max(1e-12);
                    worst = worst.max(rel);
                }
                count += 1;
            }
        }
        (worst, count)
    }
}
#[cfg(feature = "gpu")]
pub use gpu_frame::*;
