//! Streamed `.glb` animation output: frames come one at a time from a callback (a decoder, a
//! generator), so writing a clip needs memory for two frames, not F of them. Every size of the
//! container is known from F and V before a byte is written; only the morph targets'
//! `min`/`max` (which the JSON chunk, written first, must hold) need the frames, so they are
//! asked for twice: once for the bounds, once for the bytes.

use std::io::Write as _;
use std::path::Path;

use glam::{Vec2, Vec3};
use serde_json::{Value, json};

use super::write::{
    COMPONENT_FLOAT, COMPONENT_UNSIGNED_INT, TARGET_ARRAY_BUFFER, TARGET_ELEMENT_ARRAY_BUFFER,
    check_finite, check_len, check_topology, check_vec3, glb_root, invalid, write_container,
};
use crate::{MeshIoError, NormalWeighting, compute_normals};

/// Most frames a `.glb` morph-target animation may hold. The file stores the one-hot weights
/// track sparsely (linear in F), but readers expand it to F·(F − 1) floats (one weight per
/// target per keyframe): 64 MiB at this limit. Longer clips belong in `.npy`, an OBJ frame
/// folder or a vertex-animation texture.
pub const MAX_GLB_ANIMATION_FRAMES: usize = 4096;

/// Everything of a streamed animation but its frames ([`write_glb_animation_with`]).
#[derive(Clone, Copy, Debug)]
pub struct GlbClip<'a> {
    /// Triangles, shared by every frame.
    pub triangles: &'a [[u32; 3]],
    /// Per-vertex UVs (`TEXCOORD_0`), when the clip has them.
    pub uvs: Option<&'a [Vec2]>,
    /// Frames per second, finite and > 0.
    pub frame_rate: f32,
    /// F: how many frames the callback delivers, 1 ..= [`MAX_GLB_ANIMATION_FRAMES`].
    pub frames: usize,
    /// V: vertices per frame.
    pub vertices: usize,
}

/// Writes an animation whose frames `frame(f, positions)` fills one at a time, as
/// [`super::write_glb_animation`] writes a whole [`crate::Animation`] (same layout, same
/// bytes), atomically. Frame 0 is asked for once, every later frame twice (bounds, then bytes);
/// the callback must give the same positions both times.
///
/// # Errors
/// As [`super::write_glb_animation`], plus F = 0 or F > [`MAX_GLB_ANIMATION_FRAMES`] (refused
/// before the first frame) and a frame that differs between the two passes; the callback's
/// own error, unchanged. Nothing is written on error.
///
/// # Examples
/// ```
/// use glam::Vec3;
/// let triangles = [[0u32, 1, 2]];
/// let clip = meshio::GlbClip { triangles: &triangles, uvs: None, frame_rate: 30.0, frames: 3, vertices: 3 };
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("lift.glb");
/// meshio::write_glb_animation_with(&path, &clip, |f, p: &mut [Vec3]| {
///     p.copy_from_slice(&[Vec3::ZERO, Vec3::X, Vec3::Y].map(|v| v + Vec3::Z * f as f32));
///     Ok::<(), meshio::MeshIoError>(())
/// })
/// .unwrap();
/// let (clip, _) = meshio::load_animation(&path, &meshio::AnimationOptions::default()).unwrap();
/// assert_eq!(clip.frames.len(), 3);
/// assert_eq!(clip.frames[2][1], Vec3::new(1.0, 0.0, 2.0));
/// ```
pub fn write_glb_animation_with<E: From<MeshIoError>>(
    path: &Path,
    clip: &GlbClip<'_>,
    mut frame: impl FnMut(usize, &mut [Vec3]) -> Result<(), E>,
) -> Result<(), E> {
    check_clip(path, clip)?;
    let (n, count) = (clip.vertices, clip.frames);
    let mut first = vec![Vec3::ZERO; n];
    frame(0, &mut first)?;
    check_vec3(path, "frame 0 POSITION", &first, n)?;
    let base_normals = normals_of(&first, clip.triangles);

    // Pass 1: the bounds of every morph target's position deltas.
    let mut scratch = vec![Vec3::ZERO; n];
    let mut bounds = Vec::with_capacity(count.saturating_sub(1));
    for f in 1..count {
        frame(f, &mut scratch)?;
        check_vec3(path, &format!("frame {f} POSITION"), &scratch, n)?;
        bounds.push(delta_bounds(&scratch, &first));
    }

    let layout = Layout::new(clip, &first, &bounds);
    let (root, bin_len) = layout.root();
    // Pass 2, inside the atomic write: the callback's error (or a frame that changed) is kept
    // here while the write unwinds with a placeholder I/O error.
    let mut failure: Option<E> = None;
    let written = write_container(path, &root, bin_len, |w| {
        write_vec3(w, &first)?;
        write_vec3(w, &base_normals)?;
        if let Some(uvs) = clip.uvs {
            for uv in uvs {
                write_floats(w, &uv.to_array())?;
            }
        }
        for i in clip.triangles.iter().flatten() {
            w.write_all(&i.to_le_bytes())?;
        }
        let mut delta = vec![Vec3::ZERO; n];
        for f in 1..count {
            if let Err(e) = frame(f, &mut scratch) {
                failure = Some(e);
                return Err(std::io::Error::other("the frame source failed"));
            }
            if delta_bounds(&scratch, &first) != bounds[f - 1] {
                failure = Some(E::from(invalid(
                    path,
                    format!("frame {f} POSITION"),
                    "differs between the two passes of the streamed writer; the frame source \
                     must be deterministic"
                        .into(),
                )));
                return Err(std::io::Error::other("the frame source changed"));
            }
            for ((d, p), p0) in delta.iter_mut().zip(&scratch).zip(&first) {
                *d = *p - *p0;
            }
            write_vec3(w, &delta)?;
            let normals = normals_of(&scratch, clip.triangles);
            for ((d, nf), n0) in delta.iter_mut().zip(&normals).zip(&base_normals) {
                *d = *nf - *n0;
            }
            write_vec3(w, &delta)?;
        }
        if count > 1 {
            for t in keyframe_times(count, clip.frame_rate) {
                w.write_all(&t.to_le_bytes())?;
            }
            // Keyframe f's weights: one-hot on target f − 1 (all zero for f = 0), as the
            // sparse entries (f·T + f − 1, 1.0), T = F − 1 targets.
            let targets = count - 1;
            for f in 1..count {
                let index = u32::try_from(f * targets + f - 1).expect("F ≤ 4096: F² < 2³²");
                w.write_all(&index.to_le_bytes())?;
            }
            for _ in 1..count {
                w.write_all(&1.0f32.to_le_bytes())?;
            }
        }
        Ok(())
    });
    match (written, failure) {
        (_, Some(e)) => Err(e),
        (Err(e), None) => Err(E::from(e)),
        (Ok(()), None) => Ok(()),
    }
}

fn check_clip(path: &Path, clip: &GlbClip<'_>) -> Result<(), MeshIoError> {
    if clip.frames == 0 || clip.frames > MAX_GLB_ANIMATION_FRAMES {
        return Err(invalid(
            path,
            "animation".into(),
            format!(
                "has {} frames; a .glb morph-target animation holds 1 ..= \
                 {MAX_GLB_ANIMATION_FRAMES} (MAX_GLB_ANIMATION_FRAMES: readers expand its \
                 weights to F² floats); write .npy or an OBJ frame folder for longer clips",
                clip.frames
            ),
        ));
    }
    let rate = clip.frame_rate;
    if !(rate.is_finite() && rate > 0.0) {
        return Err(invalid(
            path,
            "animation frame_rate".into(),
            format!("{rate} must be finite and > 0"),
        ));
    }
    check_topology(path, clip.vertices, clip.triangles)?;
    if let Some(uvs) = clip.uvs {
        check_len(path, "TEXCOORD_0", uvs.len(), clip.vertices)?;
        check_finite(path, "TEXCOORD_0", uvs.iter().flat_map(|uv| uv.to_array()))?;
    }
    Ok(())
}

/// Angle-weighted normals; a vertex no face uses gets +Y so that every normal is unit length.
fn normals_of(frame: &[Vec3], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    compute_normals(frame, triangles, NormalWeighting::Angle)
        .into_iter()
        .map(|n| if n == Vec3::ZERO { Vec3::Y } else { n })
        .collect()
}

/// Component-wise min and max of `frame − first`.
fn delta_bounds(frame: &[Vec3], first: &[Vec3]) -> (Vec3, Vec3) {
    frame
        .iter()
        .zip(first)
        .map(|(p, p0)| *p - *p0)
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), d| {
            (lo.min(d), hi.max(d))
        })
}

/// The same expression as the loader's sampling times, so that STEP look-ups at
/// f / frame_rate land exactly on keyframe f.
fn keyframe_times(count: usize, rate: f32) -> impl Iterator<Item = f32> {
    (0..count).map(move |f| (f as f64 / f64::from(rate)) as f32)
}

fn write_floats(w: &mut impl std::io::Write, values: &[f32]) -> std::io::Result<()> {
    for v in values {
        w.write_all(&v.to_le_bytes())?;
    }
    Ok(())
}

fn write_vec3(w: &mut impl std::io::Write, values: &[Vec3]) -> std::io::Result<()> {
    for v in values {
        write_floats(w, &v.to_array())?;
    }
    Ok(())
}

/// The buffer views and accessors of a clip, in the order pass 2 writes their bytes.
struct Layout {
    views: Vec<Value>,
    accessors: Vec<Value>,
    meshes: Value,
    animations: Option<Value>,
    bin_len: usize,
}

impl Layout {
    fn new(clip: &GlbClip<'_>, first: &[Vec3], bounds: &[(Vec3, Vec3)]) -> Self {
        let mut layout = Self {
            views: Vec::new(),
            accessors: Vec::new(),
            meshes: Value::Null,
            animations: None,
            bin_len: 0,
        };
        let n = clip.vertices;
        let min_max = |lo: Vec3, hi: Vec3| {
            // f64 so that the JSON numbers are the f32 values exactly.
            Some((lo.as_dvec3().to_array(), hi.as_dvec3().to_array()))
        };
        let (lo, hi) = first
            .iter()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(a, b), v| {
                (a.min(*v), b.max(*v))
            });
        let mut attributes = serde_json::Map::new();
        attributes.insert("POSITION".into(), layout.vec3(n, min_max(lo, hi)).into());
        attributes.insert("NORMAL".into(), layout.vec3(n, None).into());
        if clip.uvs.is_some() {
            let view = layout.view(8 * n, TARGET_ARRAY_BUFFER);
            let uv = layout.accessor(view, COMPONENT_FLOAT, n, "VEC2");
            attributes.insert("TEXCOORD_0".into(), uv.into());
        }
        let view = layout.view(12 * clip.triangles.len(), TARGET_ELEMENT_ARRAY_BUFFER);
        let indices = layout.accessor(
            view,
            COMPONENT_UNSIGNED_INT,
            3 * clip.triangles.len(),
            "SCALAR",
        );
        let targets: Vec<Value> = bounds
            .iter()
            .map(|&(lo, hi)| {
                json!({ "POSITION": layout.vec3(n, min_max(lo, hi)), "NORMAL": layout.vec3(n, None) })
            })
            .collect();
        let mut primitive = json!({ "attributes": attributes, "indices": indices, "mode": 4 });
        let mut mesh = json!({ "name": "animation" });
        let target_count = targets.len();
        if target_count > 0 {
            primitive["targets"] = Value::Array(targets);
            mesh["weights"] = json!(vec![0.0; target_count]);
            let view = layout.view(4 * clip.frames, 0);
            let input = layout.accessor(view, COMPONENT_FLOAT, clip.frames, "SCALAR");
            let last = keyframe_times(clip.frames, clip.frame_rate)
                .last()
                .unwrap_or(0.0);
            layout.accessors[input]["min"] = json!([0.0]);
            layout.accessors[input]["max"] = json!([f64::from(last)]);
            // The weights track is one-hot per keyframe: a sparse accessor (zeros, with a 1
            // at f·T + f − 1 for f ≥ 1) keeps the file linear in F.
            let ones = clip.frames - 1;
            let indices = layout.view(4 * ones, 0);
            let values = layout.view(4 * ones, 0);
            layout.accessors.push(json!({
                "componentType": COMPONENT_FLOAT,
                "count": clip.frames * target_count,
                "type": "SCALAR",
                "sparse": {
                    "count": ones,
                    "indices": { "bufferView": indices, "componentType": COMPONENT_UNSIGNED_INT },
                    "values": { "bufferView": values },
                },
            }));
            let output = layout.accessors.len() - 1;
            layout.animations = Some(json!([{
                "name": "frames",
                "samplers": [{ "input": input, "output": output, "interpolation": "STEP" }],
                "channels": [{ "sampler": 0, "target": { "node": 0, "path": "weights" } }],
            }]));
        }
        mesh["primitives"] = json!([primitive]);
        layout.meshes = json!([mesh]);
        layout
    }

    /// Every view's length is a multiple of 4 (floats and u32 indices), so the views lie back
    /// to back, each 4-byte aligned.
    fn view(&mut self, byte_length: usize, target: u32) -> usize {
        let mut view =
            json!({ "buffer": 0, "byteOffset": self.bin_len, "byteLength": byte_length });
        if target != 0 {
            view["target"] = json!(target);
        }
        self.bin_len += byte_length;
        self.views.push(view);
        self.views.len() - 1
    }

    fn accessor(&mut self, view: usize, component: u32, count: usize, kind: &str) -> usize {
        self.accessors.push(json!({
            "bufferView": view,
            "componentType": component,
            "count": count,
            "type": kind,
        }));
        self.accessors.len() - 1
    }

    fn vec3(&mut self, n: usize, min_max: Option<([f64; 3], [f64; 3])>) -> usize {
        let view = self.view(12 * n, TARGET_ARRAY_BUFFER);
        let accessor = self.accessor(view, COMPONENT_FLOAT, n, "VEC3");
        if let Some((lo, hi)) = min_max {
            self.accessors[accessor]["min"] = json!(lo);
            self.accessors[accessor]["max"] = json!(hi);
        }
        accessor
    }

    /// The glTF document and the BIN chunk's length.
    fn root(self) -> (Value, usize) {
        let root = glb_root(
            self.meshes,
            self.accessors,
            self.views,
            self.bin_len,
            self.animations,
        );
        (root, self.bin_len)
    }
}
