//! Animations as folders of numbered OBJ frames (`anim jumpmap` and `anim decompress`),
//! written atomically.

use std::io::Write as _;
use std::path::Path;

use cloth_vis::Error;
use glam::Vec3;

/// Numbered OBJ frames `frame_00000.obj` … in the folder `dir`, with the comment line
/// `# {what}, frame N`: built in a temporary folder beside it and renamed into place when every
/// frame is written (`atomic_out::write_dir`), so an interrupted run leaves no shorter clip
/// that looks complete; `existing` says what happens to a folder that holds files.
/// Frames come from an iterator (a decoder streams them: one frame in memory at a time).
pub(crate) fn write_obj_frames<P: AsRef<[Vec3]>>(
    dir: &Path,
    existing: atomic_out::ExistingFolder,
    frames: impl IntoIterator<Item = Result<P, Error>>,
    triangles: &[[u32; 3]],
    what: &str,
) -> Result<(), Error> {
    atomic_out::write_dir(dir, existing, |tmp| {
        for (f, positions) in frames.into_iter().enumerate() {
            let name = format!("frame_{f:05}.obj");
            write_obj_frame(&tmp.join(&name), f, positions?.as_ref(), triangles, what).map_err(
                |e| Error::Io {
                    path: dir.join(&name),
                    reason: e.to_string(),
                },
            )?;
        }
        Ok(())
    })?;
    Ok(())
}

fn write_obj_frame(
    path: &Path,
    f: usize,
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    what: &str,
) -> std::io::Result<()> {
    let mut w = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(w, "# {what}, frame {f}")?;
    for p in positions {
        writeln!(w, "v {} {} {}", p.x, p.y, p.z)?;
    }
    for t in triangles {
        writeln!(w, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1)?;
    }
    w.into_inner().map_err(|e| e.into_error())?.sync_all()
}
