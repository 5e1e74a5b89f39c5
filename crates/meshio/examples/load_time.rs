//! Times loading a mesh or animation: `cargo run --release -p meshio --example load_time -- PATH [RUNS]`.
//!
//! A folder or `.npy`/`.glb` path is loaded as an animation, anything else as a mesh. Prints
//! every run's wall time and the median.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result};

fn main() -> Result<()> {
    let mut args = std::env::args().skip(1);
    let path = PathBuf::from(args.next().context("usage: load_time PATH [RUNS]")?);
    let runs: usize = args
        .next()
        .map(|r| r.parse())
        .transpose()
        .context("RUNS must be an integer")?
        .unwrap_or(7);
    let as_animation = path.is_dir()
        || path
            .extension()
            .is_some_and(|e| e == "npy" || e == "glb" || e == "gltf");
    let mut times_ms = Vec::with_capacity(runs);
    for run in 0..runs.max(1) {
        let start = Instant::now();
        let summary = if as_animation {
            let (animation, _) =
                meshio::load_animation(&path, &meshio::AnimationOptions::default())?;
            format!(
                "{} frames × {} vertices, {} triangles",
                animation.frame_count(),
                animation.vertex_count(),
                animation.triangles.len()
            )
        } else {
            let (mesh, _) = meshio::load_mesh(&path, &meshio::LoadOptions::default())?;
            format!(
                "{} vertices, {} triangles",
                mesh.vertex_count(),
                mesh.triangle_count()
            )
        };
        let ms = start.elapsed().as_secs_f64() * 1e3;
        println!("run {run}: {ms:.2} ms ({summary})");
        times_ms.push(ms);
    }
    times_ms.sort_by(f64::total_cmp);
    println!(
        "median of {}: {:.2} ms",
        times_ms.len(),
        times_ms[times_ms.len() / 2]
    );
    Ok(())
}
