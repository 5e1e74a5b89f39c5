//! glTF 2.0 (`.gltf`, `.glb`): the scene as a static mesh (rest pose) and skinned / morphed
//! clips sampled into an [`Animation`].
//!
//! Static load: every mesh primitive instantiated by the default scene (or the first scene),
//! with node transforms applied, skinning and default morph weights evaluated in the rest pose
//! (so that a static load equals frame "rest pose" of an animation), merged into one mesh with
//! offset indices. Triangle strips and fans are converted; point and line primitives are an
//! error. An unskinned instance whose transform mirrors (negative determinant) has its
//! triangles flipped so that they stay front-facing.
//!
//! Animation: the selected clip is sampled at `t_i = t_start + i / frame_rate` for
//! `i = 0 … ⌊(t_end − t_start)·frame_rate⌋` (the tail shorter than one frame interval is not
//! sampled), frames evaluated in parallel.

mod accessor;
mod augment;
mod meshopt;
mod pose;
mod rig;
mod sampler;
mod source;
mod stream;
mod write;

use std::path::Path;

use rayon::prelude::*;

pub use accessor::MAX_VIEWLESS_ELEMENTS;
pub use augment::{
    BakeValues, ColourChannel, DoubleSided, GltfBake, GltfBakeReport, text_gltf_buffer,
    write_gltf_with,
};
use rig::Rig;
use sampler::Clip;
use source::GltfSource;
pub use source::{GLTF_DECODE_FLOOR, GLTF_DECODE_PER_INPUT_BYTE};
pub use stream::{GlbClip, MAX_GLB_ANIMATION_FRAMES, write_glb_animation_with};
pub(crate) use write::check_topology;
pub use write::{GlbMesh, NORMAL_UNIT_TOLERANCE, write_glb, write_glb_animation};

use crate::validate::{RawMesh, finish_animation, finish_mesh};
use crate::{
    Animation, AnimationOptions, AttributeStatus, ClipInfo, ClipSelector, LoadOptions, LoadReport,
    Mesh, MeshIoError, SourceFormat,
};

/// Slack when counting sampled frames, in frames: a clip of exactly 2 s at 30 fps has 61
/// frames even when `2.0 × 30.0` rounds to 59.99999.
const FRAME_COUNT_SLACK: f64 = 1e-4;

fn open_rig(path: &Path) -> Result<(GltfSource, Rig, LoadReport), MeshIoError> {
    let src = source::open(path)?;
    let rig = Rig::build(&src)?;
    if rig.instances.is_empty() {
        return Err(MeshIoError::EmptyMesh {
            path: path.to_path_buf(),
            what: "the scene instantiates no mesh".into(),
        });
    }
    let format = if src.is_glb {
        SourceFormat::Glb
    } else {
        SourceFormat::Gltf
    };
    let mut report = LoadReport::new(path, format);
    report.file_face_count = rig.triangles.len();
    report.notes.push(format!(
        "{} primitive(s) in {} mesh instance(s) merged",
        rig.primitive_count,
        rig.instances.len()
    ));
    report.notes.extend(rig.notes.iter().cloned());
    if rig.has_normals {
        report.file_normals = AttributeStatus::Loaded;
    }
    Ok((src, rig, report))
}

/// Loads the scene of a glTF file in its rest pose.
pub(crate) fn load_gltf_mesh(
    path: &Path,
    options: &LoadOptions,
) -> Result<(Mesh, LoadReport), MeshIoError> {
    let (src, rig, mut report) = open_rig(path)?;
    // The rule for an animated glTF, the same everywhere: what holds one shape per vertex (this
    // loader, `cloth-vis bake` into the asset, `btf render`) takes the rest pose; what runs over
    // frames (load_animation: `visibility`, `anim`, bake to a VAT) samples a clip, the first
    // unless one is chosen.
    let clips: Vec<String> = src
        .document
        .animations()
        .map(|a| format!("{} {:?}", a.index(), a.name().unwrap_or("")))
        .collect();
    if !clips.is_empty() {
        report.notes.push(format!(
            "the rest pose of a file with {} animation clip(s) ({}); frame-by-frame consumers \
             sample clip 0 unless another is chosen (cloth-vis: --clip, or --animation here)",
            clips.len(),
            clips.join(", ")
        ));
    }
    let pose = rig.rest_pose();
    let positions = rig.positions(&pose);
    let normals = if options.recompute_normals {
        None
    } else {
        rig.normals(&pose)
    };
    let raw = RawMesh {
        positions,
        normals,
        uvs: rig.uvs.clone(),
        triangles: rig.triangles.clone(),
    };
    finish_mesh(path, raw, options, report)
}

/// The per-triangle materials of the static load (see [`crate::FaceMaterials`]).
pub(crate) fn face_materials(path: &Path) -> Result<crate::FaceMaterials, MeshIoError> {
    let (src, rig, _) = open_rig(path)?;
    let names = src
        .document
        .materials()
        .map(|m| {
            m.name().map_or_else(
                || format!("material {}", m.index().unwrap_or(0)),
                str::to_owned,
            )
        })
        .collect();
    let per_triangle = rig
        .triangle_material
        .iter()
        .map(|m| m.and_then(|i| u32::try_from(i).ok()))
        .collect();
    Ok(crate::FaceMaterials {
        names,
        per_triangle,
    })
}

/// Samples a clip of a glTF file.
pub(crate) fn load_gltf_animation(
    path: &Path,
    options: &AnimationOptions,
) -> Result<(Animation, LoadReport), MeshIoError> {
    options.validate(path)?;
    let (src, rig, mut report) = open_rig(path)?;
    let animations: Vec<gltf::Animation<'_>> = src.document.animations().collect();
    let names = || {
        animations
            .iter()
            .map(|a| format!("{:?}", a.name().unwrap_or("")))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let selected = match &options.clip {
        ClipSelector::First => animations.first(),
        ClipSelector::Index(i) => {
            Some(
                animations
                    .get(*i)
                    .ok_or_else(|| MeshIoError::InvalidOption {
                        path: path.to_path_buf(),
                        option: "clip",
                        value: format!("Index({i})"),
                        message: format!("the file has {} clip(s): {}", animations.len(), names()),
                    })?,
            )
        }
        ClipSelector::Name(name) => Some(
            animations
                .iter()
                .find(|a| a.name() == Some(name.as_str()))
                .ok_or_else(|| MeshIoError::InvalidOption {
                    path: path.to_path_buf(),
                    option: "clip",
                    value: format!("Name({name:?})"),
                    message: format!("no clip has this name; the clips are: {}", names()),
                })?,
        ),
    };
    let frames = match selected {
        None => {
            report
                .notes
                .push("the file has no animation clip: its rest pose is the only frame".into());
            vec![rig.positions(&rig.rest_pose())]
        }
        Some(animation) => {
            let clip = Clip::read(&src, &rig, animation)?;
            let rate = f64::from(options.frame_rate);
            let span = f64::from(clip.end) - f64::from(clip.start);
            let count = (span * rate + FRAME_COUNT_SLACK).floor() + 1.0;
            if count > options.max_frames as f64 {
                return Err(MeshIoError::InvalidOption {
                    path: path.to_path_buf(),
                    option: "max_frames",
                    value: options.max_frames.to_string(),
                    message: format!(
                        "clip {} spans {span} s, which at {rate} fps is {count} frames; lower frame_rate or raise max_frames",
                        animation.index()
                    ),
                });
            }
            let sampled_bytes = count * rig.vertex_count as f64 * 12.0;
            if sampled_bytes > crate::MAX_SAMPLED_BYTES as f64 {
                return Err(MeshIoError::InvalidOption {
                    path: path.to_path_buf(),
                    option: "frame_rate",
                    value: options.frame_rate.to_string(),
                    message: format!(
                        "clip {} is {count} frames of {} vertices, {:.1} GB of positions, over \
                         the limit of {} GB (meshio::MAX_SAMPLED_BYTES); lower the frame rate",
                        animation.index(),
                        rig.vertex_count,
                        sampled_bytes / 1e9,
                        crate::MAX_SAMPLED_BYTES as f64 / 1e9
                    ),
                });
            }
            report.clip = Some(ClipInfo {
                index: animation.index(),
                name: animation.name().map(str::to_string),
                start_s: clip.start,
                end_s: clip.end,
            });
            let start = f64::from(clip.start);
            (0..count as usize)
                .into_par_iter()
                .map(|i| rig.positions(&clip.pose(&rig, (start + i as f64 / rate) as f32)))
                .collect()
        }
    };
    let animation = Animation {
        triangles: rig.triangles,
        frames,
        frame_rate: options.frame_rate,
        uvs: rig.uvs,
    };
    finish_animation(path, animation, false, report)
}
