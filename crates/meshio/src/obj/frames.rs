//! A folder of numbered OBJ frames as one [`Animation`].
//!
//! Frames are ordered **numerically** by the last run of digits in the file stem (`2.obj`
//! before `10.obj`; `0001.obj` = 1), parsed in parallel (rayon), and must share the vertex count
//! and the face list of frame 0 exactly; the error names the first offending frame in numeric
//! order. Other files in the folder are ignored (and noted in the report).

use std::path::{Path, PathBuf};

use rayon::prelude::*;

use super::{ObjData, into_raw, parse_obj};
use crate::validate::finish_animation;
use crate::{Animation, AnimationOptions, LoadReport, MeshIoError, SourceFormat};

/// The number in a frame file name: the last run of ASCII digits of the stem.
pub(crate) fn frame_number(stem: &str) -> Option<u64> {
    let bytes = stem.as_bytes();
    let end = bytes.iter().rposition(u8::is_ascii_digit)? + 1;
    let start = bytes[..end]
        .iter()
        .rposition(|b| !b.is_ascii_digit())
        .map_or(0, |i| i + 1);
    stem[start..end].parse().ok()
}

/// Lists the `.obj` files of `dir` in numeric frame order.
fn frame_files(dir: &Path, report: &mut LoadReport) -> Result<Vec<PathBuf>, MeshIoError> {
    let folder_error = |message: String| MeshIoError::FrameFolder {
        path: dir.to_path_buf(),
        message,
    };
    let mut numbered: Vec<(u64, PathBuf)> = Vec::new();
    let mut ignored = 0usize;
    for entry in std::fs::read_dir(dir).map_err(|e| MeshIoError::io(dir, "list", e))? {
        let entry = entry.map_err(|e| MeshIoError::io(dir, "list", e))?;
        let path = entry.path();
        let is_obj = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("obj"));
        if !is_obj || !path.is_file() {
            ignored += 1;
            continue;
        }
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let Some(number) = frame_number(&stem) else {
            return Err(folder_error(format!(
                "{} has no frame number; name frames with a number (1.obj, 0002.obj …) or move the file out",
                path.display()
            )));
        };
        numbered.push((number, path));
    }
    if numbered.is_empty() {
        return Err(folder_error(
            "contains no .obj files; expected numbered frames such as 0001.obj".into(),
        ));
    }
    numbered.sort();
    if let Some(pair) = numbered.windows(2).find(|w| w[0].0 == w[1].0) {
        return Err(folder_error(format!(
            "{} and {} both have frame number {}; keep one of them",
            pair[0].1.display(),
            pair[1].1.display(),
            pair[0].0
        )));
    }
    if ignored > 0 {
        report.notes.push(format!(
            "{ignored} entries that are not .obj files were ignored"
        ));
    }
    Ok(numbered.into_iter().map(|(_, path)| path).collect())
}

fn parse_frame(path: &Path) -> Result<(ObjData, LoadReport), MeshIoError> {
    let data = input_guard::read_regular(path).map_err(|e| MeshIoError::io(path, "read", e))?;
    let mut report = LoadReport::default();
    let obj = parse_obj(path, &data, &mut report)?;
    Ok((obj, report))
}

/// Loads a folder of numbered OBJ frames.
pub(crate) fn load_obj_frames(
    dir: &Path,
    options: &AnimationOptions,
) -> Result<(Animation, LoadReport), MeshIoError> {
    options.validate(dir)?;
    let mut report = LoadReport::new(dir, SourceFormat::ObjFrames);
    let files = frame_files(dir, &mut report)?;
    let parsed: Vec<Result<(ObjData, LoadReport), MeshIoError>> =
        files.par_iter().map(|p| parse_frame(p)).collect();
    let mut frames = Vec::with_capacity(files.len());
    let mut first: Option<ObjData> = None;
    for (index, result) in parsed.into_iter().enumerate() {
        let (obj, frame_report) = result?;
        for (keyword, count) in frame_report.skipped_keywords {
            *report.skipped_keywords.entry(keyword).or_insert(0) += count;
        }
        match &first {
            None => {
                report.file_face_count = frame_report.file_face_count;
                report.polygons_triangulated = frame_report.polygons_triangulated;
                first = Some(obj);
            }
            Some(reference) => {
                check_same_topology(dir, &files, index, reference, &obj)?;
                frames.push(obj.positions);
            }
        }
    }
    let Some(first) = first else {
        return Err(MeshIoError::FrameFolder {
            path: dir.to_path_buf(),
            message: "contains no frames".into(),
        });
    };
    let raw = into_raw(first, &mut report);
    frames.insert(0, raw.positions);
    let animation = Animation {
        triangles: raw.triangles,
        frames,
        frame_rate: options.frame_rate,
        uvs: raw.uvs,
    };
    report.frame_files = files;
    finish_animation(dir, animation, false, report)
}

/// Errors unless `obj` (frame `index`) has the vertex count and face list of `reference`.
fn check_same_topology(
    dir: &Path,
    files: &[PathBuf],
    index: usize,
    reference: &ObjData,
    obj: &ObjData,
) -> Result<(), MeshIoError> {
    let count_error =
        |what: &'static str, expected: usize, found: usize| MeshIoError::FrameCountMismatch {
            path: dir.to_path_buf(),
            frame: index,
            file: files[index].clone(),
            first_file: files[0].clone(),
            what,
            expected,
            found,
        };
    if obj.positions.len() != reference.positions.len() {
        return Err(count_error(
            "vertices",
            reference.positions.len(),
            obj.positions.len(),
        ));
    }
    if obj.triangles.len() != reference.triangles.len() {
        return Err(count_error(
            "triangles",
            reference.triangles.len(),
            obj.triangles.len(),
        ));
    }
    if let Some(t) = (0..obj.triangles.len()).find(|&t| obj.triangles[t] != reference.triangles[t])
    {
        return Err(MeshIoError::FrameTopologyMismatch {
            path: dir.to_path_buf(),
            frame: index,
            file: files[index].clone(),
            triangle: t,
            expected: reference.triangles[t],
            found: obj.triangles[t],
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::frame_number;

    #[test]
    fn frame_numbers_use_the_last_digit_run() {
        assert_eq!(frame_number("170"), Some(170));
        assert_eq!(frame_number("0001"), Some(1));
        assert_eq!(frame_number("take2_frame0010"), Some(10));
        assert_eq!(frame_number("frame12b"), Some(12));
        assert_eq!(frame_number("rest"), None);
    }
}
