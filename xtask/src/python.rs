//! The Python peers (scikit-learn, Mitsuba 3, Open3D) run from virtual environments under
//! `target/`: comparisons, not dependencies. One venv may serve several commands
//! (`target/mitsuba-venv`: `compare translucency` and `bench visibility`), so each command
//! names the modules it imports and whatever is missing is installed, not only on creation.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, bail};

/// Runs `cmd`, failing with the command line when it cannot start or exits non-zero.
pub fn run(cmd: &mut Command) -> anyhow::Result<()> {
    let status = cmd
        .status()
        .with_context(|| format!("cannot start {cmd:?}"))?;
    if !status.success() {
        bail!("{cmd:?} failed with {status}");
    }
    Ok(())
}

/// The interpreter of the venv `target/NAME` under `root`, created on first use, with each
/// `(module, pip package)` installed where `import module` fails.
pub fn venv(root: &Path, name: &str, packages: &[(&str, &str)]) -> anyhow::Result<PathBuf> {
    let venv = root.join("target").join(name);
    let python = venv.join("bin/python");
    if !python.exists() {
        run(Command::new("python3").args(["-m", "venv"]).arg(&venv))?;
    }
    for (module, package) in packages {
        let present = Command::new(&python)
            .args(["-c", &format!("import {module}")])
            .status()
            .is_ok_and(|s| s.success());
        if !present {
            run(Command::new(venv.join("bin/pip")).args(["install", "--quiet", package]))?;
        }
    }
    Ok(python)
}
