//! Helpers of the subcommand tests.

use std::path::{Path, PathBuf};

/// The `cloth-vis` executable cargo built beside this test executable (`target/<profile>/`
/// holds it, `target/<profile>/deps/` this test; the way `assert_cmd::cargo_bin` finds it).
/// Cargo builds the binary for the package's integration tests before any test runs.
pub fn binary() -> PathBuf {
    let exe = std::env::current_exe().expect("the test executable has a path");
    let profile_dir = exe
        .parent()
        .and_then(Path::parent)
        .expect("test executables live in target/<profile>/deps");
    let path = profile_dir.join(format!("cloth-vis{}", std::env::consts::EXE_SUFFIX));
    assert!(
        path.is_file(),
        "{} is missing: run the tests with `cargo test -p cloth-vis`, which builds it",
        path.display()
    );
    path
}

/// Runs the `cloth-vis` binary with `args`.
pub fn cli(args: &[&str]) -> std::process::Output {
    std::process::Command::new(binary())
        .args(args)
        .output()
        .unwrap()
}

/// Runs the `cloth-vis` binary with `args` and the environment variables `envs` set.
pub fn cli_env(args: &[&str], envs: &[(&str, &str)]) -> std::process::Output {
    std::process::Command::new(binary())
        .args(args)
        .envs(envs.iter().copied())
        .output()
        .unwrap()
}

/// A path as a command-line argument.
pub fn text(p: &Path) -> &str {
    p.to_str().unwrap()
}
