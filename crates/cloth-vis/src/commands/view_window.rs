//! The window of `cloth-vis view`: winit's event loop, a wgpu surface the live scene's HDR
//! frame is tone-mapped into (render's [`ToneMapPass`], the GPU twin of the PNG path), and an
//! egui overlay (controls and per-stage times) drawn over it.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::Context as _;
use cloth_vis::Effect;
use cloth_vis::live::{LiveScene, Orbit, ViewEvent};
use gpu_context::{GpuContext, GpuOptions};
use occlusion_gpu::{LevelController, LevelParams};
use render::{ToneMapPass, output};
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

use super::view::{MotionSource, ViewRequest};
use super::view_hud::{FrameStats, Hud, UiRequests};
use super::view_motion::{CpcaMotion, JumpMotion, Motion};

/// Degrees of orbit per pixel dragged.
const ORBIT_DEG_PER_PIXEL: f32 = 0.4;
/// Idle time before the level refines one step (adaptive mode).
const IDLE_REFINE_AFTER: Duration = Duration::from_millis(300);

/// Open the window and run until it closes (or the scripted frames are presented).
pub fn run(request: ViewRequest) -> anyhow::Result<()> {
    // The maps first: a bad file is named before the GPU and the scene are set up. (The
    // loader's errors name the file.)
    let environments = request
        .environments
        .iter()
        .map(|path| {
            Ok((
                path.display().to_string(),
                lightsphere::Environment::load(path)?,
            ))
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let gpu = GpuContext::new(&GpuOptions::default())
        .map_err(|e| anyhow::anyhow!("cloth-vis view renders on the GPU: {e}"))?;
    let mut live = LiveScene::new(request.scene.clone(), &gpu)?;
    for (name, env) in environments {
        live.add_environment(name, env);
    }
    let motion = match &request.motion {
        None => None,
        Some(MotionSource::JumpMap(cells, seed)) => {
            let step = super::spinner(true, "analysing the jump map".to_owned());
            let m = JumpMotion::new(cells.clone(), *seed)?;
            step.finish_and_clear();
            Some(Motion::JumpMap(Box::new(m)))
        }
        Some(MotionSource::Cpca(data)) => Some(Motion::Cpca(CpcaMotion::new(
            &gpu.device,
            &gpu.queue,
            data,
            0,
        )?)),
    };
    let event_loop = EventLoop::new().map_err(|e| {
        anyhow::anyhow!("cloth-vis view could not reach the display ({e}); is DISPLAY right?")
    })?;
    let mut app = App::new(request, gpu, live);
    app.motion = motion;
    event_loop.run_app(&mut app)?;
    if let Some(e) = app.failure.take() {
        return Err(e);
    }
    if let Some(line) = app.summary() {
        super::print_line(&line)?;
    }
    Ok(())
}

/// What the window holds once it exists.
struct Shown {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    view_format: wgpu::TextureFormat,
    tonemap: ToneMapPass,
    egui_ctx: egui::Context,
    egui_state: egui_winit::State,
    egui_renderer: egui_wgpu::Renderer,
}

struct App {
    request: ViewRequest,
    gpu: GpuContext,
    live: LiveScene,
    orbit: Orbit,
    shown: Option<Shown>,
    failure: Option<anyhow::Error>,
    presented: u64,
    playing: bool,
    overlay: bool,
    drag: Option<(MouseButton, (f64, f64))>,
    cursor: (f64, f64),
    last_input: Instant,
    frame_ms: f64,
    /// The last frame's time outside the stage timers.
    unstaged_ms: f64,
    stats: FrameStats,
    controller: Option<LevelController>,
    motion: Option<Motion>,
    screenshots: u32,
    status: String,
}

impl App {
    fn new(request: ViewRequest, gpu: GpuContext, live: LiveScene) -> Self {
        let orbit = Orbit::from_camera(&live.start_camera(), live.bounds());
        let controller = request.adaptive_ms.and_then(|ms| {
            let level = live.settings().level;
            let params =
                LevelParams::new(Duration::from_secs_f64(ms / 1e3)).with_levels(0, level, level);
            LevelController::new(params, level).ok()
        });
        let overlay = request.overlay;
        Self {
            request,
            gpu,
            live,
            orbit,
            shown: None,
            failure: None,
            presented: 0,
            playing: false,
            overlay,
            drag: None,
            cursor: (0.0, 0.0),
            last_input: Instant::now(),
            frame_ms: 0.0,
            unstaged_ms: 0.0,
            stats: FrameStats::default(),
            controller,
            motion: None,
            screenshots: 0,
            status: String::new(),
        }
    }

    fn fail(&mut self, event_loop: &ActiveEventLoop, e: anyhow::Error) {
        self.failure.get_or_insert(e);
        event_loop.exit();
    }

    /// The scripted run's line on stdout: frames, file and the final camera (each coordinate
    /// in full: six decimals printed a mesh 10⁻⁶ across as zeros).
    fn summary(&self) -> Option<String> {
        self.request.frames?;
        let (w, h) = self.size();
        let camera = self.orbit.camera(w, h);
        let e = camera.eye;
        let t = camera.target;
        let effects: Vec<String> = self
            .live
            .settings()
            .effects
            .iter()
            .map(|(e, on)| format!("{}={}", e.name(), if *on { "on" } else { "off" }))
            .collect();
        Some(format!(
            "view: {} frames presented ({w}×{h}); {}; level {}; {}{}; eye [{}, {}, {}] \
             target [{}, {}, {}]{}",
            self.presented,
            self.stats,
            self.live.settings().level,
            effects.join(" "),
            self.motion
                .as_ref()
                .map(|m| format!("; {}", m.status()))
                .unwrap_or_default(),
            e.x,
            e.y,
            e.z,
            t.x,
            t.y,
            t.z,
            self.request
                .screenshot
                .as_ref()
                .map(|p| format!("; wrote {}", p.display()))
                .unwrap_or_default()
        ))
    }

    fn size(&self) -> (u32, u32) {
        match &self.shown {
            Some(s) => (s.config.width, s.config.height),
            None => self.request.size,
        }
    }

    fn show(&mut self, event_loop: &ActiveEventLoop) -> anyhow::Result<Shown> {
        let (w, h) = self.request.size;
        let attributes = Window::default_attributes()
            .with_title(format!("cloth-vis — {}", self.live.scene().name))
            .with_inner_size(winit::dpi::PhysicalSize::new(w, h));
        let window = Arc::new(event_loop.create_window(attributes)?);
        let surface = self
            .gpu
            .instance
            .create_surface(window.clone())
            .context("creating the window's GPU surface")?;
        if !self.gpu.adapter.is_surface_supported(&surface) {
            anyhow::bail!(
                "the adapter {} cannot present to this window",
                self.gpu.summary()
            );
        }
        let caps = surface.get_capabilities(&self.gpu.adapter);
        // An 8-bit display format (a float one would be taken as linear HDR).
        let format = caps
            .formats
            .iter()
            .copied()
            .find(|f| {
                matches!(
                    f.remove_srgb_suffix(),
                    wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Rgba8Unorm
                )
            })
            .or_else(|| caps.formats.first().copied())
            .context("the surface offers no colour format")?;
        // The tone map encodes sRGB itself: draw through a non-sRGB view of the texture.
        let view_format = format.remove_srgb_suffix();
        let size = window.inner_size();
        let config = wgpu::SurfaceConfiguration {
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            format,
            width: size.width.max(1),
            height: size.height.max(1),
            present_mode: wgpu::PresentMode::AutoVsync,
            desired_maximum_frame_latency: 2,
            alpha_mode: caps
                .alpha_modes
                .first()
                .copied()
                .unwrap_or(wgpu::CompositeAlphaMode::Auto),
            view_formats: vec![view_format],
            color_space: wgpu::SurfaceColorSpace::Auto,
        };
        surface.configure(&self.gpu.device, &config);
        let tonemap = ToneMapPass::new(&self.gpu.device, view_format);
        let egui_ctx = egui::Context::default();
        let egui_state = egui_winit::State::new(
            egui_ctx.clone(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            None,
            Some(self.gpu.device.limits().max_texture_dimension_2d as usize),
        );
        let egui_renderer = egui_wgpu::Renderer::new(
            &self.gpu.device,
            view_format,
            egui_wgpu::RendererOptions::default(),
        );
        Ok(Shown {
            window,
            surface,
            config,
            view_format,
            tonemap,
            egui_ctx,
            egui_state,
            egui_renderer,
        })
    }

    /// One frame: scripted event, animation step, the scene, the tone map, the overlay,
    /// present; then the scripted screenshot and recording.
    fn redraw(&mut self, event_loop: &ActiveEventLoop) -> anyhow::Result<()> {
        let start = Instant::now();
        let index = self.presented as usize;
        if let Some(&event) = self.request.events.get(index) {
            self.apply(event)
                .map_err(|m| anyhow::anyhow!("event {} (`{event}`): {m}", index + 1))?;
        } else if self.playing {
            self.advance(1).map_err(|m| anyhow::anyhow!("{m}"))?;
        }
        let (w, h) = self.size();
        let camera = self.orbit.camera(w, h);
        if self.live.display().is_none() {
            // Automatic exposure is measured once, on the first frame (as a sequence does).
            self.live.capture(&self.gpu, &camera)?;
        } else {
            self.live.draw(&self.gpu, &camera)?;
        }
        self.adapt_level();
        let display = self
            .live
            .display()
            .context("the display mapping is fixed by the first frame")?;
        let Some(shown) = self.shown.as_mut() else {
            return Ok(());
        };
        let texture = match shown.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t)
            | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                shown.surface.configure(&self.gpu.device, &shown.config);
                shown.window.request_redraw();
                return Ok(());
            }
            _ => {
                shown.window.request_redraw();
                return Ok(());
            }
        };
        let view = texture.texture.create_view(&wgpu::TextureViewDescriptor {
            format: Some(shown.view_format),
            ..Default::default()
        });
        let hdr = self
            .live
            .renderer()
            .hdr_view()
            .context("the frame was drawn without a target")?;
        let group = shown.tonemap.bind(&self.gpu.device, hdr);
        let mut encoder = self
            .gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("view frame"),
            });
        shown.tonemap.record(
            &self.gpu.queue,
            &mut encoder,
            &group,
            &display,
            self.live.background(),
            &view,
        );
        // The overlay.
        let raw = shown.egui_state.take_egui_input(&shown.window);
        let mut requests = UiRequests::default();
        let overlay = self.overlay;
        let motion_status = self.motion.as_ref().map(Motion::status);
        let mut hud = Hud {
            motion: motion_status.as_deref(),
            live: &mut self.live,
            frame_ms: self.frame_ms,
            unstaged_ms: self.unstaged_ms,
            playing: &mut self.playing,
            adaptive: self.controller.is_some(),
            status: &self.status,
            requests: &mut requests,
        };
        let output = shown.egui_ctx.run_pass(raw, |ctx| {
            if overlay {
                hud.ui(ctx);
            }
        });
        shown
            .egui_state
            .handle_platform_output(&shown.window, output.platform_output);
        // egui lays a new window out over two passes and animates: repaint when it asks.
        if output
            .viewport_output
            .get(&egui::ViewportId::ROOT)
            .is_some_and(|v| v.repaint_delay.is_zero())
        {
            shown.window.request_redraw();
        }
        let jobs = shown
            .egui_ctx
            .tessellate(output.shapes, output.pixels_per_point);
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [shown.config.width, shown.config.height],
            pixels_per_point: output.pixels_per_point,
        };
        let mut textures = output.textures_delta;
        for (id, deltas) in &textures.set {
            for delta in deltas {
                shown
                    .egui_renderer
                    .update_texture(&self.gpu.device, &self.gpu.queue, *id, delta);
            }
        }
        let extra = shown.egui_renderer.update_buffers(
            &self.gpu.device,
            &self.gpu.queue,
            &mut encoder,
            &jobs,
            &screen,
        );
        {
            let pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("overlay"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &view,
                    resolve_target: None,
                    depth_slice: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Load,
                        store: wgpu::StoreOp::Store,
                    },
                })],
                ..Default::default()
            });
            shown
                .egui_renderer
                .render(&mut pass.forget_lifetime(), &jobs, &screen);
        }
        for id in &textures.free {
            shown.egui_renderer.free_texture(id);
        }
        textures.clear();
        self.gpu
            .queue
            .submit(extra.into_iter().chain([encoder.finish()]));
        shown.window.pre_present_notify();
        self.gpu.queue.present(texture);
        self.presented += 1;
        let ms = start.elapsed().as_secs_f64() * 1e3;
        // The viewer draws on demand, so the last frame's own time is what the HUD shows (an
        // average would carry the first frame's loading into every idle redraw); what the
        // stage timers do not see (GPU work they only submitted, the overlay, presenting) is
        // its own line.
        self.frame_ms = ms;
        let staged: f64 = self
            .live
            .times()
            .iter()
            .filter(|t| t.fresh)
            .map(|t| t.millis)
            .sum();
        self.unstaged_ms = (ms - staged).max(0.0);
        self.stats.add(ms, &self.live);

        if let Some(dir) = self.request.record.clone() {
            let path = dir.join(render::sequence::frame_file_name(
                "frame",
                self.presented as usize - 1,
                "png",
            ));
            self.write_image(&camera, &path)?;
        }
        if requests.screenshot {
            self.key_screenshot(&camera, "png")?;
        }
        if requests.home {
            self.orbit = Orbit::from_camera(&self.live.start_camera(), self.live.bounds());
        }
        if self.request.frames == Some(self.presented) {
            if let Some(path) = self.request.screenshot.clone() {
                self.write_image(&camera, &path)?;
            }
            event_loop.exit();
        }
        Ok(())
    }

    /// Write the frame through `camera` (at `--screenshot-size` when given), as `cloth-vis
    /// render` writes its still.
    fn write_image(&mut self, camera: &render::Camera, path: &Path) -> anyhow::Result<()> {
        let camera = match self.request.screenshot_size {
            Some((w, h)) => self.orbit.camera(w, h),
            None => *camera,
        };
        let image = self.live.capture(&self.gpu, &camera)?;
        let display = self.live.display().context("display mapping")?;
        let background = self.live.background();
        let is_exr = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
        if is_exr {
            output::write_exr(&image, path, background)?;
        } else {
            output::write_png(&image, path, &display, background)?;
        }
        Ok(())
    }

    /// Write the current view as `cloth-vis-NNNN.EXT` in the working folder (`png`: the
    /// display mapping; `exr`: linear radiance), at `--screenshot-size` or the window's.
    fn key_screenshot(&mut self, camera: &render::Camera, ext: &str) -> anyhow::Result<()> {
        let path = loop {
            self.screenshots += 1;
            let p = PathBuf::from(format!("cloth-vis-{:04}.{ext}", self.screenshots));
            if !p.exists() {
                break p;
            }
        };
        self.write_image(camera, &path)?;
        self.status = format!("wrote {}", path.display());
        Ok(())
    }

    /// A screenshot key: the file, or why not, in the overlay's status line.
    fn screenshot_key(&mut self, ext: &str) {
        let (w, h) = self.size();
        let camera = self.orbit.camera(w, h);
        if let Err(e) = self.key_screenshot(&camera, ext) {
            self.status = format!("screenshot failed: {e:#}");
        }
    }

    /// Adaptive level (paper 000 §4.2): while the animation plays, the controller fits the
    /// visibility time to the target; when idle, one level finer per quiet frame, the new
    /// directions only.
    fn adapt_level(&mut self) {
        let Some(controller) = self.controller.as_mut() else {
            return;
        };
        let visibility_ms: f64 = self
            .live
            .times()
            .iter()
            .filter(|t| t.stage == "visibility" && t.fresh)
            .map(|t| t.millis)
            .sum();
        let max = controller.params().max_idle_level;
        if self.playing {
            if visibility_ms > 0.0 {
                controller.record_frame(Duration::from_secs_f64(visibility_ms / 1e3));
            }
            self.live.settings_mut().level = controller.level();
        } else if self.last_input.elapsed() >= IDLE_REFINE_AFTER {
            let level = &mut self.live.settings_mut().level;
            if *level < max {
                *level += 1;
            }
        }
    }

    fn animating(&self) -> bool {
        self.playing
            || self.request.frames.is_some()
            || self.request.record.is_some()
            || self
                .controller
                .as_ref()
                .is_some_and(|c| self.live.settings().level < c.params().max_idle_level)
    }

    fn key(&mut self, key: &Key, event_loop: &ActiveEventLoop) {
        let effects: Vec<Effect> = self.live.effects().to_vec();
        let mut event = None;
        match key {
            Key::Named(NamedKey::Escape) => event_loop.exit(),
            Key::Named(NamedKey::Space) => {
                self.playing =
                    !self.playing && (self.live.frame_count() > 1 || self.motion.is_some());
            }
            Key::Named(NamedKey::ArrowRight) => {
                if let Err(m) = self.advance(1) {
                    self.status = m;
                }
            }
            Key::Named(NamedKey::ArrowLeft) => {
                if let Err(m) = self.advance(-1) {
                    self.status = m;
                }
            }
            Key::Named(NamedKey::F12) => self.screenshot_key("png"),
            Key::Character(c) => match c.as_str() {
                "q" => event_loop.exit(),
                "f" | "F" => event = Some(ViewEvent::Home),
                "h" | "H" => self.overlay = !self.overlay,
                "c" | "C" => event = Some(ViewEvent::NextCell),
                "t" | "T" => {
                    event = Some(ViewEvent::BtfPlain(!self.live.settings().btf_plain));
                }
                "p" | "P" => self.screenshot_key("png"),
                "e" | "E" => self.screenshot_key("exr"),
                "+" | "=" => {
                    event = Some(ViewEvent::Level((self.live.settings().level + 1).min(6)))
                }
                "-" => {
                    event = Some(ViewEvent::Level(
                        self.live.settings().level.saturating_sub(1),
                    ))
                }
                "[" => event = Some(ViewEvent::Exposure(Some(self.exposure() - 0.5))),
                "]" => event = Some(ViewEvent::Exposure(Some(self.exposure() + 0.5))),
                "," => {
                    event = Some(ViewEvent::Rotation(
                        self.live.settings().rotation_deg - 15.0,
                    ))
                }
                "." => {
                    event = Some(ViewEvent::Rotation(
                        self.live.settings().rotation_deg + 15.0,
                    ))
                }
                digit => {
                    if let Some(e) = digit
                        .parse::<usize>()
                        .ok()
                        .and_then(|d| d.checked_sub(1))
                        .and_then(|i| effects.get(i))
                    {
                        event = Some(ViewEvent::Toggle(*e));
                    }
                }
            },
            _ => {}
        }
        if let Some(event) = event
            && let Err(m) = self.apply(event)
        {
            self.status = m;
        }
    }

    /// Apply an input: the motion's own (play, pause, next cell, a `.cpca` frame) when a jump
    /// map or a `.cpca` drives the pose, else the live scene's.
    fn apply(&mut self, event: ViewEvent) -> Result<(), String> {
        match (&mut self.motion, event) {
            (Some(_), ViewEvent::Play) => self.playing = true,
            (Some(_), ViewEvent::Pause) => self.playing = false,
            (Some(Motion::JumpMap(j)), ViewEvent::NextCell) => {
                j.next_cell().map_err(|e| e.to_string())?;
            }
            (Some(Motion::Cpca(c)), ViewEvent::Frame(f)) => {
                let pose = c.seek(f).map_err(|e| e.to_string())?;
                self.live.set_pose(0, &pose)?;
            }
            _ => {
                let mut playing = self.playing;
                let result = self.live.apply(event, &mut self.orbit, &mut playing);
                self.playing = playing;
                result?;
            }
        }
        Ok(())
    }

    /// Advance the animation `by` frames: the motion's next pose, or the scene's clip.
    fn advance(&mut self, by: isize) -> Result<(), String> {
        let pose = match &mut self.motion {
            None => {
                self.live.step(by);
                return Ok(());
            }
            Some(Motion::Cpca(c)) => c.step(by),
            Some(m @ Motion::JumpMap(_)) => m.next(),
        };
        let pose = pose.map_err(|e| e.to_string())?;
        self.live.set_pose(0, &pose)
    }

    fn exposure(&self) -> f32 {
        self.live.display().map_or(0.0, |d| d.exposure_ev)
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.shown.is_some() {
            return;
        }
        match self.show(event_loop) {
            Ok(shown) => {
                shown.window.request_redraw();
                self.shown = Some(shown);
            }
            Err(e) => self.fail(event_loop, e),
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let Some(shown) = self.shown.as_mut() else {
            return;
        };
        let consumed = shown
            .egui_state
            .on_window_event(&shown.window, &event)
            .consumed;
        if consumed {
            shown.window.request_redraw();
        }
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => {
                shown.config.width = size.width.max(1);
                shown.config.height = size.height.max(1);
                shown.surface.configure(&self.gpu.device, &shown.config);
                shown.window.request_redraw();
            }
            WindowEvent::RedrawRequested => {
                if let Err(e) = self.redraw(event_loop) {
                    self.fail(event_loop, e);
                }
            }
            WindowEvent::CursorMoved { position, .. } => {
                let (x, y) = (position.x, position.y);
                if let Some((button, (px, py))) = self.drag {
                    let (dx, dy) = ((x - px) as f32, (y - py) as f32);
                    if button == MouseButton::Left {
                        self.orbit
                            .orbit(-dx * ORBIT_DEG_PER_PIXEL, dy * ORBIT_DEG_PER_PIXEL);
                    } else {
                        let h = shown.config.height.max(1) as f32;
                        self.orbit.pan(dx / h, -dy / h);
                    }
                    self.drag = Some((button, (x, y)));
                    self.last_input = Instant::now();
                    shown.window.request_redraw();
                }
                self.cursor = (x, y);
            }
            WindowEvent::MouseInput { state, button, .. } if !consumed => {
                self.drag = (state == ElementState::Pressed).then_some((button, self.cursor));
            }
            WindowEvent::MouseWheel { delta, .. } if !consumed => {
                let lines = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                };
                self.orbit.zoom(0.9f32.powf(lines));
                self.last_input = Instant::now();
                shown.window.request_redraw();
            }
            WindowEvent::KeyboardInput { event, .. }
                if !consumed && event.state == ElementState::Pressed =>
            {
                self.key(&event.logical_key, event_loop);
                self.last_input = Instant::now();
                if let Some(s) = &self.shown {
                    s.window.request_redraw();
                }
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        if self.animating() {
            event_loop.set_control_flow(ControlFlow::Poll);
            if let Some(s) = &self.shown {
                s.window.request_redraw();
            }
        } else {
            event_loop.set_control_flow(ControlFlow::Wait);
        }
    }
}
