//! `cargo xtask compare translucency`: seed 004's model (the `translucency` effect) against
//! Mitsuba 3's volumetric path tracer on the bunny and the dragon of `../shared/data` — the
//! same camera, point light and medium (skin1) — with plain diffuse shading's error beside it.
//!
//! Mitsuba is a comparison, not a dependency: it is installed with numpy and Pillow into a
//! virtual environment under `target/mitsuba-venv` on first use. The script
//! (`xtask/scripts/mitsuba_translucency.py`) writes the scenes, runs the release `cloth-vis`
//! binary and Mitsuba, prints the table and writes the pictures to
//! `target/translucency-compare/`. `--quick` (CI) renders the 1,000-triangle bunny at 96²
//! with 32 samples per pixel; `--cloth-vis PATH` uses a binary already built (CI's test
//! profile) instead of building the release one.

use std::path::Path;
use std::process::Command;

use anyhow::bail;

use crate::python::{run, venv};

/// Run the comparison with the `cloth-vis` binary at `binary` (built in release when `None`).
pub fn run_comparison(root: &Path, quick: bool, binary: Option<&Path>) -> anyhow::Result<()> {
    let data = root.join("../shared/data");
    if !data.join("meshes/bun_zipper.ply").is_file() {
        bail!(
            "{} holds no meshes/bun_zipper.ply: the comparison renders the shared data",
            data.display()
        );
    }
    let python = venv(
        root,
        "mitsuba-venv",
        &[
            ("mitsuba", "mitsuba==3.*"),
            ("numpy", "numpy"),
            ("PIL", "pillow"),
        ],
    )?;
    let binary = match binary {
        Some(path) => path.to_owned(),
        None => {
            let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_owned());
            run(Command::new(&cargo).current_dir(root).args([
                "build",
                "--release",
                "-p",
                "cloth-vis",
            ]))?;
            root.join("target/release/cloth-vis")
        }
    };
    if !binary.is_file() {
        bail!("{}: no cloth-vis binary there", binary.display());
    }
    let mut script = Command::new(&python);
    script
        .arg(root.join("xtask/scripts/mitsuba_translucency.py"))
        .arg(&binary)
        .arg(root.join("target/translucency-compare"))
        .arg(&data);
    if quick {
        script.arg("--quick");
    }
    run(&mut script)
}
