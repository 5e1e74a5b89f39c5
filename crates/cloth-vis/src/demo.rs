//! `cloth-vis demo`: an embedded scene run end to end on embedded defaults only.

use std::path::Path;

use crate::{Error, RunOptions, RunOutput, Scene, run_scene};

/// The embedded demo scene (TOML).
pub const DEMO_SCENE: &str = include_str!("demo.toml");

/// The demo scene, parsed.
///
/// # Errors
/// Only if the embedded text is broken (a bug caught by the crate's tests).
pub fn demo_scene() -> Result<Scene, Error> {
    Scene::from_toml(DEMO_SCENE, Path::new("."), "embedded demo scene")
}

/// Run the demo, writing `demo.png`, `demo.exr`, `btf.png` (the cloth with the synthetic BTF
/// beside plain texturing) and the run report into `out_dir`.
///
/// # Errors
/// As [`run_scene`]; without a GPU adapter the error says what to install.
pub fn run_demo(out_dir: &Path, options: &RunOptions) -> Result<RunOutput, Error> {
    run_scene(&demo_scene()?, out_dir, options)
}
