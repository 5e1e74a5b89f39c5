//! The overlay of `cloth-vis view` (egui): per-stage times, effect toggles, level, backend,
//! environment, tone curve, exposure, point light, animation; and the scripted run's frame
//! statistics.

use cloth_vis::Effect;
use cloth_vis::live::LiveScene;

/// Frame times over a run (the scripted summary's report).
#[derive(Default)]
pub(super) struct FrameStats {
    frames: usize,
    total_ms: f64,
    max_ms: f64,
    visibility: (usize, f64),
    levels: Option<(u32, u32)>,
}

impl FrameStats {
    pub(super) fn add(&mut self, ms: f64, live: &LiveScene) {
        self.frames += 1;
        self.total_ms += ms;
        self.max_ms = self.max_ms.max(ms);
        for t in live.times() {
            if t.fresh && t.stage == "visibility" {
                self.visibility.0 += 1;
                self.visibility.1 += t.millis;
            }
        }
        let l = live.settings().level;
        self.levels = Some(self.levels.map_or((l, l), |(a, b)| (a.min(l), b.max(l))));
    }
}

impl std::fmt::Display for FrameStats {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let n = self.frames.max(1) as f64;
        write!(
            f,
            "frame {:.1} ms mean, {:.1} ms max",
            self.total_ms / n,
            self.max_ms
        )?;
        if self.visibility.0 > 0 {
            write!(
                f,
                ", visibility {:.1} ms mean over {} recomputations",
                self.visibility.1 / self.visibility.0 as f64,
                self.visibility.0
            )?;
        }
        if let Some((lo, hi)) = self.levels
            && lo != hi
        {
            write!(f, ", levels {lo}..={hi}")?;
        }
        Ok(())
    }
}

/// What the overlay asked for this frame.
#[derive(Default)]
pub(super) struct UiRequests {
    pub(super) screenshot: bool,
    pub(super) home: bool,
}

/// The overlay's view of the state.
pub(super) struct Hud<'a> {
    pub(super) motion: Option<&'a str>,
    pub(super) live: &'a mut LiveScene,
    pub(super) frame_ms: f64,
    pub(super) unstaged_ms: f64,
    pub(super) playing: &'a mut bool,
    pub(super) adaptive: bool,
    pub(super) status: &'a str,
    pub(super) requests: &'a mut UiRequests,
}

/// The overlay's level slider reaches this (k = 4,098 directions).
const MAX_UI_LEVEL: u32 = 5;

impl Hud<'_> {
    /// The overlay: timings, effect toggles, level, environment, exposure, animation.
    pub(super) fn ui(&mut self, ctx: &egui::Context) {
        let mono = |s: String| egui::RichText::new(s).monospace();
        egui::Window::new("cloth-vis")
            .default_pos([8.0, 8.0])
            .resizable(false)
            .show(ctx, |ui| {
                let fps = if self.frame_ms > 0.0 { 1e3 / self.frame_ms } else { 0.0 };
                ui.label(mono(format!("{:7.1} ms/frame {fps:6.1} fps", self.frame_ms)))
                    .on_hover_text("the last presented frame (the viewer draws on demand)");
                ui.label(mono(format!("{:<18}{:8.2} ms", "GPU + present", self.unstaged_ms)))
                    .on_hover_text(
                        "the last frame's time outside the stage timers: GPU work the stages \
                         only submitted (the BTF's per-pixel reconstruction, shading), the \
                         overlay and presenting",
                    );
                for t in self.live.times() {
                    let line = format!("{:<18}{:8.2} ms", t.stage, t.millis);
                    if t.fresh {
                        ui.label(mono(line));
                    } else {
                        ui.label(mono(line).weak())
                            .on_hover_text("not recomputed for this frame: its result is reused");
                    }
                }
                ui.separator();
                let mut settings = self.live.settings().clone();
                for (i, (effect, on)) in settings.effects.iter_mut().enumerate() {
                    let label = format!("{} {}", i + 1, effect.name());
                    ui.checkbox(on, label);
                    if *effect == Effect::Btf && *on {
                        ui.checkbox(&mut settings.btf_plain, "   plain texture (T), Fig. 5.16")
                            .on_hover_text(
                                "the BTF's objects under plain texture mapping (its frontal \
                                 normtexture) instead of the BTF",
                            );
                    }
                }
                if self.live.has_lights() {
                    let top = MAX_UI_LEVEL.max(settings.level);
                    let k = lightsphere::direction_count(settings.level);
                    ui.add(
                        egui::Slider::new(&mut settings.level, 0..=top)
                            .text(format!("level (k = {k})")),
                    );
                    if self.adaptive {
                        ui.label("adaptive level: on");
                    }
                    if settings.is_on(Effect::SelfShadowing) {
                        use cloth_vis::scene::VisibilityBackendDesc as B;
                        ui.horizontal(|ui| {
                            ui.label("M by");
                            let backends = [
                                (B::Auto, "auto"),
                                (B::Cpu, "cpu"),
                                (B::Depth, "depth"),
                                (B::Query, "query"),
                                (B::Rays, "rays"),
                            ];
                            for (b, name) in backends {
                                ui.radio_value(&mut settings.backend, b, name);
                            }
                        });
                        if settings.backend == B::Depth {
                            ui.add(
                                egui::Slider::new(&mut settings.depth_resolution, 16..=2048)
                                    .logarithmic(true)
                                    .text("depth map side"),
                            );
                        }
                    }
                    ui.add(
                        egui::Slider::new(&mut settings.rotation_deg, -180.0..=180.0)
                            .text("environment turn (°)"),
                    );
                }
                if let Some(p) = settings.point_light.as_mut() {
                    ui.horizontal(|ui| {
                        ui.label("point light");
                        let step = 0.01 * render::usable_radius(self.live.bounds().1);
                        for v in [&mut p.x, &mut p.y, &mut p.z] {
                            ui.add(egui::DragValue::new(v).speed(step));
                        }
                    });
                }
                let names = self.live.environment_names();
                if names.len() > 1 {
                    egui::ComboBox::from_label("environment")
                        .selected_text(names[settings.environment.min(names.len() - 1)])
                        .show_ui(ui, |ui| {
                            for (i, name) in names.iter().enumerate() {
                                ui.selectable_value(&mut settings.environment, i, *name);
                            }
                        });
                }
                {
                    use render::tone::ToneCurve as T;
                    let current = settings
                        .tone
                        .or_else(|| self.live.display().map(|d| d.curve))
                        .unwrap_or_default();
                    let name = |c: T| match c {
                        T::AcesFitted => "ACES filmic",
                        T::Clamp { .. } => "clamp, γ",
                        T::ClampSrgb => "clamp, sRGB",
                    };
                    egui::ComboBox::from_label("tone curve")
                        .selected_text(name(current))
                        .show_ui(ui, |ui| {
                            for c in [T::AcesFitted, T::Clamp { gamma: 2.2 }, T::ClampSrgb] {
                                if ui.selectable_label(current == c, name(c)).clicked() {
                                    settings.tone = Some(c);
                                }
                            }
                        });
                }
                let mut ev = settings
                    .exposure_ev
                    .or_else(|| self.live.display().map(|d| d.exposure_ev))
                    .unwrap_or(0.0);
                if ui
                    .add(egui::Slider::new(&mut ev, -10.0..=10.0).text("exposure (EV)"))
                    .changed()
                {
                    settings.exposure_ev = Some(ev);
                }
                let frames = self.live.frame_count();
                if let Some(status) = self.motion {
                    ui.horizontal(|ui| {
                        let label = if *self.playing { "pause" } else { "play" };
                        if ui.button(label).clicked() {
                            *self.playing = !*self.playing;
                        }
                        ui.label(status);
                    });
                } else if frames > 1 {
                    ui.horizontal(|ui| {
                        let label = if *self.playing { "pause" } else { "play" };
                        if ui.button(label).clicked() {
                            *self.playing = !*self.playing;
                        }
                        ui.add(egui::Slider::new(&mut settings.frame, 0..=frames - 1).text("frame"));
                    });
                }
                ui.horizontal(|ui| {
                    if ui.button("frame object (F)").clicked() {
                        self.requests.home = true;
                    }
                    if ui.button("screenshot (P)").clicked() {
                        self.requests.screenshot = true;
                    }
                });
                if !self.status.is_empty() {
                    ui.label(self.status);
                }
                ui.collapsing("keys", |ui| {
                    ui.label(
                        "drag: orbit · right/middle drag: pan · wheel: zoom · F: frame object\n\
                         1–9: toggle effect · T: BTF / plain texture · +/−: level · [ ]: exposure · , .: turn environment\n\
                         space: play/pause · ← →: step · P/F12: PNG screenshot · E: EXR (linear) · H: overlay · Q/Esc: quit",
                    );
                });
                if settings != *self.live.settings() {
                    *self.live.settings_mut() = settings;
                }
            });
    }
}
