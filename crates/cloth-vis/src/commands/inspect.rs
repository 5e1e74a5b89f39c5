//! `cloth-vis inspect`: load a mesh or an animation and print what the loader found.

use std::io::Write as _;
use std::path::PathBuf;
use std::time::Instant;

/// Load a mesh or an animation and print what the loader found (counts, quirks, time).
#[derive(clap::Args)]
pub struct InspectArgs {
    /// A mesh (.ply .obj .gltf .glb), an animation (.glb, .npy, a folder of numbered .obj).
    input: PathBuf,
    /// Treat a glTF as an animation (default: static mesh).
    #[arg(long)]
    animation: bool,
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
        if self.animation || input.is_dir() || has_ext("npy") {
            let (anim, report) =
                meshio::load_animation(input, &meshio::AnimationOptions::default())?;
            let ms = start.elapsed().as_secs_f64() * 1e3;
            writeln!(
                out,
                "{}: animation, {} frames x {} vertices, {} triangles, {:.1} fps, loaded in {ms:.1} ms",
                input.display(),
                anim.frame_count(),
                anim.vertex_count(),
                anim.triangles.len(),
                anim.frame_rate
            )?;
            writeln!(out, "{report:#?}")?;
        } else {
            let (mesh, report) = meshio::load_mesh(input, &meshio::LoadOptions::default())?;
            let ms = start.elapsed().as_secs_f64() * 1e3;
            writeln!(
                out,
                "{}: {} vertices, {} triangles, loaded in {ms:.1} ms",
                input.display(),
                mesh.vertex_count(),
                mesh.triangle_count()
            )?;
            writeln!(
                out,
                "unreferenced vertices: {}, degenerate triangles: {}, duplicate positions: {}, normals computed: {}",
                report.unreferenced_vertices.len(),
                report.degenerate_triangles.len(),
                report.duplicate_positions,
                report.normals_computed
            )?;
        }
        Ok(())
    }
}
