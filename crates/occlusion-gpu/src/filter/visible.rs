//! Which triangles the camera sees: the input of the "todo" list T of paper 000 §4.1.
//!
//! > "In order to compute list T, we perform an algorithm similar to the one in Section 3,
//! > except that here we render triangles in the second pass and use perspective projection.
//! > More precisely, in the first pass, we render the unlit mesh into the depth buffer as seen
//! > from the new camera position. In the second pass, we render only the triangles still in
//! > list U, each with its own occlusion query."
//!
//! Deviation: instead of one occlusion query per triangle still in U, one pass renders every
//! triangle's id into an R32Uint target with a depth test ([`TriangleIdRenderer`],
//! `shaders/triangle_ids.wgsl`); after read-back, a triangle is visible iff it covers at least
//! one pixel centre. This is one draw instead of |U| queries, and exact at pixel granularity
//! (an occlusion query with polygon offset also counts pixels that tie in depth). A triangle
//! smaller than a pixel that covers no pixel centre is not visible, so it is neither computed
//! nor drawn at that resolution. Both faces are rasterised (cloth is seen from both sides).
//! [`visible_triangles_cpu`] is the CPU reference (and the path without an adapter): the same
//! pixel-centre sampling with an inclusive edge rule instead of the GPU's top-left rule, so the
//! two may differ on triangles that only touch pixel centres with an edge.

use glam::{DMat4, DVec3, Mat4, Vec3, Vec4};
use wgpu::util::DeviceExt;

use crate::scene::Prepared;
use crate::{OcclusionError, Scene};

const ID_SHADER: &str = include_str!("triangle_ids.wgsl");
/// Near plane of [`Camera::look_at`] as a fraction of the eye–target distance.
const LOOK_AT_NEAR_RELATIVE: f32 = 1e-3;

/// A perspective camera: the clip space of the render target (wgpu conventions: y up, depth
/// 0..1) from the [`Scene`]'s world space, and the target's size in pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Clip space from the scene's world space.
    pub clip_from_world: Mat4,
    /// Target width in pixels.
    pub width: u32,
    /// Target height in pixels.
    pub height: u32,
}

impl Camera {
    /// A camera from a projection-view matrix and a target size.
    ///
    /// # Errors
    /// [`OcclusionError::InvalidParameter`] for a zero size or a non-finite matrix.
    pub fn new(clip_from_world: Mat4, width: u32, height: u32) -> Result<Self, OcclusionError> {
        if let Some(&value) = clip_from_world
            .to_cols_array()
            .iter()
            .find(|c| !c.is_finite())
        {
            return Err(invalid(
                "camera clip_from_world entry",
                value.into(),
                "finite",
            ));
        }
        for (what, value) in [("camera width", width), ("camera height", height)] {
            if value == 0 {
                return Err(invalid(what, value.into(), "at least 1 pixel"));
            }
        }
        Ok(Self {
            clip_from_world,
            width,
            height,
        })
    }

    /// A right-handed perspective camera at `eye` looking at `target` with vertical field of
    /// view `fov_y_radians` and an infinite far plane (the near plane is 10⁻³ × the eye–target
    /// distance).
    ///
    /// # Errors
    /// As [`Camera::new`], and [`OcclusionError::InvalidParameter`] when `eye == target` or the
    /// field of view is outside (0, π).
    pub fn look_at(
        eye: Vec3,
        target: Vec3,
        up: Vec3,
        fov_y_radians: f32,
        width: u32,
        height: u32,
    ) -> Result<Self, OcclusionError> {
        let distance = eye.distance(target);
        if !(distance > 0.0 && distance.is_finite()) {
            return Err(invalid("eye–target distance", distance.into(), "positive"));
        }
        if !(fov_y_radians > 0.0 && fov_y_radians < std::f32::consts::PI) {
            return Err(invalid("fov_y_radians", fov_y_radians.into(), "in (0, π)"));
        }
        let aspect = width.max(1) as f32 / height.max(1) as f32;
        // wgpu clip space: y up, depth 0..1, the DirectX convention.
        let clip_from_view = glam::camera::rh::proj::directx::perspective_infinite(
            fov_y_radians,
            aspect,
            LOOK_AT_NEAR_RELATIVE * distance,
        );
        let view_from_world = glam::camera::rh::view::look_at_mat4(eye, target, up);
        Self::new(clip_from_view * view_from_world, width, height)
    }

    /// Clip space from the prepared (centred) frame: world = centred + centre.
    fn clip_from_centred(&self, center: DVec3) -> Mat4 {
        (self.clip_from_world.as_dmat4() * DMat4::from_translation(center)).as_mat4()
    }
}

pub(crate) fn invalid(what: &'static str, value: f64, expected: &'static str) -> OcclusionError {
    OcclusionError::InvalidParameter {
        what,
        value,
        expected,
    }
}

/// A set of triangles (global indices over the scene's objects in order), as a bitset.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TriangleSet {
    len: usize,
    words: Vec<u64>,
}

impl TriangleSet {
    /// The empty set over `len` triangles.
    pub fn empty(len: usize) -> Self {
        Self {
            len,
            words: vec![0; len.div_ceil(64)],
        }
    }

    /// The set of all `len` triangles.
    pub fn full(len: usize) -> Self {
        let mut set = Self::empty(len);
        set.words.fill(u64::MAX);
        set.trim();
        set
    }

    /// The set of the given triangles.
    ///
    /// # Errors
    /// [`OcclusionError::SizeMismatch`] when an index is ≥ `len`.
    pub fn from_indices(len: usize, indices: &[u32]) -> Result<Self, OcclusionError> {
        let mut set = Self::empty(len);
        for &i in indices {
            if i as usize >= len {
                return Err(OcclusionError::SizeMismatch {
                    what: "triangle index",
                    given: i as usize,
                    expected: len,
                });
            }
            set.insert(i as usize);
        }
        Ok(set)
    }

    /// Number of triangles the set ranges over (not the number in the set: see
    /// [`TriangleSet::count`]).
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the set ranges over no triangles at all.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Number of triangles in the set.
    pub fn count(&self) -> usize {
        self.words.iter().map(|w| w.count_ones() as usize).sum()
    }

    /// Whether triangle `i` is in the set (false out of range).
    pub fn contains(&self, i: usize) -> bool {
        i < self.len && self.words[i / 64] >> (i % 64) & 1 == 1
    }

    /// Adds triangle `i`.
    ///
    /// # Panics
    /// When `i >= len()`.
    pub fn insert(&mut self, i: usize) {
        assert!(i < self.len, "triangle {i} out of range {}", self.len);
        self.words[i / 64] |= 1 << (i % 64);
    }

    /// The triangles in the set, ascending.
    pub fn iter(&self) -> impl Iterator<Item = usize> + '_ {
        self.words.iter().enumerate().flat_map(|(w, &word)| {
            let mut word = word;
            std::iter::from_fn(move || {
                if word == 0 {
                    return None;
                }
                let bit = word.trailing_zeros() as usize;
                word &= word - 1;
                Some(w * 64 + bit)
            })
        })
    }

    /// Keeps only the triangles also in `other` (same `len`).
    pub(crate) fn intersect_with(&mut self, other: &Self) {
        for (a, b) in self.words.iter_mut().zip(&other.words) {
            *a &= b;
        }
    }

    /// Removes the triangles of `other` (same `len`).
    pub(crate) fn subtract(&mut self, other: &Self) {
        for (a, b) in self.words.iter_mut().zip(&other.words) {
            *a &= !b;
        }
    }

    /// Removes every triangle.
    pub(crate) fn clear(&mut self) {
        self.words.fill(0);
    }

    fn trim(&mut self) {
        let rem = self.len % 64;
        if rem != 0
            && let Some(last) = self.words.last_mut()
        {
            *last &= (1u64 << rem) - 1;
        }
    }
}

/// The scene in the centred frame and the camera's clip matrix for it; `None` when the scene
/// has no triangles (nothing can be visible).
fn prepare(scene: &Scene, camera: &Camera) -> Result<Option<(Prepared, Mat4)>, OcclusionError> {
    Camera::new(camera.clip_from_world, camera.width, camera.height)?;
    if scene.triangle_count() == 0 {
        return Ok(None);
    }
    let prepared = Prepared::new(scene)?;
    let clip = camera.clip_from_centred(prepared.center);
    Ok(Some((prepared, clip)))
}

/// The triangles that cover at least one pixel centre of `camera`'s target after the depth
/// test, rasterised on the CPU (the reference of [`TriangleIdRenderer`]; see the module docs).
///
/// # Errors
/// An invalid camera ([`OcclusionError::InvalidParameter`]) or scene (as
/// [`crate::VisibilityEngine::compute`]).
pub fn visible_triangles_cpu(
    scene: &Scene,
    camera: &Camera,
) -> Result<TriangleSet, OcclusionError> {
    let total = scene.triangle_count();
    let Some((prepared, clip_from_centred)) = prepare(scene, camera)? else {
        return Ok(TriangleSet::empty(total));
    };
    let clip: Vec<Vec4> = prepared
        .positions
        .iter()
        .map(|p| clip_from_centred * p.extend(1.0))
        .collect();
    let (w, h) = (camera.width as usize, camera.height as usize);
    let mut depth = vec![1.0f32; w * h];
    let mut ids = vec![0u32; w * h];
    for (t, tri) in prepared.triangles.iter().enumerate() {
        let polygon = clip_polygon(tri.map(|i| clip[i as usize]));
        // Screen space: pixel (x, y) has its centre at (x + 0.5, y + 0.5), y down.
        let screen: Vec<DVec3> = polygon
            .iter()
            .map(|c| {
                let ndc = c.truncate().as_dvec3() / f64::from(c.w);
                DVec3::new(
                    (ndc.x + 1.0) * 0.5 * w as f64,
                    (1.0 - ndc.y) * 0.5 * h as f64,
                    ndc.z,
                )
            })
            .collect();
        for k in 1..screen.len().saturating_sub(1) {
            raster_triangle(
                [screen[0], screen[k], screen[k + 1]],
                (w, h),
                t as u32 + 1,
                &mut depth,
                &mut ids,
            );
        }
    }
    let mut set = TriangleSet::empty(total);
    for &id in ids.iter().filter(|&&id| id != 0) {
        set.insert(id as usize - 1);
    }
    Ok(set)
}

/// Clips a clip-space triangle to 0 ≤ z ≤ w (near and far planes; x and y are clipped by the
/// pixel loop), returning a convex polygon (empty when fully outside).
fn clip_polygon(triangle: [Vec4; 3]) -> Vec<Vec4> {
    let mut polygon = triangle.to_vec();
    let planes: [fn(Vec4) -> f32; 2] = [|c| c.z, |c| c.w - c.z];
    for plane in planes {
        let mut out = Vec::with_capacity(polygon.len() + 1);
        for (i, &a) in polygon.iter().enumerate() {
            let b = polygon[(i + 1) % polygon.len()];
            let (da, db) = (plane(a), plane(b));
            if da >= 0.0 {
                out.push(a);
            }
            if (da >= 0.0) != (db >= 0.0) {
                out.push(a + (b - a) * (da / (da - db)));
            }
        }
        polygon = out;
        if polygon.is_empty() {
            break;
        }
    }
    polygon
}

/// Rasterises one screen-space triangle (x, y pixels; z NDC depth) at pixel centres with an
/// inclusive edge rule and a `Less` depth test.
fn raster_triangle(
    v: [DVec3; 3],
    (w, h): (usize, usize),
    id: u32,
    depth: &mut [f32],
    ids: &mut [u32],
) {
    let edge =
        |a: DVec3, b: DVec3, x: f64, y: f64| (b.x - a.x) * (y - a.y) - (b.y - a.y) * (x - a.x);
    let area = edge(v[0], v[1], v[2].x, v[2].y);
    if area == 0.0 || !area.is_finite() {
        return;
    }
    let lo = v[0].min(v[1]).min(v[2]);
    let hi = v[0].max(v[1]).max(v[2]);
    let x0 = (lo.x - 0.5).ceil().max(0.0) as usize;
    let y0 = (lo.y - 0.5).ceil().max(0.0) as usize;
    let x1 = ((hi.x - 0.5).floor()).min(w as f64 - 1.0);
    let y1 = ((hi.y - 0.5).floor()).min(h as f64 - 1.0);
    if x1 < 0.0 || y1 < 0.0 {
        return;
    }
    for y in y0..=y1 as usize {
        let py = y as f64 + 0.5;
        for x in x0..=x1 as usize {
            let px = x as f64 + 0.5;
            let b0 = edge(v[1], v[2], px, py) / area;
            let b1 = edge(v[2], v[0], px, py) / area;
            let b2 = edge(v[0], v[1], px, py) / area;
            if b0 < 0.0 || b1 < 0.0 || b2 < 0.0 {
                continue;
            }
            let z = (b0 * v[0].z + b1 * v[1].z + b2 * v[2].z) as f32;
            let pixel = y * w + x;
            if z < depth[pixel] {
                depth[pixel] = z;
                ids[pixel] = id;
            }
        }
    }
}

/// Render target of one size: triangle ids, depth, and a buffer for the read-back copy.
struct IdTarget {
    width: u32,
    height: u32,
    ids: wgpu::Texture,
    depth: wgpu::Texture,
    readback: wgpu::Buffer,
    padded_row_bytes: u32,
}

/// The GPU triangle-id pass (see the module docs): one draw of all triangles into an R32Uint
/// target with a depth test, then a read-back of the ids.
pub struct TriangleIdRenderer {
    device: wgpu::Device,
    queue: wgpu::Queue,
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    target: Option<IdTarget>,
}

impl TriangleIdRenderer {
    /// Builds the pipeline on `device` (cloned handles are kept).
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("triangle_ids.wgsl"),
            source: wgpu::ShaderSource::Wgsl(ID_SHADER.into()),
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("triangle ids"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("triangle ids"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("triangle ids"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
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
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: wgpu::TextureFormat::R32Uint,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        Self {
            device: device.clone(),
            queue: queue.clone(),
            pipeline,
            layout,
            target: None,
        }
    }

    /// The triangles that cover at least one pixel of `camera`'s target after the depth test.
    ///
    /// # Errors
    /// An invalid camera or scene, a target larger than the device allows or a vertex buffer
    /// larger than its maximum ([`OcclusionError::GpuLimit`]), read-back failures.
    pub fn visible_triangles(
        &mut self,
        scene: &Scene,
        camera: &Camera,
    ) -> Result<TriangleSet, OcclusionError> {
        let total = scene.triangle_count();
        let Some((prepared, clip_from_centred)) = prepare(scene, camera)? else {
            return Ok(TriangleSet::empty(total));
        };
        let limits = self.device.limits();
        let max_side = limits.max_texture_dimension_2d;
        for (what, value) in [
            ("camera width", camera.width),
            ("camera height", camera.height),
        ] {
            if value > max_side {
                return Err(OcclusionError::GpuLimit {
                    what,
                    value: value.into(),
                    maximum: max_side.into(),
                });
            }
        }
        let expanded: Vec<Vec3> = prepared
            .triangles
            .iter()
            .flat_map(|t| t.map(|i| prepared.positions[i as usize]))
            .collect();
        let vertex_bytes = (expanded.len() * 12) as u64;
        if vertex_bytes > limits.max_buffer_size {
            return Err(OcclusionError::GpuLimit {
                what: "triangle-id vertex buffer bytes",
                value: vertex_bytes,
                maximum: limits.max_buffer_size,
            });
        }
        self.ensure_target(camera.width, camera.height);
        let Some(target) = &self.target else {
            unreachable!("the target was just built");
        };
        let device = &self.device;
        let vertices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("triangle id vertices"),
            contents: bytemuck::cast_slice(&expanded),
            usage: wgpu::BufferUsages::VERTEX,
        });
        let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("triangle id camera"),
            contents: bytemuck::cast_slice(&clip_from_centred.to_cols_array()),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("triangle ids"),
            layout: &self.layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: uniform.as_entire_binding(),
            }],
        });
        let id_view = target.ids.create_view(&Default::default());
        let depth_view = target.depth.create_view(&Default::default());
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("triangle ids"),
        });
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("triangle ids"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &id_view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &depth_view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Discard,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &bind_group, &[]);
            pass.set_vertex_buffer(0, vertices.slice(..));
            pass.draw(0..expanded.len() as u32, 0..1);
        }
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture: &target.ids,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &target.readback,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(target.padded_row_bytes),
                    rows_per_image: Some(target.height),
                },
            },
            wgpu::Extent3d {
                width: target.width,
                height: target.height,
                depth_or_array_layers: 1,
            },
        );
        self.queue.submit([encoder.finish()]);
        let size = u64::from(target.padded_row_bytes) * u64::from(target.height);
        let bytes = gpu_context::read_buffer(device, &self.queue, &target.readback, size)
            .map_err(|e| OcclusionError::Readback(e.to_string()))?;
        let words: Vec<u32> = bytemuck::pod_collect_to_vec(&bytes);
        let mut set = TriangleSet::empty(total);
        let row_words = (target.padded_row_bytes / 4) as usize;
        for row in words.chunks_exact(row_words) {
            for &id in &row[..target.width as usize] {
                if id != 0 && (id as usize) <= total {
                    set.insert(id as usize - 1);
                }
            }
        }
        Ok(set)
    }

    /// Builds the cached target of this size unless it exists.
    fn ensure_target(&mut self, width: u32, height: u32) {
        if self
            .target
            .as_ref()
            .is_none_or(|t| t.width != width || t.height != height)
        {
            let size = wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            };
            let texture = |label, format, usage| {
                self.device.create_texture(&wgpu::TextureDescriptor {
                    label: Some(label),
                    size,
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format,
                    usage,
                    view_formats: &[],
                })
            };
            let ids = texture(
                "triangle ids",
                wgpu::TextureFormat::R32Uint,
                wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            );
            let depth = texture(
                "triangle id depth",
                wgpu::TextureFormat::Depth32Float,
                wgpu::TextureUsages::RENDER_ATTACHMENT,
            );
            let align = wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
            let padded_row_bytes = (width * 4).div_ceil(align) * align;
            let readback = self.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("triangle id copy"),
                size: u64::from(padded_row_bytes) * u64::from(height),
                usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            self.target = Some(IdTarget {
                width,
                height,
                ids,
                depth,
                readback,
                padded_row_bytes,
            });
        }
    }
}

/// Where the visible triangles come from: the GPU id pass or the CPU rasteriser.
pub enum TriangleVisibility {
    /// [`TriangleIdRenderer`] on a wgpu device (boxed: it is much larger than `Cpu`).
    Gpu(Box<TriangleIdRenderer>),
    /// [`visible_triangles_cpu`] (no adapter needed).
    Cpu,
}

impl TriangleVisibility {
    /// The GPU id pass on `device` ([`TriangleIdRenderer::new`]).
    pub fn gpu(device: &wgpu::Device, queue: &wgpu::Queue) -> Self {
        Self::Gpu(Box::new(TriangleIdRenderer::new(device, queue)))
    }

    /// The triangles `camera` sees in `scene`.
    ///
    /// # Errors
    /// As [`TriangleIdRenderer::visible_triangles`] or [`visible_triangles_cpu`].
    pub fn visible(
        &mut self,
        scene: &Scene,
        camera: &Camera,
    ) -> Result<TriangleSet, OcclusionError> {
        match self {
            Self::Gpu(renderer) => renderer.visible_triangles(scene, camera),
            Self::Cpu => visible_triangles_cpu(scene, camera),
        }
    }
}
