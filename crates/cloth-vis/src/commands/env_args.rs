//! The environment flags `visibility` and `bake` share: `--env`/`--sky`, `--env-rotation`,
//! `--up-axis` (one definition, flattened into each command's flags).

use std::path::PathBuf;

use cloth_vis::Error;

use super::up_axis::UpAxis;
use super::visibility::{load_environment, turned_environment};

/// `--env FILE | --sky`, `--env-rotation DEG`, `--up-axis AXIS`.
#[derive(Clone, Debug, clap::Args)]
pub struct EnvironmentArgs {
    /// HDR environment (.hdr/.exr) lighting a white Lambertian surface: the colours and
    /// `--render` of `visibility`, `_RADIANCE` of `bake` (without --env or --sky: the grey
    /// ambient term a_i alone).
    #[arg(long, conflicts_with = "sky")]
    pub env: Option<PathBuf>,
    /// Use the procedural sky as the environment (see --env).
    #[arg(long)]
    pub sky: bool,
    /// Rotate the environment by DEG degrees about the up axis relative to the object (rotated
    /// look-ups of I_j; M is not recomputed).
    #[arg(
        long,
        value_name = "DEG",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    pub env_rotation: f32,
    /// The input's up axis: the environment's zenith and the render camera's up turn onto it
    /// (z for Blender/CAD exports); the outputs stay in the input's frame.
    #[arg(long, value_enum, default_value = "y", allow_hyphen_values = true)]
    pub up_axis: UpAxis,
}

impl EnvironmentArgs {
    /// The environment as loaded (`None` without `--env` or `--sky`), not yet turned.
    ///
    /// # Errors
    /// Reading or decoding the map, naming the file.
    pub fn load(&self) -> Result<Option<lightsphere::Environment>, Error> {
        load_environment(self.env.as_deref(), self.sky)
    }

    /// The environment turned by `--env-rotation` about +Y, then with its zenith onto
    /// `--up-axis`.
    ///
    /// # Errors
    /// As [`EnvironmentArgs::load`].
    pub fn load_turned(&self) -> Result<Option<lightsphere::Environment>, Error> {
        Ok(self
            .load()?
            .map(|env| turned_environment(env, self.up_axis, self.env_rotation)))
    }
}
