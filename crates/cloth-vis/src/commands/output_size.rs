//! Outputs too large to write silently: an estimate above [`ANNOUNCE_BYTES`] is announced on
//! stderr before any work starts, one above [`REFUSE_BYTES`] is refused unless `--force`.
//!
//! A new user's `visibility --level 7 --matrix` on the bunny ran silent for minutes towards a
//! 9.4 GB array (N × k f32 held in memory, then written): now it is refused before the first
//! ray with the size and the levers that shrink it.

use std::path::Path;

use super::invalid;
use cloth_vis::Error;

/// Outputs from 1 GiB on are announced.
pub const ANNOUNCE_BYTES: u64 = 1 << 30;
/// Outputs above 8 GiB are refused without `--force`.
pub const REFUSE_BYTES: u64 = 8 << 30;

/// Checks an output of `bytes` at `path` (`what` names it, `levers` says how to shrink it):
/// `Ok(None)` below [`ANNOUNCE_BYTES`], `Ok(Some(announcement))` up to [`REFUSE_BYTES`] or
/// with `force`, an error naming the path and the size above it.
pub fn check(
    path: &Path,
    what: &str,
    bytes: u64,
    levers: &str,
    force: bool,
) -> Result<Option<String>, Error> {
    let gb = bytes as f64 / 1e9;
    if bytes > REFUSE_BYTES && !force {
        return Err(invalid(
            path,
            format!(
                "{what} would be {gb:.1} GB in memory and on disk, above the 8 GiB ({:.1} GB) \
                 limit: {levers}, or pass --force",
                REFUSE_BYTES as f64 / 1e9
            ),
        ));
    }
    Ok((bytes >= ANNOUNCE_BYTES).then(|| {
        format!(
            "{}: {what} will be {gb:.1} GB in memory and on disk",
            path.display()
        )
    }))
}

/// Bytes of `frames` × `vertices` positions written as `.npy`/`.glb`/VAT (12 bytes a vertex)
/// or as an OBJ folder (`obj`: about 40 bytes a `v x y z` line, plus the faces once per frame,
/// `triangles` × ~24 bytes).
pub fn frames_bytes(obj: bool, frames: usize, vertices: usize, triangles: usize) -> u64 {
    let (frames, vertices, triangles) = (frames as u64, vertices as u64, triangles as u64);
    if obj {
        frames.saturating_mul(
            vertices
                .saturating_mul(40)
                .saturating_add(triangles.saturating_mul(24)),
        )
    } else {
        frames.saturating_mul(vertices.saturating_mul(12))
    }
}

/// [`check`] of a frames output ([`frames_bytes`]): the announcement printed on stderr.
///
/// # Errors
/// As [`check`].
pub fn check_frames(
    path: &Path,
    obj: bool,
    (frames, vertices, triangles): (usize, usize, usize),
    levers: &str,
    force: bool,
) -> Result<(), Error> {
    let bytes = frames_bytes(obj, frames, vertices, triangles);
    if let Some(line) = check(path, "the output", bytes, levers, force)? {
        eprintln!("{line}");
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_outputs_are_estimated_by_kind() {
        // 1,000 frames of the chicken (3,030 vertices, 5,664 triangles).
        assert_eq!(frames_bytes(false, 1000, 3030, 5664), 36_360_000);
        assert_eq!(
            frames_bytes(true, 1000, 3030, 5664),
            1000 * (121_200 + 135_936)
        );
        assert_eq!(frames_bytes(true, usize::MAX, usize::MAX, 1), u64::MAX);
    }

    #[test]
    fn the_bunny_at_level_7_is_refused_and_level_6_announced() {
        // 35,947 vertices × k f32: level 7 has k = 2 + 4^8 = 65,538 directions (9.4 GB).
        let path = Path::new("m.npy");
        let m = |k: u64| 35_947 * k * 4;
        let err = check(path, "M", m(65_538), "lower --level", false).unwrap_err();
        let message = err.to_string();
        assert!(
            message.contains("m.npy") && message.contains("9.4 GB"),
            "{message}"
        );
        assert!(message.contains("--force") && message.contains("lower --level"));
        let forced = check(path, "M", m(65_538), "", true).unwrap();
        assert!(forced.unwrap().contains("9.4 GB"));
        // Level 6 (k = 16,386: 2.4 GB) is announced, level 4 (k = 1,026: 148 MB) is quiet.
        assert!(
            check(path, "M", m(16_386), "", false)
                .unwrap()
                .unwrap()
                .contains("2.4 GB")
        );
        assert_eq!(check(path, "M", m(1_026), "", false).unwrap(), None);
        assert!(check(path, "M", REFUSE_BYTES, "", false).unwrap().is_some());
        assert!(check(path, "M", REFUSE_BYTES + 1, "", false).is_err());
    }
}
