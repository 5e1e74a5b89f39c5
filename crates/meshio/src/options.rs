//! Options for [`load_mesh`](crate::load_mesh) and [`load_animation`](crate::load_animation).

use std::path::PathBuf;

/// How face normals are weighted when they are summed into vertex normals.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum NormalWeighting {
    /// Weight each face normal by the face's interior angle at the vertex (Thürmer & Wüthrich
    /// 1998). Independent of how a polygon was triangulated; the default.
    #[default]
    Angle,
    /// Weight each face normal by the face's area (the plain sum of cross products).
    Area,
}

/// Options for [`load_mesh`](crate::load_mesh).
///
/// The default keeps the file as it is: every vertex stays at its index (per-vertex outputs
/// line up with the file), degenerate triangles stay, normals come from the file when it has
/// them and are computed otherwise.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LoadOptions {
    /// Remove triangles with a repeated index or zero area (they are always reported).
    pub remove_degenerate: bool,
    /// Remove vertices that no kept triangle references and renumber the rest; the old → new
    /// map is returned in [`LoadReport::vertex_remap`](crate::LoadReport::vertex_remap).
    pub remove_unreferenced: bool,
    /// Weighting used when normals are computed.
    pub normals: NormalWeighting,
    /// Ignore normals stored in the file and always compute them.
    pub recompute_normals: bool,
}

/// Which animation clip of a glTF file to sample.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub enum ClipSelector {
    /// The first clip in the file; a file without clips gives its rest pose as one frame.
    #[default]
    First,
    /// The clip at this index in the file's `animations` array.
    Index(usize),
    /// The first clip with this name.
    Name(String),
}

/// Default sampling rate for glTF clips and the frame rate assigned to OBJ folders and .npy
/// arrays (frames per second), the rate of the thesis's sequences.
pub const DEFAULT_FRAME_RATE: f32 = 30.0;

/// Default upper bound on the frames sampled from one glTF clip: 100 000 frames are an hour
/// at 30 fps, far above any real clip, yet stop a corrupt keyframe time (say 1e9 s) from
/// allocating terabytes.
pub const DEFAULT_MAX_FRAMES: usize = 100_000;

/// Upper bound on the positions sampled from one glTF clip, in bytes (frames × vertices × 12):
/// 4 GiB. A short clip of a small file can ask for more (BrainStem, 34 159 vertices, is
/// 0.4 MB per frame); a lower `frame_rate` or a shorter clip keeps it in bounds.
pub const MAX_SAMPLED_BYTES: u64 = 4 << 30;

/// Options for [`load_animation`](crate::load_animation).
#[derive(Clone, Debug, PartialEq)]
pub struct AnimationOptions {
    /// Frames per second: the glTF sampling rate, and the rate recorded for OBJ folders and
    /// .npy arrays (which store none). Must be finite and positive.
    pub frame_rate: f32,
    /// The glTF clip to sample.
    pub clip: ClipSelector,
    /// A mesh file (PLY, OBJ, glTF) whose triangles (and UVs) are the connectivity of a `.npy`
    /// animation. Without it a `.npy` animation has no triangles and
    /// [`LoadReport::topology_missing`](crate::LoadReport::topology_missing) is set.
    pub topology: Option<PathBuf>,
    /// Upper bound on the number of frames sampled from a glTF clip.
    pub max_frames: usize,
}

impl Default for AnimationOptions {
    fn default() -> Self {
        Self {
            frame_rate: DEFAULT_FRAME_RATE,
            clip: ClipSelector::First,
            topology: None,
            max_frames: DEFAULT_MAX_FRAMES,
        }
    }
}

impl AnimationOptions {
    /// Checks the frame rate, naming `path` in the error.
    pub(crate) fn validate(&self, path: &std::path::Path) -> Result<(), crate::MeshIoError> {
        if !(self.frame_rate.is_finite() && self.frame_rate > 0.0) {
            return Err(crate::MeshIoError::InvalidOption {
                path: path.to_path_buf(),
                option: "frame_rate",
                value: self.frame_rate.to_string(),
                message: "the frame rate must be finite and positive, e.g. 30".into(),
            });
        }
        Ok(())
    }
}
