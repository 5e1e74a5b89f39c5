//! The `rays` backend: the `cpu` backend's exact rays cast by a compute shader
//! (`occlusion_rays.wgsl`) — no depth map, no bias, no resolution. The binary BVH is built on the
//! CPU (`obvhs`'s PLOC, boxes padded as for the fans), the ray origins too (so that they round as
//! the CPU's), and the GPU walks it: one invocation per (receiver row, 32-direction word of M),
//! neighbouring invocations on rows neighbouring in Morton order (coherent walks: 1.17–1.19× faster
//! on lavapipe than file order on the bunny at k = 66 and 258), any hit, the CPU single-ray test's
//! Möller–Trumbore arithmetic and edge tolerance. M equals the `cpu` backend's up to rays within
//! rounding of a triangle edge or of the tangent plane (the GPU may fuse a multiply and an add
//! where the CPU rounds twice).
//!
//! The tree is kept between calls ([`RayTree`]), on the CPU and uploaded: reused as it is while
//! the geometry is unchanged (refinement to a finer level, vertex filtering, an idle scene),
//! refitted when only positions moved (a deforming mesh: [`CpuParams::refit`], up to
//! [`REBUILD_SAH_RATIO`] — the `cpu` backend's clock-based rule is not applied, the GPU's
//! traversal time not being measured per call), rebuilt otherwise. A refitted tree gives the
//! same M bit for bit: its boxes still hold their padded triangles and each ray's triangle
//! tests are the same.
//!
//! For GPUs that rasterise on a small part of their chip — a data-centre H100 took 0.4 ms per
//! 1024² depth map of the bunny — and for anyone who wants the exact answer from a GPU.

use glam::{Vec3, Vec3A};
use gpu_context::layout::{self, binding};
use gpu_context::pipeline;
use wgpu::util::DeviceExt;

use obvhs::bvh2::node::Bvh2Node;

use super::{DepthRun, check_storage_bindings, workgroups};
use crate::cpu::{CpuParams, fan_build, morton_order};
use crate::matrix::WORD_BITS;
use crate::progress::Ticker;
use crate::refit::{LeafOrder, REBUILD_SAH_RATIO, padded_bvh2, refit_tree};
use crate::scene::{Prepared, scaled_max_t};
use crate::{BvhStats, BvhUpdate, OcclusionError};

const RAYS_SHADER: &str = include_str!("occlusion_rays.wgsl");

/// `STACK_SIZE` of `occlusion_rays.wgsl`: the deepest root-to-leaf path it can walk.
const STACK_SIZE: usize = 64;
/// Triangles per BVH leaf.
const LEAF_SIZE: u32 = 4;
/// About this many invocations per submission: enough to fill a large GPU, few enough that
/// no single submission runs long (a desktop's GPU watchdog) and progress moves.
const CELLS_PER_SUBMISSION: usize = 1 << 18;

/// `struct Params` of `occlusion_rays.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct RayParams {
    rows: u32,
    words_per_row: u32,
    first_word: u32,
    word_count: u32,
    first_direction: u32,
    k: u32,
    max_t: f32,
    node_count: u32,
    call_first_word: u32,
    call_word_count: u32,
    _pad: [u32; 2],
}

/// `struct Node` of `occlusion_rays.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct GpuNode {
    lo: [f32; 3],
    first: u32,
    hi: [f32; 3],
    count: u32,
}

/// A triangle as the shader reads it: v0, e1 = v1 − v0, e2 = v2 − v0 (each padded to four
/// floats), computed as the `cpu` backend's single-ray test computes them.
fn gpu_triangle([v0, v1, v2]: [Vec3A; 3]) -> [f32; 12] {
    let (e1, e2) = (v1 - v0, v2 - v0);
    [
        v0.x, v0.y, v0.z, 0.0, e1.x, e1.y, e1.z, 0.0, e2.x, e2.y, e2.z, 0.0,
    ]
}

/// The shader's copy of `nodes`.
fn gpu_nodes(nodes: &[Bvh2Node]) -> Vec<GpuNode> {
    nodes
        .iter()
        .map(|n| GpuNode {
            lo: n.aabb.min.into(),
            first: n.first_index,
            hi: n.aabb.max.into(),
            count: n.prim_count,
        })
        .collect()
}

/// The BVH of the last scene the `rays` backend traced: the tree in the tracer's scaled
/// coordinates (for refits), its leaf order, and its GPU buffers.
pub(crate) struct RayTree {
    /// The geometry it was built or refitted for (centred, unscaled).
    positions: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    /// In the coordinates of that geometry's [`Prepared::tracer_scale`].
    nodes: Vec<Bvh2Node>,
    leaves: LeafOrder,
    /// The leaf-ordered triangles as uploaded.
    gpu_triangles: Vec<[f32; 12]>,
    node_buffer: wgpu::Buffer,
    triangle_buffer: wgpu::Buffer,
}

impl RayTree {
    /// Builds the tree of `prepared` (at its tracer scale) and uploads it.
    fn build(device: &wgpu::Device, prepared: &Prepared) -> Result<Self, OcclusionError> {
        let scaled = prepared.scaled(prepared.tracer_scale());
        let (nodes, triangles, leaves) = padded_bvh2(&scaled, fan_build(), LEAF_SIZE);
        let depth = tree_depth(&nodes);
        if depth > STACK_SIZE {
            return Err(OcclusionError::BvhTooDeep {
                depth: depth as u64,
                maximum: STACK_SIZE as u64,
            });
        }
        let gpu_triangles: Vec<[f32; 12]> = triangles
            .iter()
            .map(|t| gpu_triangle([t.v0, t.v1, t.v2]))
            .collect();
        check_storage_bindings(
            device,
            &[
                ("rays backend BVH node bytes", (nodes.len() * 32) as u64),
                ("rays backend triangle bytes", (triangles.len() * 48) as u64),
            ],
        )?;
        let node_buffer = storage_init(
            device,
            "occlusion rays nodes",
            bytemuck::cast_slice(&gpu_nodes(&nodes)),
        );
        let triangle_buffer = storage_init(
            device,
            "occlusion rays triangles",
            bytemuck::cast_slice(&gpu_triangles),
        );
        Ok(Self {
            positions: prepared.positions.clone(),
            triangles: prepared.triangles.clone(),
            nodes,
            leaves,
            gpu_triangles,
            node_buffer,
            triangle_buffer,
        })
    }

    /// Whether this tree was built (or refitted) for exactly `prepared`'s geometry.
    fn fits(&self, prepared: &Prepared) -> bool {
        self.positions == prepared.positions && self.triangles == prepared.triangles
    }

    /// Refits the tree to `prepared` when only positions changed (same triangles and vertex
    /// count; the boxes are recomputed at the new tracer scale, which a growing scene may
    /// change): the SAH cost over the build's (which does not depend on the scale), or `None`
    /// when it cannot be refitted. Nothing is uploaded: [`RayTree::upload`] does that once the
    /// refit is kept.
    fn refit(&mut self, prepared: &Prepared) -> Option<f32> {
        if self.triangles != prepared.triangles
            || self.positions.len() != prepared.positions.len()
            || self.nodes.is_empty()
        {
            return None;
        }
        let scaled = prepared.scaled(prepared.tracer_scale());
        let ratio = refit_tree(
            &mut self.nodes,
            &self.leaves,
            &mut self.gpu_triangles,
            &scaled,
            gpu_triangle,
        )?;
        self.positions.clone_from(&prepared.positions);
        Some(ratio)
    }

    /// Writes the (refitted) nodes and triangles into the tree's GPU buffers.
    fn upload(&self, queue: &wgpu::Queue) {
        queue.write_buffer(
            &self.node_buffer,
            0,
            bytemuck::cast_slice(&gpu_nodes(&self.nodes)),
        );
        queue.write_buffer(
            &self.triangle_buffer,
            0,
            bytemuck::cast_slice(&self.gpu_triangles),
        );
    }

    /// Brings `cached` to `prepared`: reused when it fits, refitted when `refit` allows and
    /// the refitted tree's SAH ratio is at most [`REBUILD_SAH_RATIO`], built otherwise.
    pub(crate) fn update<'a>(
        cached: &'a mut Option<Self>,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        prepared: &Prepared,
        refit: bool,
    ) -> Result<(&'a Self, BvhStats), OcclusionError> {
        let start = std::time::Instant::now();
        let update = match cached.as_mut() {
            Some(tree) if tree.fits(prepared) => BvhUpdate::Reused,
            Some(tree) if refit => match tree.refit(prepared) {
                Some(sah_ratio) if sah_ratio <= REBUILD_SAH_RATIO => {
                    tree.upload(queue);
                    BvhUpdate::Refitted { sah_ratio }
                }
                _ => BvhUpdate::Built,
            },
            _ => BvhUpdate::Built,
        };
        if update == BvhUpdate::Built {
            // The old tree goes first: a failed build leaves nothing stale behind.
            *cached = None;
            *cached = Some(Self::build(device, prepared)?);
        }
        let stats = BvhStats {
            update,
            millis: start.elapsed().as_secs_f64() * 1e3,
        };
        Ok((cached.as_ref().expect("set above"), stats))
    }
}

/// A storage buffer holding `contents` (one zero triangle's worth when empty: wgpu refuses a
/// zero-sized binding), writable by `queue.write_buffer` for refits.
fn storage_init(device: &wgpu::Device, label: &str, contents: &[u8]) -> wgpu::Buffer {
    let contents = if contents.is_empty() {
        &[0u8; 48][..]
    } else {
        contents
    };
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
    })
}

/// The compiled pipelines of the `rays` backend (built once per device).
pub(crate) struct RayPipelines {
    layout: wgpu::BindGroupLayout,
    trace: wgpu::ComputePipeline,
    sum_rows: wgpu::ComputePipeline,
}

impl RayPipelines {
    pub(crate) fn new(device: &wgpu::Device) -> Self {
        let module = pipeline::shader_module(device, "occlusion_rays.wgsl", RAYS_SHADER);
        let read = binding::storage_read();
        let write = binding::storage_rw();
        let layout = layout::bind_group_layout(
            device,
            "occlusion rays",
            wgpu::ShaderStages::COMPUTE,
            &[
                binding::uniform(),
                read,
                read,
                read,
                read,
                write,
                write,
                write,
                read,
            ],
        );
        let pipeline_layout = pipeline::pipeline_layout(device, "occlusion rays", &[&layout]);
        let trace = pipeline::compute_pipeline(
            device,
            "occlusion rays",
            &pipeline_layout,
            &module,
            "trace",
        );
        let sum_rows = pipeline::compute_pipeline(
            device,
            "occlusion rays: a_i",
            &pipeline_layout,
            &module,
            "sum_rows",
        );
        Self {
            layout,
            trace,
            sum_rows,
        }
    }

    /// Computes the columns `first..k` on the GPU with `tree` brought to `prepared`
    /// ([`RayTree::update`]); the results stay in the returned buffers.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn run(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        prepared: &Prepared,
        directions: &[Vec3],
        solid_angles: &[f64],
        first: usize,
        params: &CpuParams,
        tree: &mut Option<RayTree>,
        ticker: &std::sync::Arc<Ticker>,
    ) -> Result<(DepthRun, BvhStats), OcclusionError> {
        let k = directions.len();
        let rows = prepared.receivers.len();
        let words_per_row = k.div_ceil(WORD_BITS);
        let call_first_word = first / WORD_BITS;
        let call_word_count = words_per_row.saturating_sub(call_first_word);
        // The `cpu` backend's origins, rounded as it rounds them, then scaled by a power of
        // two (exact).
        let offset = params.offset_relative * prepared.diagonal;
        let scale = prepared.tracer_scale();
        // In Morton order of the receivers' positions: neighbouring invocations trace the same
        // direction from nearby origins (coherent paths through the tree); `order` maps each
        // slot back to its row.
        let order = morton_order(prepared);
        let origins: Vec<[f32; 8]> = order
            .iter()
            .map(|&row| {
                let r = &prepared.receivers[row as usize];
                let n = Vec3A::from(r.normal);
                let o = (Vec3A::from(r.position) + n * offset) * scale;
                [o.x, o.y, o.z, 1.0, n.x, n.y, n.z, 0.0]
            })
            .collect();
        let bits_bytes = (rows * words_per_row * 4) as u64;
        let shares_bytes = (rows * call_word_count * 4) as u64;
        check_storage_bindings(
            device,
            &[
                ("visibility bits buffer bytes", bits_bytes),
                ("rays backend a_i shares bytes", shares_bytes),
            ],
        )?;
        let (tree, stats) = RayTree::update(tree, device, queue, prepared, params.refit)?;
        let dirs: Vec<[f32; 4]> = directions
            .iter()
            .zip(solid_angles)
            .map(|(d, w)| [d.x, d.y, d.z, (w / std::f64::consts::PI) as f32])
            .collect();
        let storage = wgpu::BufferUsages::STORAGE;
        let origin_buffer = storage_init(
            device,
            "occlusion rays origins",
            bytemuck::cast_slice(&origins),
        );
        let order_buffer =
            storage_init(device, "occlusion rays rows", bytemuck::cast_slice(&order));
        let direction_buffer = storage_init(
            device,
            "occlusion rays directions",
            bytemuck::cast_slice(&dirs),
        );
        let zeroed = |label, size: u64, usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: size.max(4),
                usage,
                mapped_at_creation: false,
            })
        };
        let readable = storage | wgpu::BufferUsages::COPY_SRC;
        // Zero-initialised by wgpu: all occluded, a_i = 0.
        let bits = zeroed("occlusion bits", bits_bytes, readable);
        let ambient = zeroed("occlusion ambient", (rows * 4) as u64, readable);
        let shares = zeroed("occlusion rays shares", shares_bytes, storage);
        let params_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("occlusion rays params"),
            size: std::mem::size_of::<RayParams>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let group = layout::bind_group(
            device,
            "occlusion rays",
            &self.layout,
            &[
                params_buffer.as_entire_binding(),
                origin_buffer.as_entire_binding(),
                direction_buffer.as_entire_binding(),
                tree.node_buffer.as_entire_binding(),
                tree.triangle_buffer.as_entire_binding(),
                bits.as_entire_binding(),
                shares.as_entire_binding(),
                ambient.as_entire_binding(),
                order_buffer.as_entire_binding(),
            ],
        );
        let base = RayParams {
            rows: rows as u32,
            words_per_row: words_per_row as u32,
            first_word: call_first_word as u32,
            word_count: 0,
            first_direction: first as u32,
            k: k as u32,
            max_t: scaled_max_t(params.max_distance, scale).min(f32::MAX),
            node_count: tree.nodes.len() as u32,
            call_first_word: call_first_word as u32,
            call_word_count: call_word_count as u32,
            _pad: [0; 2],
        };
        // One compute pass of `pipeline` over `invocations`, submitted on its own.
        let dispatch = |pipeline: &wgpu::ComputePipeline, label, invocations| {
            let mut encoder = device
                .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(label) });
            {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some(label),
                    timestamp_writes: None,
                });
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, &group, &[]);
                let (x, y) = workgroups(invocations);
                pass.dispatch_workgroups(x, y, 1);
            }
            queue.submit([encoder.finish()]);
        };
        // Each submission takes whole words of every row; its own copy of the parameters
        // (a uniform rewritten between submissions is read by the later one only).
        let words_per_submission = (CELLS_PER_SUBMISSION / rows.max(1)).max(1);
        let mut word = call_first_word;
        while word < words_per_row {
            let count = words_per_submission.min(words_per_row - word);
            let batch = RayParams {
                first_word: word as u32,
                word_count: count as u32,
                ..base
            };
            queue.write_buffer(&params_buffer, 0, bytemuck::bytes_of(&batch));
            dispatch(&self.trace, "occlusion rays", rows * count);
            let done = std::sync::Arc::clone(ticker);
            let columns =
                (((word + count) * WORD_BITS).min(k) - (word * WORD_BITS).max(first)) as u64;
            let cells = rows as u64 * columns;
            queue.on_submitted_work_done(move || done.tick(cells));
            // A failed non-blocking poll leaves the callbacks to the read-back's wait.
            let _ = device.poll(wgpu::PollType::Poll);
            word += count;
        }
        queue.write_buffer(&params_buffer, 0, bytemuck::bytes_of(&base));
        dispatch(&self.sum_rows, "occlusion rays: a_i", rows);
        let run = DepthRun {
            bits,
            ambient,
            rows,
            words_per_row,
            zero_normals: prepared
                .receivers
                .iter()
                .map(|r| r.normal == Vec3::ZERO)
                .collect(),
        };
        Ok((run, stats))
    }
}

/// The most nodes on a root-to-leaf path of a tree whose inner nodes' children sit at
/// `first_index` and `first_index + 1` (0 for an empty tree) — what the shader's stack must
/// hold, less one.
fn tree_depth(nodes: &[obvhs::bvh2::node::Bvh2Node]) -> usize {
    if nodes.is_empty() {
        return 0;
    }
    let mut deepest = 0;
    let mut stack = vec![(0usize, 1usize)];
    while let Some((index, depth)) = stack.pop() {
        let node = &nodes[index];
        deepest = deepest.max(depth);
        if node.prim_count == 0 {
            let first = node.first_index as usize;
            stack.extend([(first, depth + 1), (first + 1, depth + 1)]);
        }
    }
    deepest
}

#[cfg(test)]
mod tests {
    use super::*;
    use obvhs::bvh2::node::Bvh2Node;

    fn node(first_index: u32, prim_count: u32) -> Bvh2Node {
        Bvh2Node {
            prim_count,
            first_index,
            ..Bvh2Node::default()
        }
    }

    #[test]
    fn tree_depth_counts_the_nodes_of_the_longest_path() {
        assert_eq!(tree_depth(&[]), 0);
        assert_eq!(tree_depth(&[node(0, 3)]), 1);
        // Root → (leaf, inner → (leaf, leaf)): three nodes on the longest path, whichever
        // side it is on.
        let right_heavy = [node(1, 0), node(0, 2), node(3, 0), node(2, 1), node(3, 1)];
        assert_eq!(tree_depth(&right_heavy), 3);
        let left_heavy = [node(1, 0), node(3, 0), node(0, 2), node(2, 1), node(3, 1)];
        assert_eq!(tree_depth(&left_heavy), 3);
        // A chain of 100 inner nodes: node 2i is inner, its children 2i + 1 (a leaf) and
        // 2i + 2 (the next inner node, or the last leaf).
        let chain: Vec<Bvh2Node> = (0..=200u32)
            .map(|at| {
                if at % 2 == 0 && at < 200 {
                    node(at + 1, 0)
                } else {
                    node(0, 1)
                }
            })
            .collect();
        assert_eq!(tree_depth(&chain), 101);
    }
}
