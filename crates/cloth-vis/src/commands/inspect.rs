//! `cloth-vis inspect`: load a mesh or an animation and print what the loader found, as a
//! few readable lines (format, counts, extent, attributes, what was dropped and why), or the
//! loader's whole report with `--debug`.

use std::io::Write as _;
use std::path::PathBuf;
use std::time::Instant;

use glam::Vec3;
use meshio::{AttributeStatus, LoadReport};

/// Load a mesh or an animation and print what the loader found (counts, quirks, time).
#[derive(clap::Args)]
pub struct InspectArgs {
    /// A mesh (.ply .obj .gltf .glb), an animation (.glb, .npy, .pc2, .mdd, a folder of
    /// numbered .obj).
    input: PathBuf,
    /// Treat a glTF as an animation: sample its first clip, as `visibility` and the `anim`
    /// commands do (default: the rest pose).
    #[arg(long)]
    animation: bool,
    /// The glTF animation to sample, by name or index (implies --animation).
    #[arg(long, value_name = "NAME|INDEX", value_parser = super::parse::clip)]
    clip: Option<meshio::ClipSelector>,
    /// A mesh whose triangles and UVs a point-cache clip (.npy, .pc2, .mdd) takes; its vertex
    /// count must match.
    #[arg(long, value_name = "MESH")]
    topology: Option<PathBuf>,
    /// Print the loader's whole report (every field, every frame file) after the summary.
    #[arg(long)]
    debug: bool,
}

impl InspectArgs {
    /// Load and print.
    pub fn run(self) -> anyhow::Result<()> {
        let input = &self.input;
        let has_ext = |ext: &str| {
            input
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case(ext))
        };
        let mut out = std::io::stdout().lock();
        let start = Instant::now();
        let animation = self.animation
            || self.clip.is_some()
            || input.is_dir()
            || ["npy", "pc2", "mdd"].iter().any(|e| has_ext(e));
        let (lines, report) = if animation {
            let options = super::animation_options(
                &self.clip.clone().unwrap_or_default(),
                self.topology.as_deref(),
            );
            let (anim, report) = meshio::load_animation(input, &options)?;
            let ms = start.elapsed().as_secs_f64() * 1e3;
            let mut lines = vec![format!(
                "{}: animation ({}), {} x {}, {}, {:.1} fps ({:.2} s), loaded in {ms:.1} ms",
                input.display(),
                report.format,
                counted(anim.frame_count(), "frame"),
                counted(anim.vertex_count(), "vertex"),
                counted(anim.triangles.len(), "triangle"),
                anim.frame_rate,
                anim.frame_count() as f64 / f64::from(anim.frame_rate)
            )];
            let (lo, hi) = bounds(anim.frames.iter().flatten());
            let travel = anim
                .frames
                .iter()
                .map(|f| max_distance(&anim.frames[0], f))
                .fold(0.0f32, f32::max);
            lines.push(format!(
                "extent over all frames: {} .. {} (diagonal {:.4}); largest vertex travel from \
                 frame 0: {travel:.4}",
                fmt3(lo),
                fmt3(hi),
                (hi - lo).length()
            ));
            lines.extend(up_axis_hint(hi - lo));
            if let Some(clip) = &report.clip {
                lines.push(format!(
                    "clip {} {:?}: {:.3} s … {:.3} s",
                    clip.index,
                    clip.name.as_deref().unwrap_or(""),
                    clip.start_s,
                    clip.end_s
                ));
            }
            if let (Some(first), Some(last)) =
                (report.frame_files.first(), report.frame_files.last())
            {
                lines.push(format!(
                    "frame files: {} … {}",
                    first.file_name().unwrap_or_default().to_string_lossy(),
                    last.file_name().unwrap_or_default().to_string_lossy()
                ));
            }
            (lines, report)
        } else {
            let (mesh, report) = meshio::load_mesh(input, &meshio::LoadOptions::default())?;
            let ms = start.elapsed().as_secs_f64() * 1e3;
            let (lo, hi) = bounds(mesh.positions.iter());
            let mut lines = vec![
                format!(
                    "{}: mesh ({}), {}, {}, loaded in {ms:.1} ms",
                    input.display(),
                    report.format,
                    counted(mesh.vertex_count(), "vertex"),
                    counted(mesh.triangle_count(), "triangle")
                ),
                format!(
                    "extent: {} .. {} (diagonal {:.4})",
                    fmt3(lo),
                    fmt3(hi),
                    (hi - lo).length()
                ),
            ];
            lines.extend(up_axis_hint(hi - lo));
            (lines, report)
        };
        for line in lines.iter().chain(&report_lines(&report)) {
            writeln!(out, "{line}")?;
        }
        if self.debug {
            writeln!(out, "{report:#?}")?;
        }
        Ok(())
    }
}

/// A note where the extent along Z is at least twice that along X and along Y — the shape of
/// an asset authored Z-up (Blender, CAD exports, the Berkeley garments) standing upright, which
/// the commands would light and frame lying on its side. Only a hint: a Y-up object can be
/// long along Z.
fn up_axis_hint(size: Vec3) -> Option<String> {
    (size.z > 0.0 && size.z >= 2.0 * size.x.max(size.y)).then(|| {
        format!(
            "note: the extent along Z ({:.4}) is over twice that along X ({:.4}) and Y ({:.4}): \
             if the asset stands along Z, pass --up-axis z to visibility, bake, hemicube, \
             shadows, translucency, btf render and view (or rotate it in a scene file: rotation_deg = [-90, 0, \
             0])",
            size.z, size.x, size.y
        )
    })
}

/// The loader's findings as readable lines: attributes, what the file holds that was
/// triangulated, dropped or skipped, and its notes.
fn report_lines(report: &LoadReport) -> Vec<String> {
    let status = AttributeStatus::to_string;
    let mut lines = vec![format!(
        "normals: {}{}; texture coordinates: {}",
        status(&report.file_normals),
        if report.normals_computed {
            " (computed from the triangles)"
        } else if report.file_normals == AttributeStatus::Loaded {
            // The scene path recomputes them in world space, every frame (`WorldObject`).
            " (lighting and visibility use normals computed from the triangles instead, per frame)"
        } else {
            ""
        },
        status(&report.uvs)
    )];
    lines.push(format!(
        "as written: {}, {} ({}, {} fan-triangulated); \
         unreferenced vertices: {}, degenerate triangles: {}, duplicate positions: {}, \
         repeated triangles: {}, back-to-back triangle pairs: {}",
        counted(report.file_vertex_count, "vertex"),
        counted(report.file_face_count, "face"),
        counted(report.file_triangle_count, "triangle"),
        counted(report.polygons_triangulated, "polygon"),
        report.unreferenced_vertices.len(),
        report.degenerate_triangles.len(),
        report.duplicate_positions,
        report.repeated_triangles.repeated,
        report.repeated_triangles.back_to_back
    ));
    if report.removed_triangles + report.removed_vertices > 0 {
        lines.push(format!(
            "removed: {}, {}",
            counted(report.removed_triangles, "triangle"),
            counted(report.removed_vertices, "vertex")
        ));
    }
    if report.topology_missing {
        lines.push(
            "no triangles: a point-cache clip (.npy, .pc2, .mdd) without --topology MESH"
                .to_owned(),
        );
    }
    if !report.skipped_keywords.is_empty() {
        let skipped: Vec<String> = report
            .skipped_keywords
            .iter()
            .map(|(k, n)| format!("{k} ×{n}"))
            .collect();
        lines.push(format!("skipped keywords: {}", skipped.join(", ")));
    }
    if !report.skipped_properties.is_empty() {
        lines.push(format!(
            "skipped properties: {}",
            report.skipped_properties.join(", ")
        ));
    }
    lines.extend(report.notes.iter().map(|n| format!("note: {n}")));
    lines
}

fn bounds<'a>(points: impl Iterator<Item = &'a Vec3>) -> (Vec3, Vec3) {
    points.fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| {
        (lo.min(*p), hi.max(*p))
    })
}

fn max_distance(a: &[Vec3], b: &[Vec3]) -> f32 {
    a.iter()
        .zip(b)
        .map(|(p, q)| p.distance(*q))
        .fold(0.0, f32::max)
}

fn fmt3(v: Vec3) -> String {
    format!("({:.4}, {:.4}, {:.4})", v.x, v.y, v.z)
}

/// `n` and the noun, plural unless n is 1: "1 triangle", "3 vertices".
fn counted(n: usize, noun: &str) -> String {
    match (n, noun) {
        (1, _) => format!("1 {noun}"),
        (_, "vertex") => format!("{n} vertices"),
        _ => format!("{n} {noun}s"),
    }
}
