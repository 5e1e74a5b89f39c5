//! The renderer: one frame, passes recorded into it in a fixed order, pipelines built once.
//!
//! [`Renderer::new`] builds everything that does not change between frames — the view
//! uniform and its layout, the Gouraud and backdrop pipelines — as wgpu's `framework.rs`
//! does in `init`. [`Renderer::render`] only writes the view uniform, records the passes and
//! reads the resolved colour back; the target is reallocated only when the image size
//! changes. Effect passes are built once against [`Renderer::pass_context`] and handed to
//! every `render` call.

use bytemuck::{Pod, Zeroable};
use gpu_context::layout::{bind_group, bind_group_layout, binding};
use gpu_context::{GpuError, HdrImage, read_hdr_image};
use wgpu::util::DeviceExt;

use crate::RenderError;
use crate::backdrop::BackdropPass;
use crate::camera::Camera;
use crate::gouraud::GouraudPass;
use crate::output::Background;
use crate::target::{FrameFormat, FrameTarget};
use crate::tone::Display;
use crate::tonemap::{DISPLAY_FORMAT, ToneMapPass};

/// When a pass records, relative to the others.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Phase {
    /// Writes depth (and colour): Gouraud meshes first, then these in the order given.
    Opaque,
    /// Reads the depth (and stencil) the opaque passes left: shadow volumes, translucency.
    DepthReading,
    /// Blends over everything else, the backdrop included, testing depth without writing it:
    /// BTF fins (thesis §5.7.3), whose passes must be order-independent among themselves.
    Blended,
}

/// What an effect implements to join the frame.
///
/// Build the pipelines once against [`Renderer::pass_context`] (group 0 of the pipeline
/// layout is [`PassContext::view_layout`]; colour, depth-stencil format and sample count come
/// from [`PassContext::format`]). Per frame, prepare the pass's buffers, then hand it to
/// [`Renderer::render`], which binds the view at group 0 and calls [`FramePass::record`] in
/// [`Phase`] order. A pass must leave group 0 alone.
pub trait FramePass {
    /// When the pass records.
    fn phase(&self) -> Phase;
    /// Record draws into the frame's render pass.
    fn record(&self, pass: &mut wgpu::RenderPass<'_>);
}

/// What a pass's pipelines must be built against.
#[derive(Clone, Copy, Debug)]
pub struct PassContext<'a> {
    /// Formats, samples and depth convention of the frame.
    pub format: FrameFormat,
    /// Layout of group 0, the view (`view.wgsl`, [`crate::VIEW_SHADER`]).
    pub view_layout: &'a wgpu::BindGroupLayout,
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct ViewUniform {
    clip_from_world: [[f32; 4]; 4],
    world_from_clip: [[f32; 4]; 4],
    eye: [f32; 4],
    viewport: [f32; 4],
}

/// The long-lived renderer: the frame format, the view binding, the built-in passes and the
/// target of the last size.
#[derive(Debug)]
pub struct Renderer {
    format: FrameFormat,
    view_layout: wgpu::BindGroupLayout,
    view_buffer: wgpu::Buffer,
    view_group: wgpu::BindGroup,
    target: Option<FrameTarget>,
    /// The tone-map binding of the current target's HDR colour.
    tone_group: Option<wgpu::BindGroup>,
    frames: u64,
    /// The GPU tone map into [`DISPLAY_FORMAT`] (the last pass, [`Renderer::render_display`]).
    pub tonemap: ToneMapPass,
    /// The Gouraud meshes (opaque, recorded first).
    pub gouraud: GouraudPass,
    /// The environment backdrop (recorded after every depth-reading pass).
    pub backdrop: BackdropPass,
}

impl Renderer {
    /// Build the view binding and the built-in pipelines for `format`.
    pub fn new(device: &wgpu::Device, format: FrameFormat) -> Self {
        let view_layout = bind_group_layout(
            device,
            "view",
            wgpu::ShaderStages::VERTEX_FRAGMENT,
            &[binding::uniform()],
        );
        let view_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("view uniform"),
            contents: bytemuck::bytes_of(&ViewUniform::zeroed()),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        });
        let view_group = bind_group(
            device,
            "view",
            &view_layout,
            &[view_buffer.as_entire_binding()],
        );
        let ctx = PassContext {
            format,
            view_layout: &view_layout,
        };
        let gouraud = GouraudPass::new(device, &ctx);
        let backdrop = BackdropPass::new(device, &ctx);
        let tonemap = ToneMapPass::new(device, DISPLAY_FORMAT);
        Self {
            format,
            view_layout,
            view_buffer,
            view_group,
            target: None,
            tone_group: None,
            frames: 0,
            tonemap,
            gouraud,
            backdrop,
        }
    }

    /// The frame's formats.
    pub fn format(&self) -> FrameFormat {
        self.format
    }

    /// What effect passes build their pipelines against.
    pub fn pass_context(&self) -> PassContext<'_> {
        PassContext {
            format: self.format,
            view_layout: &self.view_layout,
        }
    }

    /// Frames rendered so far.
    pub fn frames_rendered(&self) -> u64 {
        self.frames
    }

    /// Render one frame seen by `camera` and read it back as linear HDR RGBA.
    ///
    /// Order: clear (colour to the background's colour with alpha 0, depth to the far value,
    /// stencil to 0) → Gouraud meshes → `passes` of [`Phase::Opaque`] → `passes` of
    /// [`Phase::DepthReading`] → the backdrop (only with [`Background::Environment`]) →
    /// `passes` of [`Phase::Blended`] → MSAA resolve → read-back. The tone map is the caller's choice: on the read-back image
    /// ([`crate::output`], so the EXR keeps linear radiance and automatic exposure can read
    /// the objects' pixels), or on the GPU with [`Renderer::render_display`]. Alpha is the
    /// objects' coverage (a fraction of the samples at edges); background pixels have alpha 0.
    ///
    /// # Errors
    /// [`RenderError::Camera`] for a camera that makes no image; [`RenderError::Gpu`] when
    /// the size exceeds the device or the read-back fails.
    pub fn render(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        camera: &Camera,
        background: Background,
        passes: &[&dyn FramePass],
    ) -> Result<HdrImage, RenderError> {
        self.draw(device, queue, camera, background, passes)?;
        let target = self.current_target()?;
        Ok(read_hdr_image(device, queue, &target.resolved)?)
    }

    /// Render one frame as [`Renderer::render`] does, then tone-map it on the GPU with
    /// `display` (the frame's last pass, [`ToneMapPass`]) and read back 8-bit RGBA, row-major,
    /// top row first — what [`crate::output::to_rgba8`] makes of the HDR read-back, within
    /// one code, without moving 16 bytes per pixel.
    ///
    /// # Errors
    /// As [`Renderer::render`].
    pub fn render_display(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        camera: &Camera,
        background: Background,
        passes: &[&dyn FramePass],
        display: &Display,
    ) -> Result<Vec<u8>, RenderError> {
        self.draw(device, queue, camera, background, passes)?;
        let target = self.current_target()?;
        let group = self.tone_group.as_ref().ok_or_else(|| {
            RenderError::Gpu(GpuError::Readback("tone-map binding missing".to_owned()))
        })?;
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("tone map"),
        });
        self.tonemap.record(
            queue,
            &mut encoder,
            group,
            display,
            background,
            &target.display_view,
        );
        queue.submit([encoder.finish()]);
        Ok(gpu_context::read_texture(
            device,
            queue,
            &target.display,
            4,
            wgpu::TextureAspect::All,
        )?)
    }

    /// Render one frame as [`Renderer::render`] does and leave it on the GPU, read back
    /// nothing: [`Renderer::hdr_view`] then holds its resolved HDR colour, for a viewer's own
    /// [`ToneMapPass`] into a window surface.
    ///
    /// # Errors
    /// As [`Renderer::render`].
    pub fn draw_frame(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        camera: &Camera,
        background: Background,
        passes: &[&dyn FramePass],
    ) -> Result<(), RenderError> {
        self.draw(device, queue, camera, background, passes)
    }

    /// The resolved HDR colour of the last frame drawn (single-sample `Rgba32Float`, bindable
    /// as a texture): what a viewer hands to its own [`ToneMapPass`] for a surface format.
    pub fn hdr_view(&self) -> Option<&wgpu::TextureView> {
        self.target.as_ref().map(|t| &t.resolved_view)
    }

    fn current_target(&self) -> Result<&FrameTarget, RenderError> {
        self.target
            .as_ref()
            .ok_or_else(|| RenderError::Gpu(GpuError::Readback("frame target missing".to_owned())))
    }

    /// Record and submit one frame into the target (reallocated when the size changes).
    fn draw(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        camera: &Camera,
        background: Background,
        passes: &[&dyn FramePass],
    ) -> Result<(), RenderError> {
        let clip_from_world = camera.clip_from_world_with(self.format.depth)?;
        let uniform = ViewUniform {
            clip_from_world: clip_from_world.to_cols_array_2d(),
            world_from_clip: clip_from_world.inverse().to_cols_array_2d(),
            eye: camera.eye.extend(1.0).to_array(),
            viewport: [
                camera.width as f32,
                camera.height as f32,
                self.format.depth.clear_depth(),
                0.0,
            ],
        };
        queue.write_buffer(&self.view_buffer, 0, bytemuck::bytes_of(&uniform));
        if self
            .target
            .as_ref()
            .is_none_or(|t| t.width != camera.width || t.height != camera.height)
        {
            let target = FrameTarget::new(device, &self.format, camera.width, camera.height)?;
            self.tone_group = Some(self.tonemap.bind(device, &target.resolved_view));
            self.target = Some(target);
        }
        let target = self.target.as_ref().ok_or_else(|| {
            RenderError::Gpu(GpuError::Readback("frame target missing".to_owned()))
        })?;
        let clear = match background {
            Background::Color(c) => wgpu::Color {
                r: f64::from(c[0]),
                g: f64::from(c[1]),
                b: f64::from(c[2]),
                a: 0.0,
            },
            Background::Transparent | Background::Environment => wgpu::Color::TRANSPARENT,
        };
        let (view, resolve_target) = match &target.msaa_color {
            Some(msaa) => (msaa, Some(&target.resolved_view)),
            None => (&target.resolved_view, None),
        };
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("frame"),
        });
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("frame"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view,
                    depth_slice: None,
                    resolve_target,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(clear),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &target.depth_view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(self.format.depth.clear_depth()),
                        store: wgpu::StoreOp::Discard,
                    }),
                    stencil_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(0),
                        store: wgpu::StoreOp::Discard,
                    }),
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_bind_group(0, &self.view_group, &[]);
            self.gouraud.record(&mut pass);
            for phase in [Phase::Opaque, Phase::DepthReading] {
                for p in passes.iter().filter(|p| p.phase() == phase) {
                    p.record(&mut pass);
                    // A pass must leave group 0 alone; rebind in case one did not.
                    pass.set_bind_group(0, &self.view_group, &[]);
                }
            }
            if background == Background::Environment {
                self.backdrop.record(&mut pass);
            }
            for p in passes.iter().filter(|p| p.phase() == Phase::Blended) {
                p.record(&mut pass);
                pass.set_bind_group(0, &self.view_group, &[]);
            }
        }
        queue.submit([encoder.finish()]);
        self.frames += 1;
        Ok(())
    }
}
