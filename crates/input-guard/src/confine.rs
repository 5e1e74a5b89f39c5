//! References from an asset to files beside it, kept inside the asset's folder.

use std::io;
use std::path::{Component, Path, PathBuf};

/// Resolves `reference` (a relative path an asset names, such as a glTF buffer `uri` after
/// percent-decoding) against the asset's folder `base` and returns the path to open.
///
/// Refused: an empty reference, an absolute path or a drive prefix, `..` that climbs above
/// `base` (`a/../../x`), and a path that exists but whose real location (symbolic links
/// resolved) is outside the real location of `base`. `..` that stays inside (`a/../b`) is
/// accepted. A reference to a file that does not exist is returned as is: opening it then
/// fails with the usual "not found" naming it.
///
/// # Errors
/// `PermissionDenied` naming the reference and the folder.
pub fn confined_join(base: &Path, reference: &str) -> io::Result<PathBuf> {
    let refuse = |why: &str| {
        io::Error::new(
            io::ErrorKind::PermissionDenied,
            format!(
                "{reference:?} {why}; an asset may only refer to files inside its folder {}",
                base.display()
            ),
        )
    };
    if reference.is_empty() {
        return Err(refuse("is empty"));
    }
    let relative = Path::new(reference);
    let mut depth = 0usize;
    for component in relative.components() {
        match component {
            Component::Prefix(_) | Component::RootDir => return Err(refuse("is absolute")),
            Component::ParentDir => {
                depth = depth
                    .checked_sub(1)
                    .ok_or_else(|| refuse("climbs out with \"..\""))?;
            }
            Component::Normal(_) => depth += 1,
            Component::CurDir => {}
        }
    }
    let joined = base.join(relative);
    // Symbolic links: compare real locations when both exist. `Path::new("x.gltf").parent()`
    // is the empty path, which is the current folder.
    let base_dir = if base.as_os_str().is_empty() {
        Path::new(".")
    } else {
        base
    };
    if let (Ok(real_base), Ok(real)) = (base_dir.canonicalize(), joined.canonicalize()) {
        if !real.starts_with(&real_base) {
            return Err(refuse(&format!(
                "leads to {} through a symbolic link",
                real.display()
            )));
        }
    }
    Ok(joined)
}
