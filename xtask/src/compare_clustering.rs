//! `cargo xtask compare clustering`: the clustering crate beside scikit-learn on the same data.
//!
//! Runs `cargo run --release -p clustering --example compare` (which writes the benchmark data
//! as `.npy` and its own results), then `xtask/scripts/sklearn_compare.py` in a virtual
//! environment with numpy and scikit-learn (created under `target/sklearn-venv` on first use;
//! scikit-learn is a comparison, not a dependency), which prints the merged table.

use std::path::Path;
use std::process::Command;

use anyhow::{Context, bail};

fn run(cmd: &mut Command) -> anyhow::Result<()> {
    let status = cmd
        .status()
        .with_context(|| format!("cannot start {cmd:?}"))?;
    if !status.success() {
        bail!("{cmd:?} failed with {status}");
    }
    Ok(())
}

/// Run the comparison; `quick` uses one seed instead of five.
pub fn run_comparison(root: &Path, quick: bool) -> anyhow::Result<()> {
    let out = root.join("target/clustering-compare");
    let venv = root.join("target/sklearn-venv");
    let python = venv.join("bin/python");
    if !python.exists() {
        run(Command::new("python3").args(["-m", "venv"]).arg(&venv))?;
        run(Command::new(venv.join("bin/pip")).args([
            "install",
            "--quiet",
            "numpy",
            "scikit-learn",
        ]))?;
    }
    let mut example = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_owned()));
    example
        .current_dir(root)
        .args([
            "run",
            "--release",
            "-p",
            "clustering",
            "--example",
            "compare",
            "--",
        ])
        .arg(&out);
    let mut script = Command::new(&python);
    script
        .arg(root.join("xtask/scripts/sklearn_compare.py"))
        .arg(&out);
    if quick {
        example.arg("--quick");
        script.arg("--quick");
    }
    run(&mut example)?;
    run(&mut script)
}
