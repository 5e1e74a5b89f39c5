//! GPU decoder (thesis §3.3.2 "Decompression", Fig. 3.18): a WGSL compute shader
//! (`cpca_decode.wgsl`) rebuilds frame f for every vertex, pₘ(f) = r_{Iₘ}(f) + Σₕ wₘₕ E_{Iₘh}(f),
//! into a storage buffer that a renderer binds as its vertex buffer.
//!
//! The dequantized data is uploaded once, in the layout of the CPU [`Decoder`]: the cluster
//! index Iₘ, the weights component-major (wₘₕ at h·V + m), and per frame and cluster the
//! (c + 1) × 3 values r_j(f), E_j1(f), …, E_jc(f). Decoding a frame is one dispatch of one
//! invocation per vertex, c multiply-adds of vec3. With time compression the eigentrajectory
//! values of frame f are first rebuilt from the c* time components by a second kernel (one
//! invocation per cluster row, k·c·c* multiply-adds in all), into a k·(c + 1) × 3 scratch
//! buffer that the vertex kernel reads; both run in one compute pass.
//!
//! The thesis decodes in a vertex program reading the weights as vertex attributes and the
//! eigentrajectories from textures; a compute pass writing a vertex buffer does the same work
//! once per frame instead of once per rendering pass, and keeps the positions for read-back.
//!
//! Values are f32 on both sides and summed in the same order, so GPU and CPU agree to float
//! rounding (the GPU may fuse a multiply-add): ‖Δ‖ ≤ (c + 1)·ε·(|r| + Σₕ|wₕ Eₕ|) per
//! coordinate, as `tests/compress_gpu.rs` checks on lavapipe.

use glam::Vec3;
use wgpu::util::DeviceExt;

use super::container::Compressed;
#[cfg(doc)]
use super::decode::Decoder;
use crate::error::{AnimPcaError, Result};

const SHADER: &str = include_str!("cpca_decode.wgsl");

/// Invocations per workgroup of both kernels (`WORKGROUP` in the shader).
const WORKGROUP_SIZE: u32 = 64;

/// Bytes per decoded position: a `vec4<f32>` (x, y, z, 1).
pub const POSITION_STRIDE: u64 = 16;

/// The uniform block `Params` of the shader.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Params {
    vertices: u32,
    clusters: u32,
    components: u32,
    frame: u32,
    row_base: u32,
    time_components: u32,
    _pad: [u32; 2],
}

/// Pipeline and bind group of the time-compression kernel.
#[derive(Debug)]
struct TimePass {
    pipeline: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
    /// Invocations: k·(c + 1).
    invocations: u32,
}

/// A [`Compressed`] animation resident on the GPU, decoding any frame into
/// [`GpuDecoder::positions_buffer`].
///
/// ```no_run
/// # fn demo(device: &wgpu::Device, queue: &wgpu::Queue, packed: &anim_pca::Compressed)
/// #     -> anim_pca::Result<()> {
/// use anim_pca::compress::GpuDecoder;
///
/// let gpu = GpuDecoder::new(device, queue, packed)?;
/// gpu.decode(12)?; // frame 12 into gpu.positions_buffer(), ready to draw
/// let mesh = gpu.read_frame(12)?; // or on the CPU
/// assert_eq!(mesh.len(), packed.vertices());
/// # Ok(()) }
/// ```
#[derive(Debug)]
pub struct GpuDecoder {
    device: wgpu::Device,
    queue: wgpu::Queue,
    vertices: usize,
    frames: usize,
    clusters: usize,
    components: usize,
    time_components: Option<usize>,
    params: wgpu::Buffer,
    positions: wgpu::Buffer,
    pipeline: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
    time: Option<TimePass>,
}

/// Checks one buffer of `count` elements of `size` bytes against the device's limits and the
/// shader's u32 indices.
fn check_limit(device: &wgpu::Device, what: &'static str, count: usize, size: u64) -> Result<()> {
    let limits = device.limits();
    let maximum = limits
        .max_storage_buffer_binding_size
        .min(limits.max_buffer_size)
        .min(u64::from(u32::MAX) * size);
    let bytes = (count as u64).saturating_mul(size);
    if bytes > maximum {
        return Err(AnimPcaError::GpuLimit {
            what,
            value: bytes,
            maximum,
        });
    }
    Ok(())
}

fn storage_entry(binding: u32, read_only: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

fn uniform_entry() -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding: 0,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

/// A compute pipeline of `entry` in `module` over one bind group of `entries`.
fn make_pipeline(
    device: &wgpu::Device,
    module: &wgpu::ShaderModule,
    entry: &'static str,
    entries: &[wgpu::BindGroupLayoutEntry],
) -> (wgpu::ComputePipeline, wgpu::BindGroupLayout) {
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(entry),
        entries,
    });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(entry),
        bind_group_layouts: &[Some(&layout)],
        immediate_size: 0,
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(entry),
        layout: Some(&pipeline_layout),
        module,
        entry_point: Some(entry),
        compilation_options: Default::default(),
        cache: None,
    });
    (pipeline, layout)
}

fn make_bind_group(
    device: &wgpu::Device,
    label: &'static str,
    layout: &wgpu::BindGroupLayout,
    buffers: &[(u32, &wgpu::Buffer)],
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry> = buffers
        .iter()
        .map(|&(binding, buffer)| wgpu::BindGroupEntry {
            binding,
            resource: buffer.as_entire_binding(),
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &entries,
    })
}

/// Workgroups (x, y) covering `invocations` with at most `per_dimension` groups along x.
fn groups(invocations: u32, per_dimension: u32) -> (u32, u32) {
    let total = invocations.div_ceil(WORKGROUP_SIZE).max(1);
    let x = total.min(per_dimension.max(1));
    (x, total.div_ceil(x))
}

impl GpuDecoder {
    /// Dequantizes `data` (as [`Decoder::new`] does) and uploads it to `device`, with a
    /// position buffer of V × [`POSITION_STRIDE`] bytes (usages `STORAGE | VERTEX |
    /// COPY_SRC`). Both layouts are supported: direct eigentrajectories and time compression.
    ///
    /// # Errors
    /// [`AnimPcaError::GpuLimit`] when a buffer (the per-frame rows F·k·(c + 1)·3 floats, the
    /// weights V·c floats, the time basis F·c*·3 floats, …) exceeds the device's
    /// `max_storage_buffer_binding_size` or `max_buffer_size`, or 2³² elements: request a
    /// device with larger limits (`gpu-context` asks for the adapter's own) or compress with
    /// time components, fewer frames or fewer components.
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue, data: &Compressed) -> Result<Self> {
        let (v, f, k, c) = (data.vertices, data.frames, data.clusters, data.components);
        let cs = data.time_components();
        let stride = (c + 1) * 3;
        let row_values = match cs {
            None => f * k * stride,
            Some(_) => k * stride,
        };
        check_limit(device, "GpuDecoder rows bytes", row_values, 4)?;
        check_limit(device, "GpuDecoder weights bytes", v * c, 4)?;
        check_limit(device, "GpuDecoder positions bytes", v, POSITION_STRIDE)?;
        if let Some(cs) = cs {
            check_limit(device, "GpuDecoder means bytes", f * k * 3, 4)?;
            check_limit(device, "GpuDecoder time coefficients bytes", k * c * cs, 4)?;
            check_limit(device, "GpuDecoder time basis bytes", f * cs * 3, 4)?;
        }

        let init = |label: &'static str, values: &[f32]| {
            // A binding may not be empty; one unused zero keeps the layout valid.
            let contents: &[f32] = if values.is_empty() { &[0.0] } else { values };
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: bytemuck::cast_slice(contents),
                usage: wgpu::BufferUsages::STORAGE,
            })
        };
        let labels = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("cpca labels"),
            contents: bytemuck::cast_slice(&data.labels),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let weights: Vec<f32> = data
            .weights
            .iter()
            .flat_map(|q| q.values().map(|x| x as f32))
            .collect();
        let weights = init("cpca weights", &weights);
        let means: Vec<Vec<f64>> = data.means.iter().map(|q| q.values().collect()).collect();
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("cpca params"),
            size: std::mem::size_of::<Params>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let positions = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("cpca positions"),
            size: v as u64 * POSITION_STRIDE,
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::VERTEX
                | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("cpca_decode.wgsl"),
            source: wgpu::ShaderSource::Wgsl(SHADER.into()),
        });
        let (pipeline, layout) = make_pipeline(
            device,
            &module,
            "decode_frame",
            &[
                uniform_entry(),
                storage_entry(1, true),
                storage_entry(2, true),
                storage_entry(3, true),
                storage_entry(4, false),
            ],
        );

        let (rows, time) = match &data.time {
            None => {
                let eigen: Vec<Vec<f64>> =
                    data.eigen.iter().map(|q| q.values().collect()).collect();
                let mut rows = vec![0f32; row_values];
                for t in 0..f {
                    for j in 0..k {
                        let dst = &mut rows[(t * k + j) * stride..][..stride];
                        for a in 0..3 {
                            dst[a] = means[3 * j + a][t] as f32;
                            for h in 0..c {
                                dst[3 * (h + 1) + a] = eigen[j * c + h][3 * t + a] as f32;
                            }
                        }
                    }
                }
                (init("cpca rows", &rows), None)
            }
            Some(basis) => {
                let cs = basis.basis.len();
                let mut m = vec![0f32; f * k * 3];
                for t in 0..f {
                    for j in 0..k {
                        for a in 0..3 {
                            m[(t * k + j) * 3 + a] = means[3 * j + a][t] as f32;
                        }
                    }
                }
                let coef: Vec<f32> = data
                    .eigen
                    .iter()
                    .flat_map(|q| q.values().map(|x| x as f32))
                    .collect();
                let mean: Vec<f32> = basis.mean.values().map(|x| x as f32).collect();
                let b: Vec<Vec<f64>> = basis.basis.iter().map(|q| q.values().collect()).collect();
                let mut packed = vec![0f32; f * cs * 3];
                for t in 0..f {
                    for (s, bs) in b.iter().enumerate() {
                        for a in 0..3 {
                            packed[(t * cs + s) * 3 + a] = bs[3 * t + a] as f32;
                        }
                    }
                }
                let rows = device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("cpca frame rows"),
                    size: (row_values * 4) as u64,
                    usage: wgpu::BufferUsages::STORAGE,
                    mapped_at_creation: false,
                });
                let (time_pipeline, time_layout) = make_pipeline(
                    device,
                    &module,
                    "rows_from_time",
                    &[
                        uniform_entry(),
                        storage_entry(5, true),
                        storage_entry(6, true),
                        storage_entry(7, true),
                        storage_entry(8, true),
                        storage_entry(9, false),
                    ],
                );
                let (means, coef, mean, basis) = (
                    init("cpca means", &m),
                    init("cpca time coefficients", &coef),
                    init("cpca time mean", &mean),
                    init("cpca time basis", &packed),
                );
                let bind_group = make_bind_group(
                    device,
                    "rows_from_time",
                    &time_layout,
                    &[
                        (0, &params),
                        (5, &means),
                        (6, &coef),
                        (7, &mean),
                        (8, &basis),
                        (9, &rows),
                    ],
                );
                let time = TimePass {
                    pipeline: time_pipeline,
                    bind_group,
                    // ≤ row_values / 3, checked to fit u32 above.
                    invocations: (k * (c + 1)) as u32,
                };
                (rows, Some(time))
            }
        };
        let bind_group = make_bind_group(
            device,
            "decode_frame",
            &layout,
            &[
                (0, &params),
                (1, &labels),
                (2, &weights),
                (3, &rows),
                (4, &positions),
            ],
        );
        Ok(Self {
            device: device.clone(),
            queue: queue.clone(),
            vertices: v,
            frames: f,
            clusters: k,
            components: c,
            time_components: cs,
            params,
            positions,
            pipeline,
            bind_group,
            time,
        })
    }

    /// Vertices V.
    pub fn vertices(&self) -> usize {
        self.vertices
    }

    /// Frames F.
    pub fn frames(&self) -> usize {
        self.frames
    }

    /// The decoded positions: V × (x, y, z, 1) as `vec4<f32>` ([`POSITION_STRIDE`] bytes per
    /// vertex, in vertex order). Bind it as a vertex buffer of `Float32x4` (or `Float32x3`
    /// with stride 16), or as a read-only storage buffer. It holds the frame of the last
    /// [`GpuDecoder::decode`] (zeros before the first).
    pub fn positions_buffer(&self) -> &wgpu::Buffer {
        &self.positions
    }

    /// Rebuilds frame `frame` into [`GpuDecoder::positions_buffer`]: writes the frame index
    /// and submits one command buffer with the compute pass. Work submitted afterwards on the
    /// same queue (a render pass drawing the positions) sees the new frame; nothing waits
    /// here.
    ///
    /// # Errors
    /// [`AnimPcaError::InvalidParameter`] if `frame ≥ F`.
    pub fn decode(&self, frame: usize) -> Result<()> {
        if frame >= self.frames {
            return Err(crate::error::invalid(
                "GpuDecoder::decode",
                "frame",
                frame,
                "the frame index must be below the frame count",
            ));
        }
        let stride = (self.components + 1) * 3;
        let params = Params {
            // All fit u32: checked against the buffer limits in `new`.
            vertices: self.vertices as u32,
            clusters: self.clusters as u32,
            components: self.components as u32,
            frame: frame as u32,
            row_base: match self.time {
                None => (frame * self.clusters * stride) as u32,
                Some(_) => 0,
            },
            time_components: self.time_components.unwrap_or(0) as u32,
            _pad: [0; 2],
        };
        self.queue
            .write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
        let per_dimension = self.device.limits().max_compute_workgroups_per_dimension;
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("cpca decode"),
            });
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("cpca decode"),
                timestamp_writes: None,
            });
            if let Some(time) = &self.time {
                let (x, y) = groups(time.invocations, per_dimension);
                pass.set_pipeline(&time.pipeline);
                pass.set_bind_group(0, &time.bind_group, &[]);
                pass.dispatch_workgroups(x, y, 1);
            }
            let (x, y) = groups(self.vertices as u32, per_dimension);
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &self.bind_group, &[]);
            pass.dispatch_workgroups(x, y, 1);
        }
        self.queue.submit([encoder.finish()]);
        Ok(())
    }

    /// Decodes frame `frame` and reads it back (blocking): V positions in vertex order, as
    /// [`Decoder::frame_into`] gives them.
    ///
    /// # Errors
    /// [`AnimPcaError::InvalidParameter`] if `frame ≥ F`; [`AnimPcaError::GpuReadback`] if
    /// the device is lost or mapping the read-back buffer fails.
    pub fn read_frame(&self, frame: usize) -> Result<Vec<Vec3>> {
        self.decode(frame)?;
        let size = self.vertices as u64 * POSITION_STRIDE;
        let staging = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("cpca read-back"),
            size,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("cpca read-back"),
            });
        encoder.copy_buffer_to_buffer(&self.positions, 0, &staging, 0, size);
        self.queue.submit([encoder.finish()]);
        let readback = |e: &dyn std::fmt::Display| AnimPcaError::GpuReadback {
            what: "GpuDecoder::read_frame",
            reason: e.to_string(),
        };
        let slice = staging.slice(..);
        let (sender, receiver) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |result| {
            // The receiver lives until recv() below returns.
            let _ = sender.send(result);
        });
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| readback(&e))?;
        receiver
            .recv()
            .map_err(|e| readback(&e))?
            .map_err(|e| readback(&e))?;
        let mapped = slice.get_mapped_range().map_err(|e| readback(&e))?;
        // Copied out: the mapped bytes need not be aligned for f32.
        let xyzw: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&mapped);
        let out = xyzw.iter().map(|p| Vec3::new(p[0], p[1], p[2])).collect();
        drop(mapped);
        staging.unmap();
        if let Some(error) = gpu_context::take_device_error() {
            return Err(readback(&error));
        }
        Ok(out)
    }
}
