//! Scripted viewer input (`cloth-vis view --events FILE`): one event per line, replayed one per
//! presented frame — what the viewer's tests drive it with, and what a pipeline uses to turn a
//! scene and take pictures without a person at the mouse.
//!
//! ```text
//! # comments and blank lines are skipped
//! orbit 90 0          # yaw and pitch in degrees
//! pan 0.1 0           # fractions of the view's height
//! zoom 0.8            # distance × 0.8
//! home                # back to the scene's camera
//! toggle self-shadowing
//! off shadow-volumes
//! on shadow-volumes
//! level 2             # lightsphere level
//! rotation 45         # environment turn in degrees
//! light 0 3 2         # the first point light of shadow volumes / translucency, moved
//! backend depth 512   # M by GPU depth maps of side 512 (auto, cpu, depth, query, rays)
//! exposure -1         # EV; `exposure auto` returns to the scene's
//! tone clamp          # tone curve: aces, clamp (γ 2.2), srgb
//! environment 1       # 0: the scene's map, then each `--env` map
//! frame 30            # animation frame
//! btf-plain on        # the btf effect's objects under plain texture mapping (off: the BTF)
//! play
//! pause
//! next-cell           # a jump map (`view CLIP --jumpmap`): steer to the next cell
//! ```

use std::path::Path;

use crate::Error;
use crate::effects::Effect;

/// The most events a file may hold (a replay presents one frame per event).
pub const MAX_EVENTS: usize = 100_000;

/// One scripted input.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ViewEvent {
    /// Turn the camera: yaw and pitch in degrees ([`super::Orbit::orbit`]).
    Orbit(f32, f32),
    /// Pan by fractions of the view's height ([`super::Orbit::pan`]).
    Pan(f32, f32),
    /// Multiply the eye's distance to the target (> 0).
    Zoom(f32),
    /// Back to the scene's camera.
    Home,
    /// Flip an effect.
    Toggle(Effect),
    /// Switch an effect on (`true`) or off.
    Set(Effect, bool),
    /// The lightsphere level.
    Level(u32),
    /// The environment's turn in degrees.
    Rotation(f32),
    /// Choose environment N (0: the scene's own, then each `--env` map).
    Environment(usize),
    /// Replace the scene's tone curve.
    Tone(render::tone::ToneCurve),
    /// Move the scene's first point light here (world units).
    PointLight(glam::Vec3),
    /// The visibility backend, and the depth-map side for `depth`.
    Backend(crate::scene::VisibilityBackendDesc, Option<u32>),
    /// Fixed exposure in EV; `None`: the scene's.
    Exposure(Option<f32>),
    /// Pose the animation at this frame.
    Frame(usize),
    /// Draw the `btf` effect's objects under plain texture mapping (`true`) or the BTF.
    BtfPlain(bool),
    /// Play the animation (one animation frame per presented frame).
    Play,
    /// Jump map: steer to the next cell (motion control).
    NextCell,
    /// Pause it.
    Pause,
}

/// The event as a line of an events file: `parse_events` reads it back as the same event
/// (a clamp curve as `tone clamp`, the only gamma a file can name).
impl std::fmt::Display for ViewEvent {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        use crate::scene::VisibilityBackendDesc as B;
        use render::tone::ToneCurve;
        match *self {
            Self::Orbit(yaw, pitch) => write!(f, "orbit {yaw} {pitch}"),
            Self::Pan(x, y) => write!(f, "pan {x} {y}"),
            Self::Zoom(factor) => write!(f, "zoom {factor}"),
            Self::Home => f.write_str("home"),
            Self::Toggle(effect) => write!(f, "toggle {effect}"),
            Self::Set(effect, on) => write!(f, "{} {effect}", if on { "on" } else { "off" }),
            Self::Level(level) => write!(f, "level {level}"),
            Self::Rotation(degrees) => write!(f, "rotation {degrees}"),
            Self::Environment(i) => write!(f, "environment {i}"),
            Self::Tone(curve) => f.write_str(match curve {
                ToneCurve::AcesFitted => "tone aces",
                ToneCurve::Clamp { .. } => "tone clamp",
                ToneCurve::ClampSrgb => "tone srgb",
            }),
            Self::PointLight(p) => write!(f, "light {} {} {}", p.x, p.y, p.z),
            Self::Backend(backend, side) => {
                let name = match backend {
                    B::Auto => "auto",
                    B::Cpu => "cpu",
                    B::Depth => "depth",
                    B::Query => "query",
                    B::Rays => "rays",
                };
                match side {
                    Some(side) => write!(f, "backend {name} {side}"),
                    None => write!(f, "backend {name}"),
                }
            }
            Self::Exposure(Some(ev)) => write!(f, "exposure {ev}"),
            Self::Exposure(None) => f.write_str("exposure auto"),
            Self::Frame(frame) => write!(f, "frame {frame}"),
            Self::BtfPlain(on) => write!(f, "btf-plain {}", if on { "on" } else { "off" }),
            Self::Play => f.write_str("play"),
            Self::NextCell => f.write_str("next-cell"),
            Self::Pause => f.write_str("pause"),
        }
    }
}

/// Read and parse an events file (a regular file, at most [`MAX_EVENTS`] events).
///
/// # Errors
/// [`Error::Io`] when the file cannot be read; [`Error::Request`] naming the file, the line
/// and the value for a line that does not parse.
pub fn read_events(path: &Path) -> Result<Vec<ViewEvent>, Error> {
    let text = input_guard::read_regular_to_string(path).map_err(|e| Error::Io {
        path: path.to_owned(),
        reason: e.to_string(),
    })?;
    parse_events(&text).map_err(|message| Error::Request {
        path: path.to_owned(),
        message,
    })
}

/// Parse events, one per line (see the module docs).
///
/// # Errors
/// A message naming the line, its text and what was expected.
pub fn parse_events(text: &str) -> Result<Vec<ViewEvent>, String> {
    let mut events = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        if events.len() == MAX_EVENTS {
            return Err(format!("more than {MAX_EVENTS} events"));
        }
        let event = parse_line(line).map_err(|m| format!("line {}: `{line}`: {m}", i + 1))?;
        events.push(event);
    }
    Ok(events)
}

fn parse_line(line: &str) -> Result<ViewEvent, String> {
    let words: Vec<&str> = line.split_whitespace().collect();
    let args = &words[1..];
    let count = |n: usize, what: &str| {
        if args.len() == n {
            Ok(())
        } else {
            Err(format!("takes {what}"))
        }
    };
    let number = |s: &str| -> Result<f32, String> {
        s.parse::<f32>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("{s:?} is not a finite number"))
    };
    let effect = |s: &str| -> Result<Effect, String> {
        s.parse::<Effect>().map_err(|_| {
            format!(
                "unknown effect {s:?} (known: {})",
                crate::effects::known_effect_names()
            )
        })
    };
    match words[0] {
        "orbit" => {
            count(2, "two numbers: yaw and pitch in degrees")?;
            Ok(ViewEvent::Orbit(number(args[0])?, number(args[1])?))
        }
        "pan" => {
            count(2, "two numbers: fractions of the view's height")?;
            Ok(ViewEvent::Pan(number(args[0])?, number(args[1])?))
        }
        "zoom" => {
            count(1, "one factor > 0")?;
            let f = number(args[0])?;
            if f <= 0.0 {
                return Err(format!("{f} is not > 0"));
            }
            Ok(ViewEvent::Zoom(f))
        }
        "home" => count(0, "nothing").map(|()| ViewEvent::Home),
        "toggle" => {
            count(1, "an effect name")?;
            Ok(ViewEvent::Toggle(effect(args[0])?))
        }
        "on" | "off" => {
            count(1, "an effect name")?;
            Ok(ViewEvent::Set(effect(args[0])?, words[0] == "on"))
        }
        "level" => {
            count(1, "a lightsphere level")?;
            let level = args[0]
                .parse::<u32>()
                .ok()
                .filter(|&l| l <= lightsphere::MAX_LEVEL)
                .ok_or_else(|| {
                    format!(
                        "{:?} is not a level 0..={}",
                        args[0],
                        lightsphere::MAX_LEVEL
                    )
                })?;
            Ok(ViewEvent::Level(level))
        }
        "backend" => {
            use crate::scene::VisibilityBackendDesc as B;
            if !(1..=2).contains(&args.len()) {
                return Err(
                    "takes a backend (auto, cpu, depth, query, rays) and for depth a map side"
                        .to_owned(),
                );
            }
            let backend = match args[0] {
                "auto" => B::Auto,
                "cpu" => B::Cpu,
                "depth" => B::Depth,
                "query" => B::Query,
                "rays" => B::Rays,
                other => return Err(format!("{other:?} is not auto, cpu, depth, query or rays")),
            };
            let side = match args.get(1) {
                None => None,
                Some(v) => Some(
                    v.parse::<u32>()
                        .ok()
                        .filter(|n| (1..=16384).contains(n))
                        .ok_or_else(|| format!("{v:?} is not a depth-map side 1..=16384"))?,
                ),
            };
            Ok(ViewEvent::Backend(backend, side))
        }
        "light" => {
            count(3, "three numbers: the point light's position")?;
            Ok(ViewEvent::PointLight(glam::Vec3::new(
                number(args[0])?,
                number(args[1])?,
                number(args[2])?,
            )))
        }
        "environment" => {
            count(1, "an environment index (0: the scene's)")?;
            let i = args[0]
                .parse::<usize>()
                .map_err(|_| format!("{:?} is not an environment index", args[0]))?;
            Ok(ViewEvent::Environment(i))
        }
        "tone" => {
            use render::tone::ToneCurve;
            count(1, "aces, clamp (γ 2.2) or srgb")?;
            match args[0] {
                "aces" => Ok(ViewEvent::Tone(ToneCurve::AcesFitted)),
                "clamp" => Ok(ViewEvent::Tone(ToneCurve::Clamp { gamma: 2.2 })),
                "srgb" => Ok(ViewEvent::Tone(ToneCurve::ClampSrgb)),
                other => Err(format!("{other:?} is not aces, clamp or srgb")),
            }
        }
        "rotation" => {
            count(1, "degrees")?;
            Ok(ViewEvent::Rotation(number(args[0])?))
        }
        "exposure" => {
            count(1, "EV, or auto")?;
            if args[0] == "auto" {
                Ok(ViewEvent::Exposure(None))
            } else {
                Ok(ViewEvent::Exposure(Some(number(args[0])?)))
            }
        }
        "frame" => {
            count(1, "a frame index")?;
            let f = args[0]
                .parse::<usize>()
                .map_err(|_| format!("{:?} is not a frame index", args[0]))?;
            Ok(ViewEvent::Frame(f))
        }
        "btf-plain" => {
            count(1, "on or off")?;
            match args[0] {
                "on" => Ok(ViewEvent::BtfPlain(true)),
                "off" => Ok(ViewEvent::BtfPlain(false)),
                other => Err(format!("{other:?} is not on or off")),
            }
        }
        "play" => count(0, "nothing").map(|()| ViewEvent::Play),
        "next-cell" => count(0, "nothing").map(|()| ViewEvent::NextCell),
        "pause" => count(0, "nothing").map(|()| ViewEvent::Pause),
        other => Err(format!(
            "unknown event {other:?} (orbit, pan, zoom, home, toggle, on, off, level, light, backend, rotation, environment, tone, \
             exposure, frame, btf-plain, play, pause, next-cell)"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_event_parses_and_comments_are_skipped() {
        let text = "# a replay\norbit 90 -10\npan 0.1 0\nzoom 0.5\nhome\n\ntoggle self-shadowing\n\
                    off shadow-volumes  # trailing\non btf\nlevel 2\nrotation 45\nexposure -1\n\
                    exposure auto\nframe 7\nbtf-plain on\nplay\npause\nnext-cell\n\
                    light 0 3 -2.5\nbackend depth 512\nbackend cpu\nenvironment 2\ntone srgb\n";
        let events = parse_events(text).unwrap();
        assert_eq!(
            events,
            vec![
                ViewEvent::Orbit(90.0, -10.0),
                ViewEvent::Pan(0.1, 0.0),
                ViewEvent::Zoom(0.5),
                ViewEvent::Home,
                ViewEvent::Toggle(Effect::SelfShadowing),
                ViewEvent::Set(Effect::ShadowVolumes, false),
                ViewEvent::Set(Effect::Btf, true),
                ViewEvent::Level(2),
                ViewEvent::Rotation(45.0),
                ViewEvent::Exposure(Some(-1.0)),
                ViewEvent::Exposure(None),
                ViewEvent::Frame(7),
                ViewEvent::BtfPlain(true),
                ViewEvent::Play,
                ViewEvent::Pause,
                ViewEvent::NextCell,
                ViewEvent::PointLight(glam::Vec3::new(0.0, 3.0, -2.5)),
                ViewEvent::Backend(crate::scene::VisibilityBackendDesc::Depth, Some(512)),
                ViewEvent::Backend(crate::scene::VisibilityBackendDesc::Cpu, None),
                ViewEvent::Environment(2),
                ViewEvent::Tone(render::tone::ToneCurve::ClampSrgb),
            ]
        );
    }

    /// Every event prints as the line that parses back to it (the viewer's errors quote
    /// events this way).
    #[test]
    fn every_event_prints_as_its_line() {
        let text = "orbit 90.5 -10\npan 0.1 0\nzoom 0.5\nhome\ntoggle self-shadowing\n\
                    off shadow-volumes\non btf\nlevel 2\nrotation 45\nexposure -1.25\n\
                    exposure auto\nframe 7\nbtf-plain on\nbtf-plain off\nplay\npause\n\
                    next-cell\nlight 0 3 -2.5\nbackend depth 512\nbackend cpu\nbackend auto\n\
                    backend query\nbackend rays\nenvironment 2\ntone srgb\ntone aces\ntone clamp\n";
        let events = parse_events(text).unwrap();
        let printed: Vec<String> = events.iter().map(ToString::to_string).collect();
        assert_eq!(printed, text.lines().collect::<Vec<_>>());
        assert_eq!(parse_events(&printed.join("\n")).unwrap(), events);
    }

    #[test]
    fn bad_lines_name_the_line_and_the_value() {
        for (text, needle) in [
            ("orbit 10", "line 1: `orbit 10`: takes two numbers"),
            ("\nzoom -2", "line 2: `zoom -2`: -2 is not > 0"),
            ("orbit NaN 0", "\"NaN\" is not a finite number"),
            ("toggle sparkle", "unknown effect \"sparkle\""),
            ("level 99", "\"99\" is not a level 0..=8"),
            ("jump", "unknown event \"jump\""),
            ("frame -1", "\"-1\" is not a frame index"),
            ("light 1 2", "takes three numbers"),
            (
                "backend gpu",
                "\"gpu\" is not auto, cpu, depth, query or rays",
            ),
            ("backend depth 0", "\"0\" is not a depth-map side"),
        ] {
            let e = parse_events(text).unwrap_err();
            assert!(e.contains(needle), "{text:?}: {e}");
        }
    }
}
