//! The GPU builder: hemicube and single-plane maps of many vertices rasterised into one atlas
//! per pass with wgpu (the §4.3.4 OpenGL projection, the future work §4.3.8 names).
//!
//! A vertex's map is one *tile* of the atlas: its faces stacked top to bottom (HC: the n × n top
//! then four n × n/2 sides, a tile of n × 3n; SP: n × n), so a tile read row by row is the map in
//! [`PixelLayout`] pixel order. One instanced draw renders every triangle once per (vertex, face)
//! instance: the vertex shader projects through the face's pinhole camera at the vertex's eye
//! (pushed off the surface along the normal, as `glPolygonOffset` does in §4.4), places the
//! result in the instance's tile, and four clip distances (wgpu's `CLIP_DISTANCES`) cut it to
//! the face's rectangle. There is no depth buffer and no culling: the map is binary, so any
//! triangle covering a pixel centre — front or back face — occludes it, and a pixel is sampled
//! exactly where the ray builder casts its ray. The atlas (R8) is read back once per pass and
//! packed into bits on the CPU.
//!
//! HS maps cannot be projected by a pinhole camera (§4.3.4); the builder refuses them.

use std::sync::Arc;

use bytemuck::{Pod, Zeroable};
use glam::{Mat3, Vec3};
use gpu_context::GpuContext;
use occlusion_gpu::{RayCaster, Scene};
use rayon::prelude::*;
use wgpu::util::DeviceExt;

use crate::HemicubeError;
use crate::layout::PixelLayout;
use crate::maps::VisibilityMaps;
use crate::rays::{BuildParams, BuildStats, frames_of};

/// Largest atlas side used (a real GPU allows more; 4096² R8 is 16 MiB per pass).
pub const MAX_ATLAS_SIDE: u32 = 4096;

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct GpuFace {
    forward: [f32; 4],
    right: [f32; 4],
    up: [f32; 4],
    window: [f32; 4],
    rect: [f32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct GpuParams {
    faces: [GpuFace; 5],
    atlas: [f32; 4],
    grid: [u32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct GpuEye {
    eye: [f32; 4],
    t: [f32; 4],
    b: [f32; 4],
    n: [f32; 4],
}

/// The atlas geometry of one layout.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct AtlasShape {
    tile_w: u32,
    tile_h: u32,
    tiles_x: u32,
    tiles_y: u32,
}

impl AtlasShape {
    fn new(layout: &PixelLayout, max_side: u32) -> Result<Self, HemicubeError> {
        let faces = layout.faces();
        let tile_w = faces[0].width;
        let tile_h: u32 = faces.iter().map(|f| f.height).sum();
        if tile_w > max_side || tile_h > max_side {
            return Err(HemicubeError::Params(format!(
                "{} needs a {tile_w}x{tile_h} tile, larger than the {max_side}-texel atlas",
                layout.model().label()
            )));
        }
        // Rows of 256-byte multiples read back without padding.
        let tiles_x = max_side / tile_w;
        let tiles_y = max_side / tile_h;
        Ok(Self {
            tile_w,
            tile_h,
            tiles_x,
            tiles_y,
        })
    }

    fn slots(&self) -> usize {
        (self.tiles_x * self.tiles_y) as usize
    }

    fn size(&self) -> (u32, u32) {
        (self.tiles_x * self.tile_w, self.tiles_y * self.tile_h)
    }
}

/// A GPU builder for one layout: pipeline and atlas made once, reused for every scene.
pub struct GpuBuilder {
    layout: Arc<PixelLayout>,
    shape: AtlasShape,
    pipeline: wgpu::RenderPipeline,
    group_layout: wgpu::BindGroupLayout,
    params: wgpu::Buffer,
    atlas: wgpu::Texture,
}

impl GpuBuilder {
    /// Whether the adapter can run the atlas (it needs clip distances).
    pub fn is_supported(gpu: &GpuContext) -> bool {
        gpu.device
            .features()
            .contains(wgpu::Features::CLIP_DISTANCES)
    }

    /// Pipeline and atlas for `layout`.
    ///
    /// # Errors
    /// [`HemicubeError::Params`] for HS (rays only) or a tile larger than the atlas;
    /// [`HemicubeError::NoClipDistances`] when the adapter lacks clip distances.
    pub fn new(gpu: &GpuContext, layout: Arc<PixelLayout>) -> Result<Self, HemicubeError> {
        if !layout.model().is_planar() {
            return Err(HemicubeError::Params(format!(
                "{} cannot be rasterised by a pinhole camera (§4.3.4): use the ray builder",
                layout.model().label()
            )));
        }
        if !gpu
            .device
            .features()
            .contains(wgpu::Features::CLIP_DISTANCES)
        {
            return Err(HemicubeError::NoClipDistances {
                adapter: gpu.summary().name.clone(),
            });
        }
        let device = &gpu.device;
        let max_side = device.limits().max_texture_dimension_2d.min(MAX_ATLAS_SIDE);
        let shape = AtlasShape::new(&layout, max_side)?;
        let module = gpu_context::pipeline::shader_module(
            device,
            "hemicube atlas",
            include_str!("atlas.wgsl"),
        );
        let group_layout = gpu_context::layout::bind_group_layout(
            device,
            "hemicube atlas",
            wgpu::ShaderStages::VERTEX,
            &[
                gpu_context::layout::binding::uniform(),
                gpu_context::layout::binding::storage_read(),
            ],
        );
        let pipeline_layout =
            gpu_context::pipeline::pipeline_layout(device, "hemicube atlas", &[&group_layout]);
        let buffers = [wgpu::VertexBufferLayout {
            array_stride: 12,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &wgpu::vertex_attr_array![0 => Float32x3],
        }];
        let pipeline = gpu_context::RenderPipelineDesc {
            label: "hemicube atlas",
            layout: &pipeline_layout,
            module: &module,
            vertex: "vs",
            fragment: Some("fs"),
            buffers: &buffers,
            color: Some(wgpu::ColorTargetState {
                format: wgpu::TextureFormat::R8Unorm,
                blend: None,
                write_mask: wgpu::ColorWrites::RED,
            }),
            depth_stencil: None,
            samples: 1,
            cull_mode: None,
        }
        .build(device);
        let (width, height) = shape.size();
        let atlas = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("hemicube atlas"),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::R8Unorm,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("hemicube params"),
            size: std::mem::size_of::<GpuParams>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Ok(Self {
            layout,
            shape,
            pipeline,
            group_layout,
            params,
            atlas,
        })
    }

    /// Vertices per pass (tiles in the atlas).
    pub fn vertices_per_pass(&self) -> usize {
        self.shape.slots()
    }

    /// Builds the maps of every receiver vertex of `scene`.
    ///
    /// # Errors
    /// Scene errors, parameter errors ([`BuildParams::max_distance`] is rays only), GPU errors
    /// (read-back, device loss).
    pub fn build(
        &self,
        gpu: &GpuContext,
        scene: &Scene,
        params: &BuildParams,
    ) -> Result<(VisibilityMaps, BuildStats), HemicubeError> {
        params.validate()?;
        if params.max_distance.is_some() {
            return Err(HemicubeError::Params(
                "triangle preselection by distance is a ray-builder option".to_owned(),
            ));
        }
        let caster = RayCaster::new(scene)?;
        self.build_with_caster(gpu, &caster, params)
    }

    /// [`GpuBuilder::build`] on a scene already prepared (its BVH is not used, only its centred
    /// geometry and frames).
    ///
    /// # Errors
    /// As [`GpuBuilder::build`].
    pub fn build_with_caster(
        &self,
        gpu: &GpuContext,
        caster: &RayCaster,
        params: &BuildParams,
    ) -> Result<(VisibilityMaps, BuildStats), HemicubeError> {
        self.build_with_progress(gpu, caster, params, &|_| {})
    }

    /// [`GpuBuilder::build_with_caster`] calling `progress(n)` after every atlas pass with the
    /// n vertices it built.
    ///
    /// # Errors
    /// As [`GpuBuilder::build`].
    pub fn build_with_progress(
        &self,
        gpu: &GpuContext,
        caster: &RayCaster,
        params: &BuildParams,
        progress: &(dyn Fn(u64) + Sync),
    ) -> Result<(VisibilityMaps, BuildStats), HemicubeError> {
        let (device, queue) = (&gpu.device, &gpu.queue);
        let frames = frames_of(caster);
        let offset = params.offset_relative * caster.diagonal();
        let receivers: Vec<(Vec3, Vec3)> = caster.receivers().collect();
        let mut maps = VisibilityMaps::new(self.layout.clone(), frames.clone());
        let triangles: Vec<[f32; 3]> = caster
            .triangles()
            .flat_map(|t| t.map(|p| p.to_array()))
            .collect();
        let used: Vec<usize> = (0..frames.len()).filter(|&i| frames[i].is_some()).collect();
        if triangles.is_empty() || used.is_empty() {
            // Nothing occludes: every pixel of every used vertex is open.
            let (bits, words) = maps.words_mut();
            let n = self.layout.len();
            for &i in &used {
                for p in 0..n {
                    bits[i * words + p / 64] |= 1 << (p % 64);
                }
            }
            return Ok((maps, BuildStats::default()));
        }
        let vertex_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("hemicube triangles"),
            contents: bytemuck::cast_slice(&triangles),
            usage: wgpu::BufferUsages::VERTEX,
        });
        let slots = self.shape.slots();
        let eyes_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("hemicube eyes"),
            size: (slots * std::mem::size_of::<GpuEye>()) as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let near = (1e-6 * caster.diagonal()).max(f32::MIN_POSITIVE);
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&self.gpu_params(near)));
        let group = gpu_context::layout::bind_group(
            device,
            "hemicube atlas",
            &self.group_layout,
            &[
                self.params.as_entire_binding(),
                eyes_buffer.as_entire_binding(),
            ],
        );
        let view = self.atlas.create_view(&Default::default());
        let faces = self.layout.faces().len() as u32;
        let vertex_count = triangles.len() as u32;
        let mut stats = BuildStats::default();
        let (atlas_w, _) = self.shape.size();
        for batch in used.chunks(slots) {
            let eyes: Vec<GpuEye> = batch
                .iter()
                .map(|&i| {
                    let frame = frames[i].expect("used vertices have frames");
                    let (p, n) = receivers[i];
                    let m = Mat3::from_quat(frame.rotation);
                    let eye = p + n * offset;
                    GpuEye {
                        eye: eye.extend(1.0).to_array(),
                        t: m.x_axis.extend(0.0).to_array(),
                        b: m.y_axis.extend(0.0).to_array(),
                        n: m.z_axis.extend(0.0).to_array(),
                    }
                })
                .collect();
            queue.write_buffer(&eyes_buffer, 0, bytemuck::cast_slice(&eyes));
            let mut encoder = device.create_command_encoder(&Default::default());
            {
                let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("hemicube atlas"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: &view,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                            store: wgpu::StoreOp::Store,
                        },
                    })],
                    depth_stencil_attachment: None,
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                pass.set_pipeline(&self.pipeline);
                pass.set_bind_group(0, &group, &[]);
                pass.set_vertex_buffer(0, vertex_buffer.slice(..));
                pass.draw(0..vertex_count, 0..batch.len() as u32 * faces);
            }
            queue.submit([encoder.finish()]);
            let atlas =
                gpu_context::read_texture(device, queue, &self.atlas, 1, wgpu::TextureAspect::All)?;
            if let Some(message) = gpu_context::take_device_error() {
                return Err(HemicubeError::Gpu(gpu_context::GpuError::Validation(
                    message,
                )));
            }
            stats.passes += 1;
            stats.samples += (batch.len() * self.layout.len()) as u64;
            self.unpack(&atlas, atlas_w as usize, batch, &mut maps);
            progress(batch.len() as u64);
        }
        Ok((maps, stats))
    }

    /// Copies the tiles of one pass into the maps' bits (0 in the atlas = open).
    fn unpack(&self, atlas: &[u8], atlas_w: usize, batch: &[usize], maps: &mut VisibilityMaps) {
        let (tw, th, tiles_x) = (
            self.shape.tile_w as usize,
            self.shape.tile_h as usize,
            self.shape.tiles_x as usize,
        );
        let (bits, words) = maps.words_mut();
        let tiles: Vec<(usize, Vec<u64>)> = batch
            .par_iter()
            .enumerate()
            .map(|(slot, &vertex)| {
                let (x0, y0) = ((slot % tiles_x) * tw, (slot / tiles_x) * th);
                let mut out = vec![0u64; words];
                for row in 0..th {
                    let line = &atlas[(y0 + row) * atlas_w + x0..][..tw];
                    for (col, &v) in line.iter().enumerate() {
                        if v == 0 {
                            let p = row * tw + col;
                            out[p / 64] |= 1 << (p % 64);
                        }
                    }
                }
                (vertex, out)
            })
            .collect();
        for (vertex, out) in tiles {
            bits[vertex * words..][..words].copy_from_slice(&out);
        }
    }

    fn gpu_params(&self, near: f32) -> GpuParams {
        let mut faces = [GpuFace::zeroed(); 5];
        let mut y = 0.0f32;
        for (out, face) in faces.iter_mut().zip(self.layout.faces()) {
            let v4 = |v: glam::DVec3| v.as_vec3().extend(0.0).to_array();
            *out = GpuFace {
                forward: v4(face.forward),
                right: v4(face.right),
                up: v4(face.up),
                window: face.window.map(|w| w as f32),
                rect: [0.0, y, face.width as f32, face.height as f32],
            };
            y += face.height as f32;
        }
        let (w, h) = self.shape.size();
        GpuParams {
            faces,
            atlas: [w as f32, h as f32, near, self.shape.tile_w as f32],
            grid: [
                self.layout.faces().len() as u32,
                self.shape.tiles_x,
                self.shape.tile_h,
                0,
            ],
        }
    }
}
