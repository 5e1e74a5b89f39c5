//! Checks of the clips handed to the analysis: frame and vertex counts, finite positions,
//! normals and attributes of matching shape, before any PCA runs.

use glam::Vec3;

use super::analysis::Clip;
use crate::error::{AnimPcaError, Result};

/// Checks the clips of [`JumpMap::analyze_cells`] and returns their common vertex count.
pub(super) fn validate_clips(clips: &[Clip<'_>]) -> Result<usize> {
    const WHAT: &str = "JumpMap::analyze_cells";
    let cell_err = |cell: usize, reason: String| AnimPcaError::InvalidCell {
        what: WHAT,
        cell,
        reason,
    };
    let Some(first) = clips.first() else {
        return Err(cell_err(0, "no clip given; pass at least one".into()));
    };
    let n = validate_clip(WHAT, first.positions)?;
    for (k, clip) in clips.iter().enumerate() {
        let nk = validate_clip(WHAT, clip.positions)?;
        if nk != n {
            return Err(cell_err(
                k,
                format!("{nk} vertices but cell 0 has {n}; cells share one mesh (thesis §3.2.2)"),
            ));
        }
        if clip.normals.is_some() != first.normals.is_some() {
            return Err(cell_err(
                k,
                "normals given for some cells but not all".into(),
            ));
        }
        if let Some(nrm) = clip.normals {
            if nrm.len() != clip.positions.len() {
                return Err(cell_err(
                    k,
                    format!(
                        "{} normal frames for {} position frames",
                        nrm.len(),
                        clip.positions.len()
                    ),
                ));
            }
            validate_frames("JumpMap::analyze_cells normals", nrm, n)?;
        }
        if clip.attributes.is_some() != first.attributes.is_some() {
            return Err(cell_err(
                k,
                "attributes given for some cells but not all".into(),
            ));
        }
        if let Some(attr) = clip.attributes {
            if attr.len() != clip.positions.len() {
                return Err(cell_err(
                    k,
                    format!(
                        "{} attribute vectors for {} frames",
                        attr.len(),
                        clip.positions.len()
                    ),
                ));
            }
            let m = first.attributes.and_then(|a| a.first()).map_or(0, Vec::len);
            if m == 0 {
                return Err(cell_err(0, "attribute vectors are empty".into()));
            }
            for (i, r) in attr.iter().enumerate() {
                if r.len() != m {
                    return Err(cell_err(
                        k,
                        format!(
                            "frame {i} has {} attributes, frame 0 of cell 0 has {m}",
                            r.len()
                        ),
                    ));
                }
                if let Some(x) = r.iter().find(|x| !x.is_finite()) {
                    return Err(cell_err(k, format!("frame {i} has the attribute {x}")));
                }
            }
        }
    }
    Ok(n)
}

/// Checks a clip and returns its vertex count.
pub(crate) fn validate_clip(what: &'static str, positions: &[Vec<Vec3>]) -> Result<usize> {
    let n = positions.first().map_or(0, Vec::len);
    if n == 0 {
        return Err(AnimPcaError::EmptyClip {
            what,
            frames: positions.len(),
            vertices: n,
        });
    }
    if positions.len() < 2 {
        return Err(AnimPcaError::TooFewFrames {
            what,
            frames: positions.len(),
            min: 2,
        });
    }
    validate_frames(what, positions, n)?;
    Ok(n)
}

fn validate_frames(what: &'static str, frames: &[Vec<Vec3>], n: usize) -> Result<()> {
    for (i, f) in frames.iter().enumerate() {
        if f.len() != n {
            return Err(AnimPcaError::VertexCountMismatch {
                what,
                frame: i,
                expected: n,
                found: f.len(),
            });
        }
        if let Some((k, v)) = f.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            let value = v
                .to_array()
                .into_iter()
                .find(|x| !x.is_finite())
                .unwrap_or(f32::NAN);
            return Err(AnimPcaError::NonFinite {
                what,
                frame: i,
                vertex: k,
                value,
            });
        }
    }
    Ok(())
}
