//! The wgpu renderer (`btf_render.wgsl`): the same image as [`render_cpu`](super::render_cpu),
//! with the texel sums and the barycentric blend in a fragment shader.
//!
//! Uploaded once ([`GpuBtfRenderer::new`]): every texture B_kj of every slot as one layer of a
//! 3-D unsigned-integer texture holding the stored codes, with the per-layer (lo, step) and
//! the per-slot (first layer, c_j + 1) in storage buffers. Per frame
//! ([`GpuBtfRenderer::render`]): positions and UVs, triangles and the per-vertex records
//! (4 slots, 4 ω, 4 · (c + 1) γ) computed on the CPU by the code [`render_cpu`] uses. The
//! draw is non-indexed (3 vertices per triangle); each corner carries the triangle's vertex
//! ids flat and a barycentric coordinate, since WGSL has no primitive index in core.
//!
//! [`render_cpu`]: super::render_cpu

use std::sync::Mutex;

use ::render::{Background, FrameFormat, FramePass, PassContext, Phase, Renderer};
use bytemuck::{Pod, Zeroable};
use gpu_context::layout::{bind_group_layout, binding};
use gpu_context::{RenderPipelineDesc, pipeline};
use wgpu::util::DeviceExt;

use super::image::RenderedImage;
use super::mesh::{BtfMesh, Camera, Light, RenderParams};
use super::shade::VertexShading;
use crate::error::{BtfError, Result};
use crate::model::{BtfPca, Codes, SlotPca, Storage, Texture};
use crate::sampling::DIRECTIONS;

const SHADER: &str = include_str!("btf_render.wgsl");

/// u32 words of a vertex record before its γ values: 4 slots and 4 ω.
const RECORD_HEADER: usize = 8;

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct FrameUniform {
    radiance: [f32; 4],
    uv_scale: [f32; 4],
    tex: [u32; 4],
    strides: [u32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct GeomVertex {
    position: [f32; 3],
    uv: [f32; 2],
    _pad: [f32; 3],
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct LayerInfo {
    lo: f32,
    step: f32,
    raw: u32,
    _pad: u32,
}

/// Where the layers lie in the 3-D texture.
#[derive(Clone, Copy, Debug)]
struct Tiling {
    tiles_x: u32,
    tiles_per_slice: u32,
    depth: u32,
}

/// A compressed BTF resident on the GPU, rendering meshes with it.
///
/// ```no_run
/// # fn demo(device: &wgpu::Device, queue: &wgpu::Queue, pca: &btf::BtfPca,
/// #     mesh: &btf::render::BtfMesh, light: &btf::render::Light, camera: &btf::render::Camera)
/// #     -> btf::Result<()> {
/// use btf::render::{GpuBtfRenderer, RenderParams};
/// let renderer = GpuBtfRenderer::new(device, queue, pca)?;
/// let image = renderer.render(mesh, light, camera, &RenderParams::default())?;
/// image.write_png(std::path::Path::new("cloth.png"))?;
/// # Ok(()) }
/// ```
#[derive(Debug)]
pub struct GpuBtfRenderer {
    device: wgpu::Device,
    queue: wgpu::Queue,
    /// The BTF without its texels: sampling, component counts and weights p_ikj, for γ.
    weights_only: BtfPca,
    width: u32,
    height: u32,
    tiling: Tiling,
    layers: wgpu::Buffer,
    slots: wgpu::Buffer,
    texture_view: wgpu::TextureView,
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::RenderPipeline,
    /// The single-sample frame of [`GpuBtfRenderer::render`]; `None` when built for a shared
    /// frame ([`GpuBtfRenderer::for_frame`]).
    standalone: Option<Mutex<Renderer>>,
}

/// One mesh prepared for a frame: the per-vertex records uploaded, ready to record into the
/// shared frame ([`FramePass`], [`Phase::Opaque`]: it tests and writes depth like any opaque
/// object, so BTF objects and Gouraud objects occlude each other).
#[derive(Debug)]
pub struct BtfDraw {
    pipeline: wgpu::RenderPipeline,
    bind_group: wgpu::BindGroup,
    vertices: u32,
}

impl FramePass for BtfDraw {
    fn phase(&self) -> Phase {
        Phase::Opaque
    }

    fn record(&self, pass: &mut wgpu::RenderPass<'_>) {
        if self.vertices > 0 {
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(1, &self.bind_group, &[]);
            pass.draw(0..self.vertices, 0..1);
        }
    }
}

/// The smallest storage holding every texture's codes, and its texture format.
fn texture_format(pca: &BtfPca) -> (Storage, wgpu::TextureFormat, u32) {
    let widest = pca
        .slots
        .iter()
        .flat_map(|s| &s.textures)
        .map(Texture::storage)
        .max_by_key(|s| s.bytes())
        .unwrap_or(Storage::U8);
    match widest {
        Storage::U8 => (widest, wgpu::TextureFormat::Rgba8Uint, 4),
        Storage::U16 => (widest, wgpu::TextureFormat::Rgba16Uint, 8),
        Storage::F32 => (widest, wgpu::TextureFormat::Rgba32Uint, 16),
    }
}

/// Lays `layers` textures of w × h into a 3-D texture within `max_3d` per side.
fn tiling(layers: usize, width: usize, height: usize, max_3d: u32) -> Result<Tiling> {
    let max = max_3d as usize;
    for (value, what) in [(width, "BTF texture width"), (height, "BTF texture height")] {
        if value > max {
            return Err(BtfError::GpuLimit {
                what,
                limit: "max_texture_dimension_3d",
                value: value as u64,
                maximum: u64::from(max_3d),
                hint: "downsample the BTF or request a device with larger limits",
            });
        }
    }
    let needed = layers.div_ceil(max).max(1);
    let tiles_x = needed.min(max / width);
    let tiles_y = needed.div_ceil(tiles_x);
    if tiles_y > max / height {
        return Err(BtfError::GpuLimit {
            what: "eigen-normtexture layers Σ_j (c_j + 1), tiled",
            limit: "max_texture_dimension_3d",
            value: layers as u64,
            maximum: ((max / width) * (max / height) * max) as u64,
            hint: "compress with fewer components, downsample the BTF, or request a device \
                   with larger limits",
        });
    }
    let per_slice = tiles_x * tiles_y;
    // All ≤ max_3d ≤ u32::MAX.
    Ok(Tiling {
        tiles_x: tiles_x as u32,
        tiles_per_slice: per_slice as u32,
        depth: layers.div_ceil(per_slice) as u32,
    })
}

/// The codes of one texture as `channels` texels of 4 components in `storage`'s byte width.
fn texel_bytes(texture: &Texture, storage: Storage, out: &mut Vec<u8>) {
    out.clear();
    let push = |out: &mut Vec<u8>, q: u32| match storage {
        Storage::U8 => out.push(q as u8),
        Storage::U16 => out.extend_from_slice(&(q as u16).to_le_bytes()),
        Storage::F32 => out.extend_from_slice(&q.to_le_bytes()),
    };
    let code = |i: usize| -> u32 {
        match &texture.codes {
            Codes::U8(c) => u32::from(c[i]),
            Codes::U16(c) => u32::from(c[i]),
            Codes::F32(c) => c[i].to_bits(),
        }
    };
    for t in 0..texture.len() / 3 {
        for a in 0..3 {
            push(out, code(3 * t + a));
        }
        push(out, 0);
    }
}

/// Fails with [`BtfError::GpuLimit`] when a storage buffer of `bytes` exceeds the device.
pub(super) fn check_buffer(device: &wgpu::Device, what: &'static str, bytes: u64) -> Result<()> {
    let limits = device.limits();
    let (limit, maximum) = if limits.max_storage_buffer_binding_size <= limits.max_buffer_size {
        (
            "max_storage_buffer_binding_size",
            limits.max_storage_buffer_binding_size,
        )
    } else {
        ("max_buffer_size", limits.max_buffer_size)
    };
    // The shader indexes with u32.
    let maximum = maximum.min(4 * u64::from(u32::MAX));
    if bytes > maximum {
        return Err(BtfError::GpuLimit {
            what,
            limit,
            value: bytes,
            maximum,
            hint: "render fewer vertices per call, compress with fewer components, or request \
                   a device with larger limits",
        });
    }
    Ok(())
}

pub(super) fn storage_init(device: &wgpu::Device, label: &str, bytes: &[u8]) -> wgpu::Buffer {
    // A binding may not be empty; 16 zero bytes keep an empty mesh valid.
    let contents: &[u8] = if bytes.is_empty() { &[0; 16] } else { bytes };
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents,
        usage: wgpu::BufferUsages::STORAGE,
    })
}

pub(super) fn buffer(binding: u32, b: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry {
        binding,
        resource: b.as_entire_binding(),
    }
}

impl GpuBtfRenderer {
    /// Uploads every texture of `pca` (means and eigen-normtextures of all 81 slots) and
    /// builds the pipeline for a single-sample frame of its own, for [`Self::render`] (what
    /// the CPU reference is compared with, pixel for pixel).
    ///
    /// # Errors
    /// [`BtfError::GpuLimit`] naming the limit when the normtextures are wider or taller than
    /// `max_texture_dimension_3d`, or their Σ_j (c_j + 1) layers do not fit one 3-D texture
    /// even tiled.
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue, pca: &BtfPca) -> Result<Self> {
        let renderer = Renderer::new(device, FrameFormat::single_sample(device));
        let mut this = Self::for_frame(device, queue, pca, &renderer.pass_context())?;
        this.standalone = Some(Mutex::new(renderer));
        Ok(this)
    }

    /// Uploads `pca` as [`Self::new`] does, with the pipeline built for a shared frame
    /// (`ctx` from [`Renderer::pass_context`]); draw with [`Self::prepare`] and hand the
    /// [`BtfDraw`] to [`Renderer::render`].
    ///
    /// # Errors
    /// As [`Self::new`].
    pub fn for_frame(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        pca: &BtfPca,
        ctx: &PassContext<'_>,
    ) -> Result<Self> {
        let (w, h) = (pca.width, pca.height);
        let max_3d = device.limits().max_texture_dimension_3d;
        let layer_count: usize = pca.slots.iter().map(|s| s.textures.len()).sum();
        let tiling = tiling(layer_count, w, h, max_3d)?;
        let (storage, format, bytes_per_texel) = texture_format(pca);
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("btf eigen-normtextures"),
            size: wgpu::Extent3d {
                // ≤ max_3d: checked by `tiling`.
                width: (w as u32) * tiling.tiles_x,
                height: (h as u32) * tiling.tiles_per_slice.div_ceil(tiling.tiles_x),
                depth_or_array_layers: tiling.depth,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D3,
            format,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let mut infos = Vec::with_capacity(layer_count);
        let mut slot_table = Vec::with_capacity(DIRECTIONS);
        let mut bytes = Vec::new();
        for slot in &pca.slots {
            slot_table.push([infos.len() as u32, slot.textures.len() as u32]);
            for tex in &slot.textures {
                let layer = infos.len() as u32;
                let (z, r) = (
                    layer / tiling.tiles_per_slice,
                    layer % tiling.tiles_per_slice,
                );
                texel_bytes(tex, storage, &mut bytes);
                queue.write_texture(
                    wgpu::TexelCopyTextureInfo {
                        texture: &texture,
                        mip_level: 0,
                        origin: wgpu::Origin3d {
                            x: (r % tiling.tiles_x) * w as u32,
                            y: (r / tiling.tiles_x) * h as u32,
                            z,
                        },
                        aspect: wgpu::TextureAspect::All,
                    },
                    &bytes,
                    wgpu::TexelCopyBufferLayout {
                        offset: 0,
                        bytes_per_row: Some(w as u32 * bytes_per_texel),
                        rows_per_image: Some(h as u32),
                    },
                    wgpu::Extent3d {
                        width: w as u32,
                        height: h as u32,
                        depth_or_array_layers: 1,
                    },
                );
                infos.push(LayerInfo {
                    lo: tex.lo,
                    step: tex.step(),
                    raw: u32::from(tex.storage() == Storage::F32),
                    _pad: 0,
                });
            }
        }
        let layers = storage_init(device, "btf layers", bytemuck::cast_slice(&infos));
        let slots = storage_init(device, "btf slots", bytemuck::cast_slice(&slot_table));
        let texture_view = texture.create_view(&wgpu::TextureViewDescriptor::default());
        let (layout, pipeline) = make_pipeline(device, ctx);
        Ok(Self {
            device: device.clone(),
            queue: queue.clone(),
            weights_only: weights_only(pca),
            width: w as u32,
            height: h as u32,
            tiling,
            layers,
            slots,
            texture_view,
            layout,
            pipeline,
            standalone: None,
        })
    }

    /// Renders `mesh` under `light` seen by `camera` in a single-sample frame of its own
    /// (blocking until the image is read back). Same inputs, conventions and result as
    /// [`render_cpu`](super::render_cpu), to float rounding and the GPU's rasterisation
    /// rules at triangle edges.
    ///
    /// # Errors
    /// As [`render_cpu`](super::render_cpu) for invalid inputs; [`BtfError::GpuLimit`] when
    /// the image exceeds `max_texture_dimension_2d` or a per-frame buffer exceeds
    /// `max_storage_buffer_binding_size`; [`BtfError::GpuReadback`] when reading the image
    /// back fails or the renderer was built with [`Self::for_frame`].
    pub fn render(
        &self,
        mesh: &BtfMesh<'_>,
        light: &Light,
        camera: &Camera,
        params: &RenderParams,
    ) -> Result<RenderedImage> {
        let readback = |e: &dyn std::fmt::Display| BtfError::GpuReadback {
            what: "GpuBtfRenderer::render",
            reason: e.to_string(),
        };
        let standalone = self.standalone.as_ref().ok_or_else(|| {
            readback(&"built for a shared frame: record its BtfDraw with render::Renderer")
        })?;
        let draw = self.prepare(mesh, light, camera, params)?;
        let mut renderer = standalone.lock().map_err(|e| readback(&e))?;
        let background = Background::Color(params.background.to_array());
        let hdr = renderer
            .render(&self.device, &self.queue, camera, background, &[&draw])
            .map_err(|e| readback(&e))?;
        let pixels = hdr.pixels().iter().map(|p| [p[0], p[1], p[2]]).collect();
        let coverage = hdr.pixels().iter().map(|p| p[3] > 0.5).collect();
        Ok(RenderedImage::new(
            camera.width,
            camera.height,
            pixels,
            coverage,
        ))
    }

    /// Computes the per-vertex slots, ω and γ of `mesh` for `camera`'s eye and `light`, and
    /// uploads them: a [`BtfDraw`] to record into a frame built with the same format.
    ///
    /// # Errors
    /// As [`Self::render`], without the read-back.
    pub fn prepare(
        &self,
        mesh: &BtfMesh<'_>,
        light: &Light,
        camera: &Camera,
        params: &RenderParams,
    ) -> Result<BtfDraw> {
        light.validate()?;
        let frames = mesh.frames()?;
        let shading = VertexShading::compute(&self.weights_only, mesh, &frames, light, camera.eye);
        self.upload(mesh, &shading, light.radiance(), camera, params)
    }

    /// As [`Self::prepare`] under an environment (thesis §5.5.2): `w[v]` is the environment
    /// binned for vertex v ([`crate::env`]: its radiance, solid angles and visibility), and
    /// each vertex carries RGB γ* per view slot (eq. 5.11).
    ///
    /// # Errors
    /// As [`Self::prepare`]; [`BtfError::LengthMismatch`] unless `w` has one entry per vertex.
    pub fn prepare_env(
        &self,
        mesh: &BtfMesh<'_>,
        w: &[crate::env::EnvLightWeights],
        camera: &Camera,
        params: &RenderParams,
    ) -> Result<BtfDraw> {
        super::cpu::check_env_len(mesh, w)?;
        let frames = mesh.frames()?;
        let shading = VertexShading::compute_env(&self.weights_only, mesh, &frames, w, camera.eye);
        self.upload(mesh, &shading, glam::Vec3::ONE, camera, params)
    }

    fn upload(
        &self,
        mesh: &BtfMesh<'_>,
        shading: &VertexShading,
        radiance: glam::Vec3,
        camera: &Camera,
        params: &RenderParams,
    ) -> Result<BtfDraw> {
        camera.validate()?;
        params.validate()?;
        let device = &self.device;
        let max_2d = device.limits().max_texture_dimension_2d;
        for (what, value) in [
            ("image width", camera.width),
            ("image height", camera.height),
        ] {
            if value > max_2d {
                return Err(BtfError::GpuLimit {
                    what,
                    limit: "max_texture_dimension_2d",
                    value: u64::from(value),
                    maximum: u64::from(max_2d),
                    hint: "render a smaller image",
                });
            }
        }
        let stride = shading.gamma_stride;
        let record_words = RECORD_HEADER + 4 * stride;
        let n = mesh.positions.len();
        check_buffer(
            device,
            "vertex records bytes",
            (n * record_words * 4) as u64,
        )?;
        check_buffer(device, "vertex geometry bytes", (n * 32) as u64)?;
        check_buffer(device, "triangle bytes", (mesh.triangles.len() * 12) as u64)?;

        let mut records = Vec::with_capacity(n * record_words);
        for v in 0..n {
            records.extend_from_slice(&shading.slots[v]);
            records.extend(shading.omega[v].map(f32::to_bits));
            let gammas = &shading.gammas[v * 4 * stride..(v + 1) * 4 * stride];
            records.extend(gammas.iter().map(|g| g.to_bits()));
        }
        let geometry: Vec<GeomVertex> = mesh
            .positions
            .iter()
            .zip(mesh.uvs)
            .map(|(p, uv)| GeomVertex {
                position: p.to_array(),
                uv: uv.to_array(),
                _pad: [0.0; 3],
            })
            .collect();
        let uniform = FrameUniform {
            radiance: radiance.extend(0.0).to_array(),
            uv_scale: [params.uv_scale.x, params.uv_scale.y, 0.0, 0.0],
            tex: [
                self.width,
                self.height,
                self.tiling.tiles_x,
                self.tiling.tiles_per_slice,
            ],
            // Fits u32: the records buffer was checked above.
            strides: [
                stride as u32,
                record_words as u32,
                u32::from(shading.rgb),
                0,
            ],
        };
        let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("btf frame"),
            contents: bytemuck::bytes_of(&uniform),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let geometry = storage_init(device, "btf geometry", bytemuck::cast_slice(&geometry));
        let triangles = storage_init(
            device,
            "btf triangles",
            bytemuck::cast_slice(mesh.triangles),
        );
        let records = storage_init(device, "btf vertex records", bytemuck::cast_slice(&records));
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("btf render"),
            layout: &self.layout,
            entries: &[
                buffer(0, &uniform),
                buffer(1, &geometry),
                buffer(2, &triangles),
                buffer(3, &records),
                buffer(4, &self.layers),
                buffer(5, &self.slots),
                wgpu::BindGroupEntry {
                    binding: 6,
                    resource: wgpu::BindingResource::TextureView(&self.texture_view),
                },
            ],
        });

        Ok(BtfDraw {
            pipeline: self.pipeline.clone(),
            bind_group,
            // ≤ u32::MAX: the triangle buffer was checked above.
            vertices: 3 * mesh.triangles.len() as u32,
        })
    }
}

/// A copy of `pca` whose textures keep their count and range but no texels: what γ needs
/// (sampling, c_j and the weights p_ikj), without a second copy of the texture data.
fn weights_only(pca: &BtfPca) -> BtfPca {
    let slots = pca
        .slots
        .iter()
        .map(|s| SlotPca {
            textures: s
                .textures
                .iter()
                .map(|t| Texture {
                    lo: t.lo,
                    hi: t.hi,
                    codes: Codes::F32(Vec::new()),
                })
                .collect(),
            weights: s.weights.clone(),
            eigenvalues: Vec::new(),
        })
        .collect();
    BtfPca {
        sampling: pca.sampling,
        width: pca.width,
        height: pca.height,
        requested_components: pca.requested_components,
        storage: pca.storage,
        mean_storage: pca.mean_storage,
        slots,
    }
}

fn make_pipeline(
    device: &wgpu::Device,
    ctx: &PassContext<'_>,
) -> (wgpu::BindGroupLayout, wgpu::RenderPipeline) {
    let source = format!("{}\n{}", ::render::VIEW_SHADER, SHADER);
    let module = pipeline::shader_module(device, "btf_render.wgsl", &source);
    let layout = bind_group_layout(
        device,
        "btf render",
        wgpu::ShaderStages::VERTEX_FRAGMENT,
        &[
            binding::uniform(),
            binding::storage_read(),
            binding::storage_read(),
            binding::storage_read(),
            binding::storage_read(),
            binding::storage_read(),
            binding::texture(
                wgpu::TextureSampleType::Uint,
                wgpu::TextureViewDimension::D3,
            ),
        ],
    );
    let pipeline_layout =
        pipeline::pipeline_layout(device, "btf render", &[ctx.view_layout, &layout]);
    let pipeline = RenderPipelineDesc {
        label: "btf render",
        layout: &pipeline_layout,
        module: &module,
        vertex: "vs_main",
        fragment: Some("fs_main"),
        buffers: &[],
        color: Some(ctx.format.color_target()),
        depth_stencil: Some(ctx.format.opaque_depth()),
        samples: ctx.format.samples,
        cull_mode: None,
    }
    .build(device);
    (layout, pipeline)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layers_tile_only_when_they_exceed_the_3d_limit() {
        // The thesis's c = 16 at 256²: 81 · 17 = 1377 layers, one per z slice.
        let t = tiling(1377, 256, 256, 2048).unwrap();
        assert_eq!((t.tiles_x, t.tiles_per_slice, t.depth), (1, 1, 1377));
        // All 80 components at 16²: 6561 layers, 4 tiles per slice.
        let t = tiling(6561, 16, 16, 2048).unwrap();
        assert_eq!((t.tiles_x, t.tiles_per_slice, t.depth), (4, 4, 1641));
        // 256² with 6561 layers needs 4 tiles of 256 in x: fits (8 per row).
        let t = tiling(6561, 256, 256, 2048).unwrap();
        assert_eq!((t.tiles_x, t.tiles_per_slice), (4, 4));
        for (layers, w) in [(6561, 2048), (10, 4096)] {
            match tiling(layers, w, w, 2048) {
                Err(BtfError::GpuLimit { limit, .. }) => {
                    assert_eq!(limit, "max_texture_dimension_3d")
                }
                other => panic!("{other:?}"),
            }
        }
    }
}
