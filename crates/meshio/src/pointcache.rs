//! Point caches: PC2 (3ds Max, Blender, Maya exporters) and MDD (LightWave, Blender, Houdini)
//! — per-frame vertex positions without connectivity, read as animations and written from
//! them. Triangles come from [`AnimationOptions::topology`] (`--topology MESH`), as for
//! `.npy`.
//!
//! **PC2**, little-endian: `"POINTCACHE2\0"` (12 bytes), `i32` version (1), `i32` points P,
//! `f32` start frame, `f32` sample rate (frames between samples), `i32` samples S, then
//! S × P × 3 `f32`.
//!
//! **MDD**, big-endian: `i32` frames F, `i32` points P, F × `f32` times (seconds), then
//! F × P × 3 `f32`. Blender's exporter writes one extra block of P positions (its rest pose)
//! before the frames; such a file (exactly one block longer) is read with that block skipped
//! and a note in the report.
//!
//! Both headers are checked against the file's length before anything is allocated: a count
//! the bytes cannot hold is an error naming it.
//!
//! ```
//! use glam::Vec3;
//! let dir = tempfile::tempdir().unwrap();
//! let frames = vec![vec![Vec3::ZERO, Vec3::X], vec![Vec3::Y, Vec3::Z]];
//! let path = dir.path().join("clip.pc2");
//! meshio::write_pc2(&path, &frames, 0.0, 1.0).unwrap();
//! let (clip, _) = meshio::load_animation(&path, &meshio::AnimationOptions::default()).unwrap();
//! assert_eq!(clip.frames, frames);
//! ```

use std::io::Write as _;
use std::path::Path;

use glam::Vec3;

use crate::npy::attach_topology;
use crate::validate::finish_animation;
use crate::{Animation, AnimationOptions, LoadReport, MeshIoError, SourceFormat};

/// The PC2 signature.
const PC2_MAGIC: &[u8; 12] = b"POINTCACHE2\0";
/// PC2 header bytes.
const PC2_HEADER: u64 = 32;

fn header_error(path: &Path, message: impl Into<String>) -> MeshIoError {
    MeshIoError::InvalidHeader {
        path: path.to_path_buf(),
        line: None,
        message: message.into(),
    }
}

fn i32_at(bytes: &[u8], at: usize, big_endian: bool) -> i32 {
    let b: [u8; 4] = bytes[at..at + 4].try_into().expect("4 bytes");
    if big_endian {
        i32::from_be_bytes(b)
    } else {
        i32::from_le_bytes(b)
    }
}

fn f32_at(bytes: &[u8], at: usize, big_endian: bool) -> f32 {
    f32::from_bits(i32_at(bytes, at, big_endian) as u32)
}

/// A count from a header: positive, else an error naming `what`.
fn count(path: &Path, what: &str, value: i32) -> Result<u64, MeshIoError> {
    if value <= 0 {
        return Err(header_error(
            path,
            format!("{what} = {value}; a point cache needs at least one frame of one point"),
        ));
    }
    Ok(value as u64)
}

/// `frames` × `points` positions of 3 f32 starting at `offset`, in the file's byte order.
fn positions(
    bytes: &[u8],
    offset: usize,
    frames: usize,
    points: usize,
    big_endian: bool,
) -> Vec<Vec<Vec3>> {
    (0..frames)
        .map(|f| {
            let base = offset + 12 * points * f;
            (0..points)
                .map(|m| {
                    let at = base + 12 * m;
                    Vec3::new(
                        f32_at(bytes, at, big_endian),
                        f32_at(bytes, at + 4, big_endian),
                        f32_at(bytes, at + 8, big_endian),
                    )
                })
                .collect()
        })
        .collect()
}

/// Loads a `.pc2` point cache.
pub(crate) fn load_pc2(
    path: &Path,
    options: &AnimationOptions,
) -> Result<(Animation, LoadReport), MeshIoError> {
    options.validate(path)?;
    let bytes = input_guard::read_regular(path).map_err(|e| MeshIoError::io(path, "read", e))?;
    let len = bytes.len() as u64;
    if len < PC2_HEADER || &bytes[..12] != PC2_MAGIC {
        return Err(header_error(
            path,
            "not a PC2 point cache: it must start with \"POINTCACHE2\\0\" and a 32-byte header",
        ));
    }
    let version = i32_at(&bytes, 12, false);
    if version != 1 {
        return Err(header_error(
            path,
            format!("PC2 version {version}; only version 1 exists"),
        ));
    }
    let points = count(path, "points", i32_at(&bytes, 16, false))?;
    let (start, rate) = (f32_at(&bytes, 20, false), f32_at(&bytes, 24, false));
    let samples = count(path, "samples", i32_at(&bytes, 28, false))?;
    // i32 counts: the product fits in u128 (not always in u64).
    let needed = u128::from(PC2_HEADER) + 12 * u128::from(points) * u128::from(samples);
    let needed = u64::try_from(needed).unwrap_or(u64::MAX);
    if len < needed {
        return Err(MeshIoError::Truncated {
            path: path.to_path_buf(),
            element: format!("{samples} samples × {points} points"),
            offset: PC2_HEADER,
            bytes_needed: needed - PC2_HEADER,
            file_len: len,
        });
    }
    let mut report = LoadReport::new(path, SourceFormat::Pc2);
    if len > needed {
        report.notes.push(format!(
            "{} bytes after the last sample ignored",
            len - needed
        ));
    }
    report.notes.push(format!(
        "PC2: start frame {start}, sample rate {rate} (frames per sample); played at {} fps",
        options.frame_rate
    ));
    let (points, samples) = (points as usize, samples as usize);
    let (triangles, uvs) = attach_topology(path, options, points, &mut report)?;
    let frames = positions(&bytes, PC2_HEADER as usize, samples, points, false);
    let animation = Animation {
        triangles,
        frames,
        frame_rate: options.frame_rate,
        uvs,
    };
    finish_animation(path, animation, true, report)
}

/// Loads a `.mdd` point cache. The frame rate comes from the file's times when they step
/// evenly, else from `options`.
pub(crate) fn load_mdd(
    path: &Path,
    options: &AnimationOptions,
) -> Result<(Animation, LoadReport), MeshIoError> {
    options.validate(path)?;
    let bytes = input_guard::read_regular(path).map_err(|e| MeshIoError::io(path, "read", e))?;
    let len = bytes.len() as u64;
    if len < 8 {
        return Err(header_error(
            path,
            format!("{len} bytes; an MDD file starts with two big-endian i32 counts"),
        ));
    }
    let frames = count(path, "frames", i32_at(&bytes, 0, true))?;
    let points = count(path, "points", i32_at(&bytes, 4, true))?;
    let data = 8 + 4 * frames;
    let block = 12 * points;
    // i32 counts: the product fits in u128 (not always in u64).
    let needed = u64::try_from(u128::from(data) + u128::from(block) * u128::from(frames))
        .unwrap_or(u64::MAX);
    let mut report = LoadReport::new(path, SourceFormat::Mdd);
    // Blender's exporter writes its rest pose as one extra block before the frames.
    let skip = if len.checked_sub(block) == Some(needed) {
        report.notes.push(
            "one extra block of positions before the frames (Blender's rest pose) skipped".into(),
        );
        block
    } else if len < needed {
        return Err(MeshIoError::Truncated {
            path: path.to_path_buf(),
            element: format!("{frames} frames × {points} points"),
            offset: 8,
            bytes_needed: needed - 8,
            file_len: len,
        });
    } else {
        if len > needed {
            report.notes.push(format!(
                "{} bytes after the last frame ignored",
                len - needed
            ));
        }
        0
    };
    let (frames, points) = (frames as usize, points as usize);
    let times: Vec<f32> = (0..frames)
        .map(|f| f32_at(&bytes, 8 + 4 * f, true))
        .collect();
    let frame_rate = even_rate(&times).unwrap_or(options.frame_rate);
    report.notes.push(format!(
        "MDD: times {}…{} s; played at {frame_rate} fps",
        times[0],
        times[frames - 1]
    ));
    let (triangles, uvs) = attach_topology(path, options, points, &mut report)?;
    let animation = Animation {
        triangles,
        frames: positions(&bytes, (data + skip) as usize, frames, points, true),
        frame_rate,
        uvs,
    };
    finish_animation(path, animation, true, report)
}

/// 1/Δt when `times` step evenly (to 0.1 %) by a positive Δt, Δt taken over the whole
/// range; a rate within 10⁻⁴ of a whole number (f32 times f/30 give 29.999998) is that
/// number. `None` otherwise.
fn even_rate(times: &[f32]) -> Option<f32> {
    let first = f64::from(times[0]);
    let dt = (f64::from(*times.last()?) - first) / (times.len() - 1).max(1) as f64;
    let even = times.windows(2).all(|w| {
        let d = f64::from(w[1]) - f64::from(w[0]);
        (d - dt).abs() <= 1e-3 * dt
    });
    if !(times.len() > 1 && dt.is_finite() && dt > 0.0 && even) {
        return None;
    }
    let rate = 1.0 / dt;
    let whole = rate.round();
    Some(if (rate - whole).abs() <= 1e-4 * whole {
        whole
    } else {
        rate
    } as f32)
}

/// Checks a clip for writing: at least one frame of one vertex, every frame as long as the
/// first, counts within i32.
fn check_clip(path: &Path, frames: &[Vec<Vec3>]) -> Result<(i32, i32), MeshIoError> {
    let invalid = |message: String| MeshIoError::InvalidHeader {
        path: path.to_path_buf(),
        line: None,
        message,
    };
    let points = frames.first().map_or(0, Vec::len);
    if points == 0 {
        return Err(invalid(
            "nothing to write: no frames, or frames without vertices".into(),
        ));
    }
    if let Some((f, frame)) = frames.iter().enumerate().find(|(_, fr)| fr.len() != points) {
        return Err(invalid(format!(
            "frame {f} has {} vertices, frame 0 has {points}",
            frame.len()
        )));
    }
    let p = i32::try_from(points).map_err(|_| invalid(format!("{points} points exceed i32")))?;
    let n = i32::try_from(frames.len())
        .map_err(|_| invalid(format!("{} frames exceed i32", frames.len())))?;
    Ok((n, p))
}

/// Writes `frames` as a PC2 point cache (atomically: a temporary file renamed into place).
/// `start_frame` and `sample_rate` (frames per sample) go into the header.
///
/// # Errors
/// [`MeshIoError::InvalidHeader`] for an empty clip, frames of different lengths or counts
/// beyond i32; write errors naming `path`.
pub fn write_pc2(
    path: &Path,
    frames: &[Vec<Vec3>],
    start_frame: f32,
    sample_rate: f32,
) -> Result<(), MeshIoError> {
    let (n, p) = check_clip(path, frames)?;
    atomic_out::write_with(path, |w| {
        w.write_all(PC2_MAGIC)?;
        for v in [1, p] {
            w.write_all(&v.to_le_bytes())?;
        }
        w.write_all(&start_frame.to_le_bytes())?;
        w.write_all(&sample_rate.to_le_bytes())?;
        w.write_all(&n.to_le_bytes())?;
        for frame in frames {
            for c in frame.iter().flat_map(|v| v.to_array()) {
                w.write_all(&c.to_le_bytes())?;
            }
        }
        Ok(())
    })?;
    Ok(())
}

/// Writes `frames` as an MDD point cache (atomically), frame f at time f / `frame_rate`
/// seconds; F position blocks, without the extra rest-pose block Blender's exporter adds.
///
/// # Errors
/// As for [`write_pc2`], and [`MeshIoError::InvalidHeader`] for a frame rate that is not
/// finite and positive.
pub fn write_mdd(path: &Path, frames: &[Vec<Vec3>], frame_rate: f32) -> Result<(), MeshIoError> {
    let (n, p) = check_clip(path, frames)?;
    if !(frame_rate.is_finite() && frame_rate > 0.0) {
        return Err(MeshIoError::InvalidHeader {
            path: path.to_path_buf(),
            line: None,
            message: format!("frame rate {frame_rate} must be finite and > 0"),
        });
    }
    atomic_out::write_with(path, |w| {
        for v in [n, p] {
            w.write_all(&v.to_be_bytes())?;
        }
        for f in 0..frames.len() {
            w.write_all(&(f as f32 / frame_rate).to_be_bytes())?;
        }
        for frame in frames {
            for c in frame.iter().flat_map(|v| v.to_array()) {
                w.write_all(&c.to_be_bytes())?;
            }
        }
        Ok(())
    })?;
    Ok(())
}
