//! `cloth-vis render` (a scene file) and `cloth-vis demo` (the embedded demo scene): both run
//! [`cloth_vis::run_scene`] and print the run report's table.

use std::io::Write as _;
use std::path::PathBuf;

use cloth_vis::{RunOptions, Scene};
use render::sequence::FrameRange;

/// Run a scene file: only the effects it names are built; images and a run report go to DIR.
#[derive(clap::Args)]
pub struct RenderArgs {
    /// The scene (TOML).
    scene: PathBuf,
    /// Output folder (created with its parents; built beside and renamed into place when
    /// complete).
    #[arg(long, short = 'o')]
    out: PathBuf,
    /// Replace an output folder that already holds files, once the new one is complete.
    #[arg(long)]
    force: bool,
    /// Render frames A..B of the scene's animated objects to frame-NNNN.png (overrides
    /// `[output] frames`).
    #[arg(long, value_name = "A..B")]
    frames: Option<FrameRange>,
    /// Hide progress bars.
    #[arg(long)]
    quiet: bool,
}

impl RenderArgs {
    /// Load, validate and run the scene.
    pub fn run(self) -> anyhow::Result<()> {
        let scene = Scene::load(&self.scene)?;
        let options = RunOptions {
            progress: !self.quiet,
            frames: self.frames,
            replace_output: self.force,
            ..RunOptions::default()
        };
        let output = cloth_vis::run_scene(&scene, &self.out, &options)?;
        write!(std::io::stdout().lock(), "{}", output.report.table())?;
        Ok(())
    }
}

/// Render the embedded demo scene (synthetic cloth under a procedural sky) into DIR.
#[derive(clap::Args)]
pub struct DemoArgs {
    /// Output folder (created with its parents; built beside and renamed into place when
    /// complete).
    #[arg(long, short = 'o')]
    out: PathBuf,
    /// Replace an output folder that already holds files, once the new one is complete.
    #[arg(long)]
    force: bool,
    /// Render frames A..B of the cloth animation (120 frames: 0..120) to frame-NNNN.png,
    /// with the visibility recomputed per frame.
    #[arg(long, value_name = "A..B")]
    frames: Option<FrameRange>,
    /// Hide progress bars.
    #[arg(long)]
    quiet: bool,
}

impl DemoArgs {
    /// Run the demo scene.
    pub fn run(self) -> anyhow::Result<()> {
        let options = RunOptions {
            progress: !self.quiet,
            frames: self.frames,
            replace_output: self.force,
            ..RunOptions::default()
        };
        let output = cloth_vis::run_demo(&self.out, &options)?;
        write!(std::io::stdout().lock(), "{}", output.report.table())?;
        Ok(())
    }
}
