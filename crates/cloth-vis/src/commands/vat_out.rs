//! `--out CLIP.exr|CLIP.png` of the animation commands: a vertex-animation texture
//! ([`meshio::write_vat_with`]: positions per vertex per frame, a normals image and a JSON
//! sidecar, in the layout SideFX Labs' and OpenVAT's engine shaders read).

use std::path::Path;

use cloth_vis::Error;
use glam::Vec3;

use super::invalid;

/// Whether `out` names a vertex-animation texture (`.exr` float, `.png` 16-bit).
pub(super) fn is_vat(out: &Path) -> bool {
    matches!(
        super::visibility::lower_extension(out).as_deref(),
        Some("exr" | "png")
    )
}

/// Refuses, before any work, a clip without triangles (an `.npy` without `--topology`: the
/// normals need them) or one whose texture would exceed [`meshio::VAT_MAX_HEIGHT`].
pub(super) fn check(
    input: &Path,
    out: &Path,
    triangles: &[[u32; 3]],
    (frames, vertices): (usize, usize),
) -> Result<(), Error> {
    meshio::vat_layout(out, frames, vertices)?;
    if triangles.is_empty() {
        return Err(invalid(
            input,
            "the clip has no triangles (an .npy clip): a vertex-animation texture holds \
             normals too; pass --topology MESH or write .npy"
                .to_owned(),
        ));
    }
    Ok(())
}

/// Writes the frames `frame(f, positions, alpha)` delivers as a VAT at `out`; returns the line
/// that tells the user what was written.
pub(super) fn write(
    out: &Path,
    triangles: &[[u32; 3]],
    frame_rate: f32,
    (frames, vertices): (usize, usize),
    frame: impl FnMut(usize, &mut [Vec3], &mut [f32]) -> Result<(), Error>,
) -> Result<String, Error> {
    let clip = meshio::VatClip {
        triangles,
        frame_rate,
        frames,
        vertices,
    };
    let report = meshio::write_vat_with(out, &clip, frame)?;
    let [positions, normals, sidecar] = &report.files;
    Ok(format!(
        "vertex-animation texture {}x{} ({} row(s) per frame): {}, {}, {}",
        report.width,
        report.height,
        report.rows_per_frame,
        positions.display(),
        normals.display(),
        sidecar.display()
    ))
}
