//! The animations the reports run on: every clip in `../shared/data/anim` that meshio reads,
//! and the synthetic cloth drape.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context as _;
use glam::Vec3;

/// The synthetic cloth: the default drape, 66 × 66 vertices over 120 frames (4 s at 30 fps),
/// about a second to simulate on two cores.
pub fn cloth_params() -> synth::ClothParams {
    synth::ClothParams {
        grid: 66,
        frames: 120,
        ..synth::ClothParams::default()
    }
}

/// One clip of the report.
pub struct Sequence {
    /// Name in the tables (path under `anim/` without `.glb`, or `synth-cloth`).
    pub name: String,
    /// Where it came from, as markdown.
    pub source: String,
    /// Frames, rate and load time, as markdown.
    pub note: String,
    /// `frames[f][m]`.
    pub frames: Vec<Vec<Vec3>>,
    /// Triangles (empty for an `.npy` clip).
    pub triangles: Vec<[u32; 3]>,
}

impl Sequence {
    /// Frames.
    pub fn l(&self) -> usize {
        self.frames.len()
    }

    /// Vertices.
    pub fn n(&self) -> usize {
        self.frames[0].len()
    }

    /// The name with every non-alphanumeric character replaced by `-`.
    pub fn slug(&self) -> String {
        self.name
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
            .collect()
    }
}

/// Animation files and OBJ folders under `anim`: a folder holding `.obj` files is one
/// sequence, `.glb`/`.gltf`/`.npy` files are one each; other folders are searched one level
/// deeper. Sorted by path.
fn discover(anim: &Path, depth: usize, out: &mut Vec<PathBuf>) -> anyhow::Result<()> {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(anim)
        .with_context(|| format!("listing {}", anim.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .collect();
    entries.sort();
    let has_ext = |p: &Path, exts: &[&str]| {
        p.extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| exts.iter().any(|x| e.eq_ignore_ascii_case(x)))
    };
    for path in entries {
        if path.is_dir() {
            let has_obj = std::fs::read_dir(&path)
                .with_context(|| format!("listing {}", path.display()))?
                .filter_map(|e| e.ok())
                .any(|e| has_ext(&e.path(), &["obj"]));
            if has_obj {
                out.push(path);
            } else if depth > 0 {
                discover(&path, depth - 1, out)?;
            }
        } else if has_ext(&path, &["glb", "gltf", "npy"]) {
            out.push(path);
        }
    }
    Ok(())
}

/// Loads every sequence meshio reads (the others are listed in `skipped`) and the cloth;
/// clips longer than `max_frames` are cut to their first `max_frames` frames, and clips of
/// fewer than 3 frames are skipped. `what` names the report in the missing-data error.
pub fn load_sequences(
    skipped: &mut Vec<String>,
    max_frames: usize,
    what: &str,
) -> anyhow::Result<Vec<Sequence>> {
    let root = test_data::data_root();
    let anim = root.join("anim");
    if !anim.is_dir() {
        anyhow::bail!(
            "missing {}: the {what} repro needs the shared animations (`../shared/data` \
             beside the workspace, or set {} to its folder)",
            anim.display(),
            test_data::DATA_ENV
        );
    }
    let mut paths = Vec::new();
    discover(&anim, 2, &mut paths)?;
    let mut sequences = Vec::new();
    for path in paths {
        let name = path
            .strip_prefix(&anim)
            .unwrap_or(&path)
            .to_string_lossy()
            .into_owned();
        let start = Instant::now();
        match meshio::load_animation(&path, &meshio::AnimationOptions::default()) {
            Ok((mut clip, _)) => {
                let total = clip.frames.len();
                if total < 3 {
                    skipped.push(format!(
                        "`{name}`: {total} frame(s); the report needs a clip"
                    ));
                    continue;
                }
                let mut note = format!(
                    "{total} frames at {} fps, loaded in {:.1} s",
                    clip.frame_rate,
                    start.elapsed().as_secs_f64()
                );
                if total > max_frames {
                    clip.frames.truncate(max_frames);
                    let _ = write!(note, "; **first {max_frames} used**");
                }
                eprintln!("loaded {name}: {note}");
                sequences.push(Sequence {
                    name: name.trim_end_matches(".glb").to_owned(),
                    source: format!("`anim/{name}`"),
                    note,
                    frames: clip.frames,
                    triangles: clip.triangles,
                });
            }
            Err(e) => skipped.push(format!("`{name}`: meshio could not load it ({e})")),
        }
    }
    let params = cloth_params();
    let start = Instant::now();
    let cloth = synth::simulate_cloth(&params)?;
    let note = format!(
        "{}×{} grid dropped on a ball, simulated in {:.1} s",
        params.grid,
        params.grid,
        start.elapsed().as_secs_f64()
    );
    eprintln!("simulated the cloth: {note}");
    sequences.push(Sequence {
        name: "synth-cloth".to_owned(),
        source: "`synth::simulate_cloth`".to_owned(),
        note,
        frames: cloth.frames,
        triangles: cloth.triangles,
    });
    Ok(sequences)
}
