//! Helpers shared by the facade's tests.
#![allow(dead_code)]

use std::path::Path;

use cloth_vis::Scene;
use gpu_context::{GpuContext, GpuOptions};

/// A scene from TOML text with paths relative to `base`.
#[track_caller]
pub fn scene(text: &str, base: &Path) -> Scene {
    match Scene::from_toml(text, base, "test scene") {
        Ok(s) => s,
        Err(e) => panic!("test scene does not parse: {e}"),
    }
}

/// A GPU context, or `None` after the project's skip policy (fails under CI).
pub fn gpu_available() -> bool {
    match GpuContext::new(&GpuOptions::default()) {
        Ok(_) => true,
        Err(e) => test_data::skip::<()>(&format!("no GPU adapter: {e}")).is_some(),
    }
}

/// Small procedural settings so end-to-end runs stay quick in tests.
pub const SMALL_SYNTH: &str = r#"
[synth]
cloth_grid = 24
cloth_frames = 40
seed = 3
sky_width = 256
"#;

/// Runs the `cloth-vis` binary with `args`.
pub fn cli(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_cloth-vis"))
        .args(args)
        .output()
        .unwrap()
}

/// A path as a command-line argument.
pub fn text(p: &Path) -> &str {
    p.to_str().unwrap()
}
