//! Per frame: the mesh and uniforms uploaded, passes 1–5 recorded (each timed on request).

use glam::DVec3;
use std::time::Instant;
use wgpu::util::DeviceExt;

use super::build::view;
use super::{
    BlurUniform, MeshBuffers, ParamsUniform, PassTimes, TranslucencyPass, TranslucentMesh, Vertex,
};
use crate::cube;
use crate::error::{TranslucencyError, bad_parameter};
use crate::material::Material;
use crate::model::{AccumulationFrame, Light};

/// The faces of a point light's six-face map that the object's box can reach: a face is left
/// out when all eight box corners lie outside one of its pyramid's four side planes
/// (conservative: a face drawn in vain costs time, a face missed would lose the thickness).
/// A light inside the box needs all six.
fn needed_faces(light: DVec3, frame: &AccumulationFrame) -> Vec<u32> {
    let corners: Vec<DVec3> = (0..8)
        .map(|i| {
            let s = DVec3::new(
                if i & 1 == 0 { -1.0 } else { 1.0 },
                if i & 2 == 0 { -1.0 } else { 1.0 },
                if i & 4 == 0 { -1.0 } else { 1.0 },
            );
            frame.centre + s * frame.half_extent - light
        })
        .collect();
    (0..6u32)
        .filter(|&f| {
            let [fwd, right, up] = cube::FACES[f as usize];
            [fwd - right, fwd + right, fwd - up, fwd + up]
                .iter()
                .all(|n| corners.iter().any(|v| v.dot(*n) >= 0.0))
        })
        .collect()
}

/// A point light farther than this many bounding radii from the object's centre draws its
/// distance map into one perspective face fitted to the bounding sphere, instead of the six
/// 90° faces around it: a 90° face spans 2D at distance D, so an object of radius R covered
/// size · R / D of its texels (3.4 of 512 at 150 R, where the bunny's whole body read as thin
/// and glowed).
const FITTED_MIN_RADII: f64 = 1.5;

/// A point light farther than this many bounding radii draws its distance map as a
/// directional light from its direction: f32 distances from it no longer resolve the object
/// (10⁴ radii: 10⁻³ of the radius), and its rays across the object differ from parallel by
/// under 10⁻⁴ rad. Only the map's geometry changes; the irradiance stays the caller's.
const DIRECTIONAL_MIN_RADII: f64 = 1e4;

/// Orthonormal (forward, right, up) for a directional light's map: forward = −l.
fn directional_basis(l: DVec3) -> [DVec3; 3] {
    let forward = -l;
    let helper = if forward.y.abs() < 0.9 {
        DVec3::Y
    } else {
        DVec3::X
    };
    let right = forward.cross(helper).normalize();
    let up = right.cross(forward);
    [forward, right, up]
}

fn vec4(v: DVec3, w: f64) -> [f32; 4] {
    [v.x as f32, v.y as f32, v.z as f32, w as f32]
}

fn check_mesh(mesh: &TranslucentMesh<'_>) -> Result<(), TranslucencyError> {
    let n = mesh.positions.len();
    if mesh.normals.len() != n || mesh.irradiance.len() != n {
        return Err(TranslucencyError::Mesh(format!(
            "{n} positions, {} normals, {} irradiance values",
            mesh.normals.len(),
            mesh.irradiance.len()
        )));
    }
    if mesh.triangles.is_empty() {
        return Err(TranslucencyError::Mesh("no triangles".into()));
    }
    if let Some((i, t)) = mesh
        .triangles
        .iter()
        .enumerate()
        .find(|(_, t)| t.iter().any(|&v| v as usize >= n))
    {
        return Err(TranslucencyError::Mesh(format!(
            "triangle {i} = {t:?} names a vertex ≥ {n}"
        )));
    }
    if let Some(i) = (0..n).find(|&i| {
        !mesh.normals[i].is_finite()
            || mesh.irradiance[i]
                .iter()
                .any(|v| !v.is_finite() || *v < 0.0)
    }) {
        return Err(TranslucencyError::Mesh(format!(
            "vertex {i}: normal {} or irradiance {:?} is not finite (or negative)",
            mesh.normals[i], mesh.irradiance[i]
        )));
    }
    Ok(())
}

impl TranslucencyPass {
    /// Run passes 1–5 for this frame's mesh, light, material and eye (world), leaving the
    /// matrices and the light maps on the GPU for [`render::FramePass::record`]. With `timed`, each
    /// pass is submitted and waited for, so [`PassTimes`] holds per-pass times (the frame is
    /// then slower than with one submission).
    ///
    /// # Errors
    /// A mesh whose slices disagree, with an index out of range, non-finite values, or no
    /// extent; a bad light; a GPU failure.
    #[allow(clippy::too_many_arguments)]
    pub fn prepare(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        mesh: &TranslucentMesh<'_>,
        light: Light,
        material: &Material,
        eye: DVec3,
        timed: bool,
    ) -> Result<PassTimes, TranslucencyError> {
        let start = Instant::now();
        check_mesh(mesh)?;
        let light = light.validated()?;
        if !eye.is_finite() {
            return Err(bad_parameter("eye", eye, "must be finite"));
        }
        let frame = AccumulationFrame::of_points(mesh.positions.iter().copied())?;
        let c = frame.centre;
        let vertices: Vec<Vertex> = (0..mesh.positions.len())
            .map(|i| Vertex {
                world: mesh.positions[i].as_vec3().to_array(),
                centred: (mesh.positions[i] - c).as_vec3().to_array(),
                normal: mesh.normals[i].to_array(),
                irradiance: mesh.irradiance[i],
            })
            .collect();
        let index_count = u32::try_from(mesh.triangles.len() * 3)
            .map_err(|_| TranslucencyError::Mesh("too many triangles".into()))?;
        match &self.mesh {
            Some(m) if m.vertex_count == vertices.len() && m.index_count == index_count => {
                queue.write_buffer(&m.vertices, 0, bytemuck::cast_slice(&vertices));
                queue.write_buffer(&m.indices, 0, bytemuck::cast_slice(mesh.triangles));
            }
            _ => {
                self.mesh = Some(MeshBuffers {
                    vertices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                        label: Some("translucency vertices"),
                        contents: bytemuck::cast_slice(&vertices),
                        usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
                    }),
                    indices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                        label: Some("translucency indices"),
                        contents: bytemuck::cast_slice(mesh.triangles),
                        usage: wgpu::BufferUsages::INDEX | wgpu::BufferUsages::COPY_DST,
                    }),
                    vertex_count: vertices.len(),
                    index_count,
                });
            }
        }
        let radius = frame.half_extent.length() * 1.01;
        let mut faces = [[0.0f32; 4]; 18];
        let light = match light {
            Light::Point(p) if (p - c).length() > DIRECTIONAL_MIN_RADII * radius => {
                Light::Directional((p - c).normalize())
            }
            other => other,
        };
        let (light_vec, near, far) = match light {
            Light::Point(p) => {
                let pc = p - c;
                let distance = pc.length();
                if distance > FITTED_MIN_RADII * radius {
                    // One face looking at the centre, its half-angle θ the bounding sphere's:
                    // forward.w = 1 / tan θ.
                    let scale = (distance * distance - radius * radius).sqrt() / radius;
                    let [f, r, u] = directional_basis(pc / distance);
                    (faces[0], faces[1], faces[2]) = (vec4(f, scale), vec4(r, 0.0), vec4(u, 0.0));
                    self.light_faces = vec![0];
                    let near = (distance - radius).max(distance * 1e-5);
                    (vec4(pc, 2.0), near, distance + radius)
                } else {
                    for (f, axes) in cube::FACES.iter().enumerate() {
                        for (k, a) in axes.iter().enumerate() {
                            faces[3 * f + k] = vec4(*a, if k == 0 { 1.0 } else { 0.0 });
                        }
                    }
                    self.light_faces = needed_faces(p, &frame);
                    let far = distance + radius;
                    (vec4(pc, 1.0), far * 1e-5, far)
                }
            }
            Light::Directional(l) => {
                for (k, a) in directional_basis(l).iter().enumerate() {
                    faces[k] = vec4(*a, 0.0);
                }
                self.light_faces = vec![0];
                (vec4(l, 0.0), 0.0, 0.0)
            }
        };
        let (tr, tp) = (material.sigma_tr(), material.sigma_t_prime());
        let h = self.params.window.factors();
        let mut uniform = ParamsUniform {
            half_extent: vec4(frame.half_extent, 6.0),
            light: light_vec,
            eye: vec4(eye - c, 1.0),
            sigma_tr: [
                tr[0] as f32,
                tr[1] as f32,
                tr[2] as f32,
                material.mm_per_unit as f32,
            ],
            sigma_t: [
                tp[0] as f32,
                tp[1] as f32,
                tp[2] as f32,
                material.eta as f32,
            ],
            misc: [
                self.params.intensity as f32,
                (radius * 1e-4) as f32,
                near as f32,
                far as f32,
            ],
            maps: [
                self.params.cube_size as f32,
                self.params.light_map_size as f32,
                radius as f32,
                if self.params.peel { 1.0 } else { 0.0 },
            ],
            window: [
                h[0] as f32,
                h[1] as f32,
                h[2] as f32,
                material.clamp_distance() as f32,
            ],
            light_faces: faces,
        };
        // Instance i of the light passes draws face light_faces[i].
        for (i, &f) in self.light_faces.iter().enumerate() {
            uniform.light_faces[3 * i + 1][3] = f as f32;
        }
        let mut blur = BlurUniform {
            size: [self.params.light_map_size as f32, 0.0, 0.0, 0.0],
            faces: [[0; 4]; 2],
        };
        for (i, &f) in self.light_faces.iter().enumerate() {
            blur.faces[i / 4][i % 4] = f;
        }
        queue.write_buffer(&self.blur_uniform, 0, bytemuck::bytes_of(&blur));
        queue.write_buffer(&self.params_buffer, 0, bytemuck::bytes_of(&uniform));
        queue.write_buffer(&self.window_buffer, 0, bytemuck::bytes_of(&uniform.window));
        let mut times = PassTimes::default();
        let wait = |device: &wgpu::Device| {
            device
                .poll(wgpu::PollType::wait_indefinitely())
                .map_err(|e| TranslucencyError::Gpu(gpu_context::GpuError::Readback(e.to_string())))
        };
        if timed {
            wait(device)?;
            times.upload = (Instant::now() - start).as_secs_f64() * 1e3;
        }
        let mut mark = Instant::now();
        let mut step = |device: &wgpu::Device, slot: &mut f64, encoder: wgpu::CommandEncoder| {
            queue.submit([encoder.finish()]);
            if timed {
                wait(device)?;
                let now = Instant::now();
                *slot = (now - mark).as_secs_f64() * 1e3;
                mark = now;
            }
            Ok::<(), TranslucencyError>(())
        };
        let new_encoder = |label| {
            device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(label) })
        };
        let m = self.mesh.as_ref().expect("uploaded above");

        // 1. The external cube map.
        let mut encoder = new_encoder("translucency cube map");
        self.draw_offscreen(
            &mut encoder,
            m,
            &self.cube_pipeline,
            None,
            &self.targets.cube,
            &self.targets.cube_depth,
            0.0,
            6,
        );
        step(device, &mut times.cube_map, encoder)?;

        // 2. SH projection and eq. 10.
        let mut encoder = new_encoder("translucency sh");
        self.record_sh(&mut encoder);
        step(device, &mut times.sh_projection, encoder)?;

        // 3–4. The light distance map and its peeled layer.
        let mut encoder = new_encoder("translucency light map");
        let faces = self.light_faces.len() as u32;
        self.draw_offscreen(
            &mut encoder,
            m,
            &self.distance_pipeline,
            None,
            &self.targets.first,
            &self.targets.light_depth,
            1.0,
            faces,
        );
        self.draw_offscreen(
            &mut encoder,
            m,
            &self.peel_pipeline,
            Some(&self.targets.peel_group),
            &self.targets.second,
            &self.targets.light_depth,
            1.0,
            faces,
        );
        step(device, &mut times.light_map, encoder)?;

        // 5. The separable Gaussian.
        let mut encoder = new_encoder("translucency blur");
        {
            let size = self.params.light_map_size;
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("translucency blur"),
                timestamp_writes: None,
            });
            for (pipe, group) in [
                (&self.blur_h, &self.targets.blur_h_group),
                (&self.blur_v, &self.targets.blur_v_group),
            ] {
                pass.set_pipeline(pipe);
                pass.set_bind_group(0, group, &[]);
                // Only the faces in use (one for a directional light).
                pass.dispatch_workgroups(size.div_ceil(8), size.div_ceil(8), faces);
            }
        }
        step(device, &mut times.blur, encoder)?;
        if timed {
            wait(device)?;
        }
        times.total = (Instant::now() - start).as_secs_f64() * 1e3;
        Ok(times)
    }

    /// One offscreen render pass over every face slot (instances = faces): colour cleared to
    /// 1e30 ("nothing") for distance maps or 0 for the cube map, depth to `clear_depth`.
    #[allow(clippy::too_many_arguments)]
    fn draw_offscreen(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        m: &MeshBuffers,
        pipeline: &wgpu::RenderPipeline,
        extra: Option<&wgpu::BindGroup>,
        color: &wgpu::Texture,
        depth: &wgpu::Texture,
        clear_depth: f32,
        faces: u32,
    ) {
        let clear = if clear_depth > 0.5 { 1e30 } else { 0.0 };
        let (cv, dv) = (view(color), view(depth));
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("translucency offscreen"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &cv,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color {
                        r: clear,
                        g: 0.0,
                        b: 0.0,
                        a: 0.0,
                    }),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &dv,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(clear_depth),
                    store: wgpu::StoreOp::Discard,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &self.params_group, &[]);
        if let Some(g) = extra {
            pass.set_bind_group(1, g, &[]);
        }
        pass.set_vertex_buffer(0, m.vertices.slice(..));
        pass.set_index_buffer(m.indices.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..m.index_count, 0, 0..faces);
    }
}
