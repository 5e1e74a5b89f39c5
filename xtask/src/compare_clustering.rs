//! `cargo xtask compare clustering`: the clustering crate beside scikit-learn on the same data.
//!
//! Runs `cargo run --release -p clustering --example compare` (which writes the benchmark data
//! as `.npy` and its own results), then `xtask/scripts/sklearn_compare.py` in a virtual
//! environment with numpy and scikit-learn (created under `target/sklearn-venv` on first use;
//! scikit-learn is a comparison, not a dependency), which prints the merged table.

use std::path::Path;
use std::process::Command;

use crate::python::{run, venv};

/// Run the comparison; `quick` uses one seed instead of five.
pub fn run_comparison(root: &Path, quick: bool) -> anyhow::Result<()> {
    let out = root.join("target/clustering-compare");
    let python = venv(
        root,
        "sklearn-venv",
        &[("numpy", "numpy"), ("sklearn", "scikit-learn")],
    )?;
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
