//! The `query` backend, as published (paper 000 §3.2, Figure 2): per light direction l_j the
//! scene is rendered into an orthographic depth map (the `depth` backend's scene pass and
//! [`LightBox`](super::LightBox)), then every receiver vertex is drawn as a point of size 1
//! with depth test LessEqual and no depth write, each inside its own hardware occlusion query;
//! a vertex whose query counts a sample is visible, M_ij = n_i·l_j (eq. in §3.2).
//!
//! Deviations from the seed, and why:
//! * The seed reads every query back to the CPU (its §8.1 names that as the drawback). Here
//!   the queries of a batch of directions (≤ [`QUERY_SET_MAX_QUERIES`] per query set) are
//!   resolved with `resolve_query_set` into a GPU buffer, and `occlusion_pack.wgsl` turns the
//!   sample counts into the same visibility bits and a_i sums as the `depth` backend. No query
//!   result is waited on; M stays on the GPU until it is asked for.
//! * `glPolygonOffset(1, 1)` biases polygons only, and Vulkan gives points no fixed-function
//!   bias, so the equivalent bias is applied in the vertex shader with the `depth` backend's
//!   formula and [`DepthParams`] knobs (constant + slope-scaled bias, normal offset). The
//!   point is snapped to the texel centre the compute test reads, so both GPU backends make
//!   the same decision up to float rounding of the same expressions.
//! * Both faces of the scene are rasterised (two-sided cloth), as in the `depth` backend.
//!
//! It is slow by nature — N·k draws and queries — and kept as the published baseline.

use glam::Vec3;
use wgpu::{QUERY_SET_MAX_QUERIES, QUERY_SIZE};

use super::{
    DepthParams, DepthPipelines, DepthRun, SceneBuffers, check_resolution, check_storage_bindings,
    storage_entry,
};
use crate::OcclusionError;
use crate::progress::Ticker;
use crate::scene::Prepared;

/// Queries per batch of directions (64 query sets, 2 MiB of resolved counts). A batch is one
/// submission: scene passes, point passes, resolves and the pack dispatch. Large enough to
/// keep per-submission overhead small on lavapipe, small enough to keep the buffer modest.
const DEFAULT_MAX_BATCH_QUERIES: usize = 64 * QUERY_SET_MAX_QUERIES as usize;

const QUERY_SHADER: &str = include_str!("occlusion_query.wgsl");
const PACK_SHADER: &str = include_str!("occlusion_pack.wgsl");

/// `struct Params` of `occlusion_query.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct PointParams {
    resolution: u32,
    texel_world: f32,
    texel_depth: f32,
    bias_constant_texels: f32,
    bias_slope_texels: f32,
    max_slope: f32,
    normal_offset_texels: f32,
    _pad: f32,
}

/// `struct Params` of `occlusion_pack.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct PackParams {
    vertex_count: u32,
    first_direction: u32,
    direction_count: u32,
    words_per_row: u32,
}

/// The compiled pipelines of the `query` backend (build once per device); the scene pass is
/// the `depth` backend's.
pub(crate) struct QueryPipelines {
    point_pipeline: wgpu::RenderPipeline,
    point_layout: wgpu::BindGroupLayout,
    pack_pipeline: wgpu::ComputePipeline,
    pack_layout: wgpu::BindGroupLayout,
}

fn uniform_entry(binding: u32, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

fn entries<'a>(buffers: &[&'a wgpu::Buffer]) -> Vec<wgpu::BindGroupEntry<'a>> {
    buffers
        .iter()
        .enumerate()
        .map(|(binding, buffer)| wgpu::BindGroupEntry {
            binding: binding as u32,
            resource: buffer.as_entire_binding(),
        })
        .collect()
}

impl QueryPipelines {
    pub(crate) fn new(device: &wgpu::Device) -> Self {
        let point_module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("occlusion_query.wgsl"),
            source: wgpu::ShaderSource::Wgsl(QUERY_SHADER.into()),
        });
        let pack_module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("occlusion_pack.wgsl"),
            source: wgpu::ShaderSource::Wgsl(PACK_SHADER.into()),
        });
        let vertex = wgpu::ShaderStages::VERTEX;
        let point_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("occlusion query points"),
            entries: &[
                uniform_entry(0, vertex),
                storage_entry(1, vertex, true),
                storage_entry(2, vertex, true),
            ],
        });
        let compute = wgpu::ShaderStages::COMPUTE;
        let pack_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("occlusion query pack"),
            entries: &[
                uniform_entry(0, compute),
                storage_entry(1, compute, true),
                storage_entry(2, compute, true),
                storage_entry(3, compute, true),
                storage_entry(4, compute, false),
                storage_entry(5, compute, false),
            ],
        });
        let point_pipeline_layout =
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("occlusion query points"),
                bind_group_layouts: &[Some(&point_layout)],
                immediate_size: 0,
            });
        let point_pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("occlusion query points"),
            layout: Some(&point_pipeline_layout),
            vertex: wgpu::VertexState {
                module: &point_module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::PointList,
                cull_mode: None,
                ..Default::default()
            },
            // §3.2: "without updating the depth buffer"; the bias is in the vertex shader.
            depth_stencil: Some(wgpu::DepthStencilState {
                format: wgpu::TextureFormat::Depth32Float,
                depth_write_enabled: Some(false),
                depth_compare: Some(wgpu::CompareFunction::LessEqual),
                stencil: wgpu::StencilState::default(),
                bias: wgpu::DepthBiasState::default(),
            }),
            multisample: wgpu::MultisampleState::default(),
            fragment: None,
            multiview_mask: None,
            cache: None,
        });
        let pack_pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("occlusion query pack"),
            bind_group_layouts: &[Some(&pack_layout)],
            immediate_size: 0,
        });
        let pack_pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("occlusion query pack"),
            layout: Some(&pack_pipeline_layout),
            module: &pack_module,
            entry_point: Some("cs_main"),
            compilation_options: Default::default(),
            cache: None,
        });
        Self {
            point_pipeline,
            point_layout,
            pack_pipeline,
            pack_layout,
        }
    }

    /// Computes the columns `first..k` with one occlusion query per (vertex, direction); the
    /// results stay in the returned buffers. `depth` provides the scene pass.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn run(
        &self,
        depth: &DepthPipelines,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        prepared: &Prepared,
        directions: &[Vec3],
        solid_angles: &[f64],
        first: usize,
        params: &DepthParams,
        ticker: &std::sync::Arc<Ticker>,
    ) -> Result<DepthRun, OcclusionError> {
        let resolution = check_resolution(device, params.resolution)?;
        let scene = SceneBuffers::new(device, prepared, directions, solid_angles)?;
        let (rows, words_per_row, k) = (scene.rows, scene.words_per_row, directions.len());
        if rows == 0 || first >= k {
            return Ok(scene.into_run(prepared));
        }
        // Directions per batch: as many as fit the query budget, at least one.
        let batch_directions = (DEFAULT_MAX_BATCH_QUERIES / rows).clamp(1, k - first);
        let batch_queries = batch_directions * rows;
        let resolved_bytes = batch_queries as u64 * u64::from(QUERY_SIZE);
        check_storage_bindings(
            device,
            &[(
                "resolved occlusion-query bytes (receiver vertices × 8)",
                resolved_bytes,
            )],
        )?;
        let set_size = QUERY_SET_MAX_QUERIES as usize;
        let query_sets: Vec<wgpu::QuerySet> = (0..batch_queries.div_ceil(set_size))
            .map(|_| {
                device.create_query_set(&wgpu::QuerySetDescriptor {
                    label: Some("occlusion queries"),
                    ty: wgpu::QueryType::Occlusion,
                    count: QUERY_SET_MAX_QUERIES,
                })
            })
            .collect();
        let resolved = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("occlusion query counts"),
            size: resolved_bytes,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        let depth_map = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("occlusion query depth map"),
            size: wgpu::Extent3d {
                width: resolution,
                height: resolution,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Depth32Float,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        });
        let depth_view = depth_map.create_view(&wgpu::TextureViewDescriptor::default());

        let point_params = PointParams {
            resolution,
            texel_world: 2.0 * scene.light_box.half_extent / resolution as f32,
            // The depth range (2R) equals the box width, so one texel is 1/res in depth.
            texel_depth: 1.0 / resolution as f32,
            bias_constant_texels: params.bias_constant_texels,
            bias_slope_texels: params.bias_slope_texels,
            max_slope: params.max_slope,
            normal_offset_texels: params.normal_offset_texels,
            _pad: 0.0,
        };
        let uniform = |label, size: usize| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: size as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let point_params_buffer = uniform("occlusion query params", size_of::<PointParams>());
        queue.write_buffer(&point_params_buffer, 0, bytemuck::bytes_of(&point_params));
        let pack_params_buffer = uniform("occlusion pack params", size_of::<PackParams>());
        let depth_group = depth.depth_bind_group(device, &scene);
        let point_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("occlusion query points"),
            layout: &self.point_layout,
            entries: &entries(&[
                &point_params_buffer,
                &scene.receiver_buffer,
                &scene.light_buffer,
            ]),
        });
        let pack_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("occlusion query pack"),
            layout: &self.pack_layout,
            entries: &entries(&[
                &pack_params_buffer,
                &scene.receiver_buffer,
                &scene.light_buffer,
                &resolved,
                &scene.bits,
                &scene.ambient,
            ]),
        });
        let (groups_x, groups_y) = super::workgroups(rows);

        let mut first_direction = first;
        while first_direction < k {
            let direction_count = batch_directions.min(k - first_direction);
            let pack_params = PackParams {
                vertex_count: rows as u32,
                first_direction: first_direction as u32,
                direction_count: direction_count as u32,
                words_per_row: words_per_row as u32,
            };
            queue.write_buffer(&pack_params_buffer, 0, bytemuck::bytes_of(&pack_params));
            let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("occlusion query batch"),
            });
            for d in 0..direction_count {
                let j = (first_direction + d) as u32;
                self.record_direction(
                    &mut encoder,
                    depth,
                    &depth_view,
                    &query_sets,
                    (&depth_group, &point_group),
                    &scene,
                    j,
                    d * rows,
                );
            }
            // Resolve only the queries written in this batch (whole sets but the last).
            let used = direction_count * rows;
            for (s, set) in query_sets.iter().enumerate() {
                let start = s * set_size;
                if start >= used {
                    break;
                }
                let count = (used - start).min(set_size) as u32;
                let offset = (start * QUERY_SIZE as usize) as u64;
                encoder.resolve_query_set(set, 0..count, &resolved, offset);
            }
            {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("occlusion query pack"),
                    timestamp_writes: None,
                });
                pass.set_pipeline(&self.pack_pipeline);
                pass.set_bind_group(0, &pack_group, &[]);
                pass.dispatch_workgroups(groups_x, groups_y, 1);
            }
            queue.submit([encoder.finish()]);
            // Counted when the device has finished the batch (fired by this poll or a later
            // one, at the latest the read-back's wait).
            let done = std::sync::Arc::clone(ticker);
            let cells = (rows * direction_count) as u64;
            queue.on_submitted_work_done(move || done.tick(cells));
            // A failed non-blocking poll leaves the callbacks to the read-back's wait.
            let _ = device.poll(wgpu::PollType::Poll);
            first_direction += direction_count;
        }
        Ok(scene.into_run(prepared))
    }

    /// Records direction `j`: the scene into the depth map, then one point per receiver, each
    /// in its own occlusion query `first_query + i` of the batch. A render pass takes one
    /// query set, so the points are split into passes at query-set boundaries; the first
    /// pass clears the depth map and draws the scene, the others load it.
    #[allow(clippy::too_many_arguments)]
    fn record_direction(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        depth: &DepthPipelines,
        depth_view: &wgpu::TextureView,
        query_sets: &[wgpu::QuerySet],
        (depth_group, point_group): (&wgpu::BindGroup, &wgpu::BindGroup),
        scene: &SceneBuffers,
        j: u32,
        first_query: usize,
    ) {
        let set_size = QUERY_SET_MAX_QUERIES as usize;
        let mut i = 0;
        while i < scene.rows {
            let query = first_query + i;
            let (set, local) = (query / set_size, query % set_size);
            let count = (scene.rows - i).min(set_size - local);
            let load = if i == 0 {
                wgpu::LoadOp::Clear(1.0)
            } else {
                wgpu::LoadOp::Load
            };
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("occlusion query"),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: depth_view,
                    depth_ops: Some(wgpu::Operations {
                        load,
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: Some(&query_sets[set]),
                multiview_mask: None,
            });
            if i == 0 {
                depth.draw_scene(&mut pass, depth_group, scene, j);
            }
            pass.set_pipeline(&self.point_pipeline);
            pass.set_bind_group(0, point_group, &[]);
            for t in 0..count {
                let vertex = (i + t) as u32;
                pass.begin_occlusion_query((local + t) as u32);
                pass.draw(vertex..vertex + 1, j..j + 1);
                pass.end_occlusion_query();
            }
            i += count;
        }
    }
}
