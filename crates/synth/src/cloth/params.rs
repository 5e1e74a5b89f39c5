//! Parameters of the drape simulation and their validation.

use crate::error::{Result, SynthError, check_finite3, check_range};
use glam::Vec3;

/// Largest accepted grid side (4 Mi vertices), far above any interactive use.
pub const MAX_GRID: usize = 2048;
/// Largest accepted `frames × grid²` (1.5 GiB of `Vec3` output).
pub const MAX_POSITIONS: u128 = 1 << 27;
/// Largest accepted substep count per frame.
pub const MAX_SUBSTEPS: usize = 10_000;
/// Largest accepted self-collision distance, in grid spacings: larger values would make
/// the neighbour lists of the spatial hash overflow.
pub const MAX_SELF_COLLISION_DISTANCE: f32 = 2.0;

/// What the cloth falls onto.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Obstacle {
    /// A solid sphere.
    Sphere {
        /// Centre in world space (metres).
        centre: Vec3,
        /// Radius in metres (> 0).
        radius: f32,
    },
}

impl Obstacle {
    /// The point the simulation's local frame is centred on (the sphere's centre).
    pub fn anchor(&self) -> Vec3 {
        match *self {
            Obstacle::Sphere { centre, .. } => centre,
        }
    }

    /// Height of the obstacle's top above its anchor (the sphere's radius).
    pub fn top_above_anchor(&self) -> f32 {
        match *self {
            Obstacle::Sphere { radius, .. } => radius,
        }
    }
}

/// Tuning knobs of [`simulate_cloth`](crate::simulate_cloth).
///
/// All lengths are metres, times seconds, masses kilograms. The defaults drop a 2 m × 2 m
/// cloth of 66 × 66 vertices from 0.25 m above a 1 m-diameter ball standing on the ground;
/// after 4 s (120 frames at 30 fps) it hangs over the ball in irregular folds, its corners
/// on the ground.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClothParams {
    /// Vertices per side of the square grid (≥ 2; default 66 → 4,356 vertices).
    pub grid: usize,
    /// Side length of the cloth (default 2 m).
    pub size: f32,
    /// Frames to output, including the initial frame (≥ 1; default 120).
    pub frames: usize,
    /// Frames per second (default 30).
    pub frame_rate: f32,
    /// XPBD substeps per frame, one constraint iteration each (default 24, i.e. Δt = 1/720 s
    /// at 30 fps: settled edges stay within ~10% of their rest length, ~0.5% on average).
    pub substeps: usize,
    /// Compliance (inverse stiffness, m/N) of the edge-length constraints; 0 = inextensible
    /// (default 0).
    pub stretch_compliance: f32,
    /// Compliance (1/(N·m)) of the isometric bending constraints (default 3·10⁴: a soft,
    /// silk-like cloth that folds; 10³ gives stiff, paper-like drapes, 10⁵ crumples).
    pub bend_compliance: f32,
    /// Coulomb friction coefficient against the obstacle and the ground (default 0.5).
    pub friction: f32,
    /// Linear velocity damping in 1/s, a stand-in for air drag (default 0.3).
    pub damping: f32,
    /// Mass per area in kg/m² (default 0.2, a cotton sheet).
    pub areal_density: f32,
    /// Gravity in m/s² (default −9.81 ŷ).
    pub gravity: Vec3,
    /// The obstacle (default: a sphere of radius 0.5 m centred at (0, 0.5, 0)).
    pub obstacle: Obstacle,
    /// World y of a ground plane, or `None` for no ground (default `Some(0.0)`).
    pub ground_height: Option<f32>,
    /// Initial height of the cloth above the obstacle's top (default 0.25 m). Negative
    /// values start the cloth intersecting the obstacle; it is pushed out before frame 0.
    pub drop_height: f32,
    /// Distance kept between the cloth and the obstacle or ground (default 0.008 m).
    pub collision_margin: f32,
    /// Distance kept between non-adjacent cloth vertices, in grid spacings; 0 disables
    /// self-collision (default 0.9).
    pub self_collision_distance: f32,
    /// Seed of the symmetry-breaking perturbation (yaw, tilt, offset, jitter).
    pub seed: u64,
}

impl Default for ClothParams {
    fn default() -> Self {
        Self {
            grid: 66,
            size: 2.0,
            frames: 120,
            frame_rate: 30.0,
            substeps: 24,
            stretch_compliance: 0.0,
            bend_compliance: 3.0e4,
            friction: 0.5,
            damping: 0.3,
            areal_density: 0.2,
            gravity: Vec3::new(0.0, -9.81, 0.0),
            obstacle: Obstacle::Sphere {
                centre: Vec3::new(0.0, 0.5, 0.0),
                radius: 0.5,
            },
            ground_height: Some(0.0),
            drop_height: 0.25,
            collision_margin: 0.008,
            self_collision_distance: 0.9,
            seed: 1,
        }
    }
}

impl ClothParams {
    /// Distance between neighbouring vertices in the rest state.
    pub fn spacing(&self) -> f32 {
        self.size / (self.grid.max(2) - 1) as f32
    }

    /// Checks every field.
    ///
    /// # Errors
    /// [`SynthError::InvalidParameter`] naming the first offending field, or
    /// [`SynthError::TooLarge`] when `grid` exceeds [`MAX_GRID`] or `frames × grid²`
    /// exceeds [`MAX_POSITIONS`].
    pub fn validate(&self) -> Result<()> {
        let count = |field, value: usize, min: usize, max: usize, expected| {
            if (min..=max).contains(&value) {
                Ok(())
            } else {
                Err(SynthError::InvalidParameter {
                    field,
                    value: value as f64,
                    expected,
                })
            }
        };
        count(
            "ClothParams::grid",
            self.grid,
            2,
            usize::MAX,
            "at least 2 vertices per side",
        )?;
        if self.grid > MAX_GRID {
            return Err(SynthError::TooLarge {
                field: "ClothParams::grid",
                requested: self.grid as u128,
                maximum: MAX_GRID as u128,
                unit: "vertices per side",
            });
        }
        count(
            "ClothParams::frames",
            self.frames,
            1,
            usize::MAX,
            "at least 1 frame",
        )?;
        let positions = self.frames as u128 * (self.grid * self.grid) as u128;
        if positions > MAX_POSITIONS {
            return Err(SynthError::TooLarge {
                field: "ClothParams::frames × grid²",
                requested: positions,
                maximum: MAX_POSITIONS,
                unit: "vertex positions",
            });
        }
        count(
            "ClothParams::substeps",
            self.substeps,
            1,
            MAX_SUBSTEPS,
            "1 ..= 10000",
        )?;
        let pos = "a finite value > 0";
        let non_neg = "a finite value ≥ 0";
        check_range(
            "ClothParams::size",
            self.size,
            f32::MIN_POSITIVE,
            f32::MAX,
            pos,
        )?;
        check_range(
            "ClothParams::frame_rate",
            self.frame_rate,
            1e-3,
            1e6,
            "0.001 ..= 1e6 fps",
        )?;
        check_range(
            "ClothParams::stretch_compliance",
            self.stretch_compliance,
            0.0,
            f32::MAX,
            non_neg,
        )?;
        check_range(
            "ClothParams::bend_compliance",
            self.bend_compliance,
            0.0,
            f32::MAX,
            non_neg,
        )?;
        check_range(
            "ClothParams::friction",
            self.friction,
            0.0,
            f32::MAX,
            non_neg,
        )?;
        check_range("ClothParams::damping", self.damping, 0.0, f32::MAX, non_neg)?;
        check_range(
            "ClothParams::areal_density",
            self.areal_density,
            1e-9,
            1e9,
            "1e-9 ..= 1e9 kg/m²",
        )?;
        check_finite3("ClothParams::gravity", self.gravity)?;
        match self.obstacle {
            Obstacle::Sphere { centre, radius } => {
                check_finite3("ClothParams::obstacle (sphere centre)", centre)?;
                check_range(
                    "ClothParams::obstacle (sphere radius)",
                    radius,
                    f32::MIN_POSITIVE,
                    f32::MAX,
                    pos,
                )?;
            }
        }
        if let Some(ground) = self.ground_height {
            check_range(
                "ClothParams::ground_height",
                ground,
                f32::MIN,
                f32::MAX,
                "a finite height",
            )?;
        }
        check_range(
            "ClothParams::drop_height",
            self.drop_height,
            f32::MIN,
            f32::MAX,
            "a finite height",
        )?;
        check_range(
            "ClothParams::collision_margin",
            self.collision_margin,
            0.0,
            f32::MAX,
            non_neg,
        )?;
        check_range(
            "ClothParams::self_collision_distance",
            self.self_collision_distance,
            0.0,
            MAX_SELF_COLLISION_DISTANCE,
            "0 ..= 2 grid spacings",
        )?;
        Ok(())
    }
}
