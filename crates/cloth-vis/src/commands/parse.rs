//! Value parsers shared by the subcommands' flags.

/// Parse `A..B` (end exclusive).
pub fn range(text: &str) -> Result<(usize, usize), String> {
    let (a, b) = text
        .split_once("..")
        .ok_or_else(|| format!("{text:?} is not A..B"))?;
    let a = a
        .trim()
        .parse::<usize>()
        .map_err(|e| format!("{a:?}: {e}"))?;
    let b = b
        .trim()
        .parse::<usize>()
        .map_err(|e| format!("{b:?}: {e}"))?;
    Ok((a, b))
}

/// Parse `A,E`: two counts, each at least 1 (e.g. `--decompose 30,5`).
pub fn two_counts(text: &str) -> Result<(usize, usize), String> {
    let (a, e) = text
        .split_once(',')
        .ok_or_else(|| format!("{text:?} is not A,E (e.g. 30,5)"))?;
    let count = |s: &str| match s.trim().parse::<usize>() {
        Ok(0) => Err(format!("{s:?} in {text:?}: must be at least 1")),
        Ok(n) => Ok(n),
        Err(err) => Err(format!("{s:?} in {text:?}: {err}")),
    };
    Ok((count(a)?, count(e)?))
}

/// Parse `NAME=PATH` (e.g. `--part sleeve=silk.btfpca`); NAME may not be empty.
pub fn named_path(text: &str) -> Result<(String, std::path::PathBuf), String> {
    match text.split_once('=') {
        Some((name, path)) if !name.is_empty() && !path.is_empty() => {
            Ok((name.to_owned(), std::path::PathBuf::from(path)))
        }
        _ => Err(format!(
            "{text:?} is not NAME=FILE (e.g. sleeve=silk.btfpca)"
        )),
    }
}

/// Parse `X,Y,Z` (finite).
pub fn vec3(text: &str) -> Result<glam::Vec3, String> {
    let parts: Vec<&str> = text.split(',').collect();
    let [x, y, z] = parts[..] else {
        return Err(format!("{text:?} is not X,Y,Z (e.g. 0.3,0.8,0.5)"));
    };
    let num = |s: &str| {
        s.trim()
            .parse::<f32>()
            .map_err(|e| format!("{s:?} in {text:?}: {e}"))
    };
    let v = glam::Vec3::new(num(x)?, num(y)?, num(z)?);
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!("{text:?} is not finite"))
    }
}

/// Parse `WxH` (e.g. `640x480`).
pub fn size(text: &str) -> Result<[u32; 2], String> {
    let (w, h) = text
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("{text:?} is not WxH (e.g. 640x480)"))?;
    let side = |s: &str| {
        s.trim()
            .parse::<u32>()
            .map_err(|e| format!("{s:?} in {text:?}: {e}"))
    };
    Ok([side(w)?, side(h)?])
}

/// Parse `--clip NAME|INDEX`: a glTF animation by its index in the file (digits) or its name.
pub fn clip(text: &str) -> Result<meshio::ClipSelector, String> {
    let text = text.trim();
    if text.is_empty() {
        return Err("give a clip name or index (e.g. --clip Walk or --clip 1)".to_owned());
    }
    Ok(match text.parse::<usize>() {
        Ok(index) => meshio::ClipSelector::Index(index),
        Err(_) => meshio::ClipSelector::Name(text.to_owned()),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_vectors_and_sizes_parse_and_bad_text_names_itself() {
        assert_eq!(range("3..7"), Ok((3, 7)));
        assert!(range("3-7").unwrap_err().contains("\"3-7\""));
        assert_eq!(vec3("1, 2,3"), Ok(glam::Vec3::new(1.0, 2.0, 3.0)));
        assert!(vec3("1,2").unwrap_err().contains("X,Y,Z"));
        assert!(vec3("1,inf,2").unwrap_err().contains("not finite"));
        assert_eq!(size("640X480"), Ok([640, 480]));
        assert!(size("640").unwrap_err().contains("WxH"));
    }
}
