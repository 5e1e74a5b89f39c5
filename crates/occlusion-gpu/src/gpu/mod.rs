//! The `depth` backend (paper 000 §3.2 with the seed's future work §8.1): per light direction
//! the scene is rendered into an orthographic Depth32Float map (layers of a 2D array, a batch
//! at a time), then a compute pass depth-tests every receiver vertex against the batch with a
//! slope-scaled bias — the compute counterpart of one occlusion query per vertex with
//! `glPolygonOffset(1, 1)` — writing one visibility bit per (i, j) and accumulating a_i in
//! storage buffers. M stays on the GPU; only what is asked for is read back.
//!
//! Deviation from the seed: both faces are rasterised (two-sided cloth occludes from both
//! sides), and the tested point is pushed along its normal by a fraction of a texel
//! (normal-offset shadow mapping) besides the depth bias, which removes most self-shadowing
//! acne at grazing angles.
//!
//! Limit: a depth map cannot separate surfaces closer than the bias (about 1.5 texels of
//! 2R/resolution). On the synthetic cloth draped over itself, 1.6–2.4 % of vertices lie
//! under another layer that close (nearest occluder 1.6e-5 to 1e-3 of the diagonal, measured
//! with an f64 ray cast): the `cpu` backend sees them shadowed (a_i ≈ 0), the depth maps see
//! them open, at every resolution from 256² to 2048² (`cargo xtask repro visibility`). Use
//! the `cpu` backend where cloth lies in contact with itself.
//!
//! Speed on a real GPU (`cargo xtask bench visibility-gpu`, NVIDIA H100, Vulkan): the bunny
//! at k = 1026 takes 415 ms at 1024², of which the calling thread spends 36 ms recording and
//! submitting: the GPU is the limit, at 0.4 ms per depth map (0.14 ms at 256²). Tried: a
//! batch's maps as tiles of one 2D atlas drawn in a single render pass (a viewport and a
//! scissor per direction) instead of one render pass per layer. Same machine, bunny, k = 258,
//! medians of 11: 136.5 ms against 113.6 and 114.3 ms for the layers at 1024² (k = 1026: 493
//! against 415 ms), 32.2 against 34.2 and 36.5 ms at 256²; the host's share fell from 15–19
//! to 12 ms. Slower at the default resolution, and M moved on a few edge cells (1 of the
//! res4 bunny's 116,874 at level 3, 4 of the full bunny's 2.37 M at level 2: window
//! coordinates round differently far from the atlas origin): not kept.

mod light;
mod query;
mod rays;
mod resident;

use glam::Vec3;
use wgpu::util::DeviceExt;

pub(crate) use light::LightBox;
pub(crate) use query::QueryPipelines;
pub(crate) use rays::{RayPipelines, RayTree};
pub use resident::GpuVisibility;

pub(crate) use crate::depth_params::DepthParams;

use crate::matrix::WORD_BITS;
use crate::progress::Ticker;
use crate::scene::Prepared;
use crate::{OcclusionError, VisibilityMatrix};

/// Workgroup size of `occlusion_test.wgsl` (keep in sync with the shader).
const WORKGROUP_SIZE: u32 = 64;
/// Largest workgroup count per dispatch dimension guaranteed by WebGPU.
const MAX_GROUPS_PER_DIMENSION: u32 = 65_535;

/// Workgroups (x, y) of [`WORKGROUP_SIZE`] covering `invocations`, x within WebGPU's
/// per-dimension limit (the shaders rebuild the index as `id.x + id.y · groups.x · 64`).
pub(crate) fn workgroups(invocations: usize) -> (u32, u32) {
    let groups = (invocations as u32).div_ceil(WORKGROUP_SIZE);
    let x = groups.clamp(1, MAX_GROUPS_PER_DIMENSION);
    (x, groups.div_ceil(x).max(1))
}

const DEPTH_SHADER: &str = include_str!("occlusion_depth.wgsl");
const TEST_SHADER: &str = include_str!("occlusion_test.wgsl");

/// `struct Params` of `occlusion_test.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct TestParams {
    vertex_count: u32,
    first_direction: u32,
    layer_count: u32,
    words_per_row: u32,
    resolution: u32,
    texel_world: f32,
    texel_depth: f32,
    bias_constant_texels: f32,
    bias_slope_texels: f32,
    max_slope: f32,
    normal_offset_texels: f32,
    _pad: f32,
}

/// The compiled pipelines of the `depth` backend (build once per device).
pub(crate) struct DepthPipelines {
    depth_pipeline: wgpu::RenderPipeline,
    depth_layout: wgpu::BindGroupLayout,
    test_pipeline: wgpu::ComputePipeline,
    test_layout: wgpu::BindGroupLayout,
}

fn storage_entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
    read_only: bool,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

impl DepthPipelines {
    pub(crate) fn new(device: &wgpu::Device) -> Self {
        let depth_module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("occlusion_depth.wgsl"),
            source: wgpu::ShaderSource::Wgsl(DEPTH_SHADER.into()),
        });
        let test_module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("occlusion_test.wgsl"),
            source: wgpu::ShaderSource::Wgsl(TEST_SHADER.into()),
        });
        let depth_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("occlusion depth"),
            entries: &[storage_entry(0, wgpu::ShaderStages::VERTEX, true)],
        });
        let compute = wgpu::ShaderStages::COMPUTE;
        let test_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("occlusion test"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: compute,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                storage_entry(1, compute, true),
                storage_entry(2, compute, true),
                wgpu::BindGroupLayoutEntry {
                    binding: 3,
                    visibility: compute,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Depth,
                        view_dimension: wgpu::TextureViewDimension::D2Array,
                        multisampled: false,
                    },
                    count: None,
                },
                storage_entry(4, compute, false),
                storage_entry(5, compute, false),
            ],
        });
        let depth_pipeline_layout =
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("occlusion depth"),
                bind_group_layouts: &[Some(&depth_layout)],
                immediate_size: 0,
            });
        let depth_pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("occlusion depth"),
            layout: Some(&depth_pipeline_layout),
            vertex: wgpu::VertexState {
                module: &depth_module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: 12,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &wgpu::vertex_attr_array![0 => Float32x3],
                })],
            },
            primitive: wgpu::PrimitiveState {
                cull_mode: None,
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: wgpu::TextureFormat::Depth32Float,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: wgpu::StencilState::default(),
                bias: wgpu::DepthBiasState::default(),
            }),
            multisample: wgpu::MultisampleState::default(),
            fragment: None,
            multiview_mask: None,
            cache: None,
        });
        let test_pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("occlusion test"),
            bind_group_layouts: &[Some(&test_layout)],
            immediate_size: 0,
        });
        let test_pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("occlusion test"),
            layout: Some(&test_pipeline_layout),
            module: &test_module,
            entry_point: Some("cs_main"),
            compilation_options: Default::default(),
            cache: None,
        });
        Self {
            depth_pipeline,
            depth_layout,
            test_pipeline,
            test_layout,
        }
    }

    /// Computes the columns `first..k` on the GPU; the results stay in the returned buffers.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn run(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        prepared: &Prepared,
        directions: &[Vec3],
        solid_angles: &[f64],
        first: usize,
        params: &DepthParams,
        ticker: &std::sync::Arc<Ticker>,
    ) -> Result<DepthRun, OcclusionError> {
        let limits = device.limits();
        let resolution = check_resolution(device, params.resolution)?;
        let k = directions.len();
        let scene = SceneBuffers::new(device, prepared, directions, solid_angles)?;
        let (rows, words_per_row) = (scene.rows, scene.words_per_row);
        let layer_bytes = u64::from(resolution) * u64::from(resolution) * 4;
        let max_layers = (params.max_array_bytes / layer_bytes)
            .clamp(1, u64::from(limits.max_texture_array_layers)) as usize;
        let light_box = scene.light_box;
        let params_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("occlusion params"),
            size: std::mem::size_of::<TestParams>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let layers = max_layers.min(k - first).max(1);
        let depth_maps = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("occlusion depth maps"),
            size: wgpu::Extent3d {
                width: resolution,
                height: resolution,
                depth_or_array_layers: layers as u32,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Depth32Float,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let layer_views: Vec<wgpu::TextureView> = (0..layers as u32)
            .map(|layer| {
                depth_maps.create_view(&wgpu::TextureViewDescriptor {
                    dimension: Some(wgpu::TextureViewDimension::D2),
                    base_array_layer: layer,
                    array_layer_count: Some(1),
                    ..Default::default()
                })
            })
            .collect();
        let array_view = depth_maps.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let depth_group = self.depth_bind_group(device, &scene);
        let test_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("occlusion test"),
            layout: &self.test_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: params_buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: scene.receiver_buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: scene.light_buffer.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: wgpu::BindingResource::TextureView(&array_view),
                },
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: scene.bits.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 5,
                    resource: scene.ambient.as_entire_binding(),
                },
            ],
        });
        let texel_world = 2.0 * light_box.half_extent / resolution as f32;
        let (groups_x, groups_y) = workgroups(rows);
        let mut first_direction = first;
        while first_direction < k {
            let layer_count = layers.min(k - first_direction);
            let test_params = TestParams {
                vertex_count: rows as u32,
                first_direction: first_direction as u32,
                layer_count: layer_count as u32,
                words_per_row: words_per_row as u32,
                resolution,
                texel_world,
                // The depth range (2R) equals the box width, so one texel is 1/res in depth.
                texel_depth: 1.0 / resolution as f32,
                bias_constant_texels: params.bias_constant_texels,
                bias_slope_texels: params.bias_slope_texels,
                max_slope: params.max_slope,
                normal_offset_texels: params.normal_offset_texels,
                _pad: 0.0,
            };
            queue.write_buffer(&params_buffer, 0, bytemuck::bytes_of(&test_params));
            let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("occlusion batch"),
            });
            for (layer, view) in layer_views.iter().enumerate().take(layer_count) {
                let j = (first_direction + layer) as u32;
                let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("occlusion depth"),
                    color_attachments: &[],
                    depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                        view,
                        depth_ops: Some(wgpu::Operations {
                            load: wgpu::LoadOp::Clear(1.0),
                            store: wgpu::StoreOp::Store,
                        }),
                        stencil_ops: None,
                    }),
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                self.draw_scene(&mut pass, &depth_group, &scene, j);
            }
            {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("occlusion test"),
                    timestamp_writes: None,
                });
                pass.set_pipeline(&self.test_pipeline);
                pass.set_bind_group(0, &test_group, &[]);
                pass.dispatch_workgroups(groups_x, groups_y, 1);
            }
            queue.submit([encoder.finish()]);
            // Counted when the device has finished the batch (fired by this poll or a later
            // one, at the latest the read-back's wait).
            let done = std::sync::Arc::clone(ticker);
            let cells = (rows * layer_count) as u64;
            queue.on_submitted_work_done(move || done.tick(cells));
            // A failed non-blocking poll leaves the callbacks to the read-back's wait.
            let _ = device.poll(wgpu::PollType::Poll);
            first_direction += layer_count;
        }
        Ok(scene.into_run(prepared))
    }

    /// The bind group of the scene pass (the lights, indexed by the draw's instance index).
    pub(crate) fn depth_bind_group(
        &self,
        device: &wgpu::Device,
        scene: &SceneBuffers,
    ) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("occlusion depth"),
            layout: &self.depth_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: scene.light_buffer.as_entire_binding(),
            }],
        })
    }

    /// Records the scene's depth-only draw as seen from direction `j` into `pass` (§3.2, first
    /// pass); `group` comes from [`DepthPipelines::depth_bind_group`].
    pub(crate) fn draw_scene(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        group: &wgpu::BindGroup,
        scene: &SceneBuffers,
        j: u32,
    ) {
        if scene.index_count > 0 {
            pass.set_pipeline(&self.depth_pipeline);
            pass.set_bind_group(0, group, &[]);
            pass.set_vertex_buffer(0, scene.vertex_buffer.slice(..));
            pass.set_index_buffer(scene.index_buffer.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..scene.index_count, 0, j..j + 1);
        }
    }
}

/// Checks a depth-map resolution against the device.
pub(crate) fn check_resolution(
    device: &wgpu::Device,
    resolution: u32,
) -> Result<u32, OcclusionError> {
    let maximum = device.limits().max_texture_dimension_2d;
    if resolution == 0 || resolution > maximum {
        return Err(OcclusionError::GpuLimit {
            what: "depth resolution",
            value: u64::from(resolution),
            maximum: u64::from(maximum),
        });
    }
    Ok(resolution)
}

/// Refuses any of `sizes` (what, bytes) above the device's storage-binding limit, naming the
/// first one that is.
pub(crate) fn check_storage_bindings(
    device: &wgpu::Device,
    sizes: &[(&'static str, u64)],
) -> Result<(), OcclusionError> {
    let maximum = device.limits().max_storage_buffer_binding_size;
    match sizes.iter().find(|(_, value)| *value > maximum) {
        Some(&(what, value)) => Err(OcclusionError::GpuLimit {
            what,
            value,
            maximum,
        }),
        None => Ok(()),
    }
}

/// The GPU buffers the two depth-map backends share for one computation: lights, receivers, the
/// scene's geometry, and the zero-initialised outputs (visibility bits, a_i).
pub(crate) struct SceneBuffers {
    pub light_box: LightBox,
    pub light_buffer: wgpu::Buffer,
    pub receiver_buffer: wgpu::Buffer,
    pub vertex_buffer: wgpu::Buffer,
    pub index_buffer: wgpu::Buffer,
    pub index_count: u32,
    pub bits: wgpu::Buffer,
    pub ambient: wgpu::Buffer,
    pub rows: usize,
    pub words_per_row: usize,
}

impl SceneBuffers {
    /// Uploads the scene and allocates the outputs for `directions.len()` columns.
    ///
    /// The geometry goes up multiplied by [`Prepared::tracer_scale`], the power of two that
    /// brings the diagonal into (8, 16] (as the `cpu` backend's tracers do): the shaders' f32
    /// products then never underflow or overflow, so a scene 10⁻²⁴ or 10¹⁶ across gets the M
    /// of the same scene in metres, bit for bit (a power of two commutes with f32 rounding).
    /// Without it both depth-map backends got a third of the cells of a sphere over a plane
    /// wrong at 2⁻⁸⁰.
    pub(crate) fn new(
        device: &wgpu::Device,
        prepared: &Prepared,
        directions: &[Vec3],
        solid_angles: &[f64],
    ) -> Result<Self, OcclusionError> {
        let scaled = prepared.scaled(prepared.tracer_scale());
        let prepared = &*scaled;
        let k = directions.len();
        let rows = prepared.receivers.len();
        let words_per_row = k.div_ceil(WORD_BITS);
        let bits_bytes = (rows * words_per_row * 4) as u64;
        check_storage_bindings(device, &[("visibility bits buffer bytes", bits_bytes)])?;
        let light_box = LightBox::new(prepared.radius);
        let lights = light_box.lights(directions, solid_angles);
        let receivers: Vec<[f32; 8]> = prepared
            .receivers
            .iter()
            .map(|r| {
                let (p, n) = (r.position, r.normal);
                [p.x, p.y, p.z, 1.0, n.x, n.y, n.z, 0.0]
            })
            .collect();
        let init = |label, contents: &[u8], usage| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage,
            })
        };
        let storage = wgpu::BufferUsages::STORAGE;
        let light_buffer = init("occlusion lights", bytemuck::cast_slice(&lights), storage);
        let receiver_buffer = init(
            "occlusion receivers",
            bytemuck::cast_slice(&receivers),
            storage,
        );
        let positions: &[f32] = bytemuck::cast_slice(&prepared.positions);
        let vertex_buffer = init(
            "occlusion positions",
            bytemuck::cast_slice(positions),
            wgpu::BufferUsages::VERTEX,
        );
        let indices: &[u32] = bytemuck::cast_slice(&prepared.triangles);
        let index_buffer = init(
            "occlusion indices",
            bytemuck::cast_slice(indices),
            wgpu::BufferUsages::INDEX,
        );
        let readable = storage | wgpu::BufferUsages::COPY_SRC;
        // Buffers are zero-initialised by wgpu: all occluded, a_i = 0.
        let bits = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("occlusion bits"),
            size: bits_bytes.max(4),
            usage: readable,
            mapped_at_creation: false,
        });
        let ambient = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("occlusion ambient"),
            size: (rows as u64 * 4).max(4),
            usage: readable,
            mapped_at_creation: false,
        });
        Ok(Self {
            light_box,
            light_buffer,
            receiver_buffer,
            vertex_buffer,
            index_buffer,
            index_count: indices.len() as u32,
            bits,
            ambient,
            rows,
            words_per_row,
        })
    }

    /// The outputs, kept on the GPU.
    pub(crate) fn into_run(self, prepared: &Prepared) -> DepthRun {
        DepthRun {
            bits: self.bits,
            ambient: self.ambient,
            rows: self.rows,
            words_per_row: self.words_per_row,
            zero_normals: prepared
                .receivers
                .iter()
                .map(|r| r.normal == Vec3::ZERO)
                .collect(),
        }
    }
}

/// The GPU-resident result of one `depth` or `query` computation: visibility bits and a_i in
/// storage buffers, read back only on request (wrapped by the public [`GpuVisibility`]).
pub(crate) struct DepthRun {
    bits: wgpu::Buffer,
    ambient: wgpu::Buffer,
    rows: usize,
    words_per_row: usize,
    zero_normals: Vec<bool>,
}

impl DepthRun {
    /// The visibility bits, row-major, `words_per_row` u32 words per receiver.
    pub(crate) fn bits_buffer(&self) -> &wgpu::Buffer {
        &self.bits
    }

    /// a_i, one f32 per receiver (0 for zero-normal vertices on the GPU).
    pub(crate) fn ambient_buffer(&self) -> &wgpu::Buffer {
        &self.ambient
    }

    /// Receiver rows N.
    pub(crate) fn rows(&self) -> usize {
        self.rows
    }

    /// u32 words per row, ⌈k/32⌉.
    pub(crate) fn words_per_row(&self) -> usize {
        self.words_per_row
    }

    /// Reads a_i back (N floats, clamped to [0, 1] as the CPU's); NaN for vertices with a
    /// zero normal.
    pub(crate) fn read_ambient(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> Result<Vec<f32>, OcclusionError> {
        let bytes = gpu_context::read_buffer(device, queue, &self.ambient, self.rows as u64 * 4)
            .map_err(|e| OcclusionError::Readback(e.to_string()))?;
        let mut ambient: Vec<f32> = bytemuck::pod_collect_to_vec(&bytes);
        for (a, &zero) in ambient.iter_mut().zip(&self.zero_normals) {
            *a = if zero {
                f32::NAN
            } else {
                crate::matrix::clamp_ambient(*a)
            };
        }
        Ok(ambient)
    }

    /// Reads the bits back and copies columns `first..k` into `matrix`.
    pub(crate) fn read_bits_into(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        matrix: &mut VisibilityMatrix,
        first: usize,
    ) -> Result<(), OcclusionError> {
        assert_eq!(
            matrix.words_per_row(),
            self.words_per_row,
            "layout mismatch"
        );
        let size = (self.rows * self.words_per_row * 4) as u64;
        let bytes = gpu_context::read_buffer(device, queue, &self.bits, size)
            .map_err(|e| OcclusionError::Readback(e.to_string()))?;
        let words: Vec<u32> = bytemuck::pod_collect_to_vec(&bytes);
        let k = matrix.directions_len();
        let target = matrix.bits_mut();
        for (row_new, row_gpu) in target
            .chunks_exact_mut(self.words_per_row)
            .zip(words.chunks_exact(self.words_per_row))
        {
            for j in first..k {
                let (w, mask) = (j / WORD_BITS, 1u32 << (j % WORD_BITS));
                row_new[w] = (row_new[w] & !mask) | (row_gpu[w] & mask);
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// At the limit passes; one byte over is refused, naming the first buffer over it with
    /// its size and the device's limit.
    #[test]
    fn storage_bindings_past_the_device_limit_are_refused_by_name() {
        let Some(ctx) = gpu_context::testing::gpu_or_skip() else {
            return;
        };
        let maximum = ctx.device.limits().max_storage_buffer_binding_size;
        assert!(check_storage_bindings(&ctx.device, &[("a", maximum), ("b", 0)]).is_ok());
        let refused = check_storage_bindings(
            &ctx.device,
            &[("a", maximum), ("b", maximum + 1), ("c", u64::MAX)],
        );
        match refused {
            Err(OcclusionError::GpuLimit {
                what,
                value,
                maximum: limit,
            }) => assert_eq!((what, value, limit), ("b", maximum + 1, maximum)),
            other => panic!("{other:?}"),
        }
    }
}
