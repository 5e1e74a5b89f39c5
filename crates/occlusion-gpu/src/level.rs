//! The adaptive lightsphere level (paper 000 §4.2, "Changing the Lightsphere configuration").
//!
//! > "While the scene is animated or objects are deformed, we can decrease the number of light
//! > directions. In idle time, in order to converge to the exact solution, we increase that
//! > count […]. In our experience a level of s = 3 and often even level s = 2 produces
//! > reasonable results. The algorithm allows user control through the choice of a desired
//! > frame rate or a certain configuration." (§4.2)
//!
//! Policy of [`LevelController`] (deterministic given the times fed in):
//! * **Animating** ([`LevelController::record_frame`], one call per frame with the measured
//!   visibility time t at the current level s). The cost is predicted proportional to the
//!   direction count: t(s') = t · k(s') / k(s), k(s) = 2 + 4^(s+1).
//!   - *Drop* at once when t > target: to the finest level s' < s whose predicted time fits
//!     the target (at least one level, at most down to `min_level`).
//!   - *Rise* one level when the predicted time at s + 1 is ≤ `rise_fraction` × target for
//!     `rise_after_frames` consecutive frames (at most up to `max_level`).
//!   - Otherwise stay. The gap between the drop test (t > target) and the rise test (t(s+1) ≤
//!     `rise_fraction` × target < target) is the hysteresis: a rise predicted to fit with margin
//!     is not undone by the next frame unless the time itself grew, and a constant time series
//!     moves monotonically to one level and stays there.
//! * **Idle** ([`LevelController::refine_idle`], the caller says the scene is static): one
//!   level finer per call up to `max_idle_level` with [`VisibilityEngine::refine`], which
//!   computes only the new directions (the lightsphere is nested, §3.4). The animated level is
//!   untouched, so animation resumes at the level that fitted the budget.

use std::time::Duration;

use lightsphere::{Lightsphere, MAX_LEVEL, direction_count};

use crate::filter::camera::invalid;
use crate::{OcclusionError, Scene, VisibilityEngine, VisibilityMatrix};

/// Default `rise_fraction`: rise only when the finer level is predicted to take ≤ 80% of the
/// budget (20% margin for timing noise; one level is ×≈4 the cost, so a rise from a level
/// that runs at ≤ 20% of the budget).
pub const DEFAULT_RISE_FRACTION: f64 = 0.8;
/// Default `rise_after_frames`: three consecutive fast frames before a rise, so one quiet frame
/// does not trigger it.
pub const DEFAULT_RISE_AFTER_FRAMES: u32 = 3;
/// Default coarsest level (k = 6).
pub const DEFAULT_MIN_LEVEL: u32 = 0;
/// Default finest level while animating: s = 3 (k = 258), the seed's "reasonable results".
pub const DEFAULT_MAX_LEVEL: u32 = 3;
/// Default finest level reached in idle time: s = 4 (k = 1026), the seed's largest in Table 1.
pub const DEFAULT_MAX_IDLE_LEVEL: u32 = 4;

/// Knobs of [`LevelController`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct LevelParams {
    /// The visibility time allowed per animated frame.
    pub target_frame_time: Duration,
    /// Coarsest level.
    pub min_level: u32,
    /// Finest level while animating.
    pub max_level: u32,
    /// Finest level reached by idle refinement (≥ `max_level`).
    pub max_idle_level: u32,
    /// Rise when the predicted time at the next level is ≤ this × target (in (0, 1]).
    pub rise_fraction: f64,
    /// Consecutive frames the rise test must pass (≥ 1).
    pub rise_after_frames: u32,
}

impl LevelParams {
    /// The defaults for a target visibility time per frame.
    pub fn new(target_frame_time: Duration) -> Self {
        Self {
            target_frame_time,
            min_level: DEFAULT_MIN_LEVEL,
            max_level: DEFAULT_MAX_LEVEL,
            max_idle_level: DEFAULT_MAX_IDLE_LEVEL,
            rise_fraction: DEFAULT_RISE_FRACTION,
            rise_after_frames: DEFAULT_RISE_AFTER_FRAMES,
        }
    }

    /// The same parameters with other level bounds.
    pub fn with_levels(mut self, min_level: u32, max_level: u32, max_idle_level: u32) -> Self {
        self.min_level = min_level;
        self.max_level = max_level;
        self.max_idle_level = max_idle_level;
        self
    }

    /// The same parameters with another hysteresis.
    pub fn with_rise(mut self, rise_fraction: f64, rise_after_frames: u32) -> Self {
        self.rise_fraction = rise_fraction;
        self.rise_after_frames = rise_after_frames;
        self
    }
}

/// What [`LevelController::record_frame`] decided.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LevelChange {
    /// Keep the level.
    Stay,
    /// Coarser: the frame was over budget.
    Drop {
        /// Level of the measured frame.
        from: u32,
        /// Level of the next frame.
        to: u32,
    },
    /// One level finer: frames were well under budget.
    Rise {
        /// Level of the measured frame.
        from: u32,
        /// Level of the next frame.
        to: u32,
    },
}

/// Picks the lightsphere level per animated frame from measured times, and refines in idle
/// time (see the module docs for the policy).
#[derive(Clone, Debug)]
pub struct LevelController {
    params: LevelParams,
    level: u32,
    fast_frames: u32,
}

impl LevelController {
    /// A controller starting at `initial_level`.
    ///
    /// # Errors
    /// [`OcclusionError::InvalidParameter`] unless target > 0, `min_level` ≤ `initial_level` ≤
    /// `max_level` ≤ `max_idle_level` ≤ [`lightsphere::MAX_LEVEL`], `rise_fraction` ∈ (0, 1]
    /// and `rise_after_frames` ≥ 1.
    pub fn new(params: LevelParams, initial_level: u32) -> Result<Self, OcclusionError> {
        let p = &params;
        if p.target_frame_time.is_zero() {
            return Err(invalid("target_frame_time (s)", 0.0, "positive"));
        }
        let checks = [
            (
                "min_level",
                p.min_level,
                p.min_level <= initial_level,
                "≤ the initial level",
            ),
            (
                "initial level",
                initial_level,
                initial_level <= p.max_level,
                "≤ max_level",
            ),
            (
                "max_level",
                p.max_level,
                p.max_level <= p.max_idle_level,
                "≤ max_idle_level",
            ),
            (
                "max_idle_level",
                p.max_idle_level,
                p.max_idle_level <= MAX_LEVEL,
                "≤ 8",
            ),
            (
                "rise_after_frames",
                p.rise_after_frames,
                p.rise_after_frames >= 1,
                "≥ 1",
            ),
        ];
        if let Some(&(what, value, _, expected)) = checks.iter().find(|c| !c.2) {
            return Err(invalid(what, value.into(), expected));
        }
        if !(p.rise_fraction > 0.0 && p.rise_fraction <= 1.0) {
            return Err(invalid("rise_fraction", p.rise_fraction, "in (0, 1]"));
        }
        Ok(Self {
            params,
            level: initial_level,
            fast_frames: 0,
        })
    }

    /// The parameters.
    pub fn params(&self) -> &LevelParams {
        &self.params
    }

    /// The level for the next animated frame.
    pub fn level(&self) -> u32 {
        self.level
    }

    /// The lightsphere of [`LevelController::level`].
    ///
    /// # Errors
    /// Never for a validated level; a lightsphere error is reported as
    /// [`OcclusionError::InvalidParameter`].
    pub fn sphere(&self) -> Result<Lightsphere, OcclusionError> {
        sphere(self.level)
    }

    /// The predicted time at level `to` of a frame measured at `measured` on level `from`:
    /// cost ∝ k (`measured` × k(to) / k(from)).
    pub fn predict(measured: Duration, from: u32, to: u32) -> Duration {
        let ratio = direction_count(to) as f64 / direction_count(from) as f64;
        Duration::from_secs_f64(measured.as_secs_f64() * ratio)
    }

    /// Records the visibility time of a frame computed at [`LevelController::level`] and
    /// picks the next frame's level.
    pub fn record_frame(&mut self, measured: Duration) -> LevelChange {
        let (from, target) = (self.level, self.params.target_frame_time);
        if measured > target {
            self.fast_frames = 0;
            if from == self.params.min_level {
                return LevelChange::Stay;
            }
            let to = (self.params.min_level..from)
                .rev()
                .find(|&s| Self::predict(measured, from, s) <= target)
                .unwrap_or(self.params.min_level);
            self.level = to;
            return LevelChange::Drop { from, to };
        }
        let fits_finer = from < self.params.max_level
            && Self::predict(measured, from, from + 1).as_secs_f64()
                <= self.params.rise_fraction * target.as_secs_f64();
        if !fits_finer {
            self.fast_frames = 0;
            return LevelChange::Stay;
        }
        self.fast_frames += 1;
        if self.fast_frames < self.params.rise_after_frames {
            return LevelChange::Stay;
        }
        self.fast_frames = 0;
        self.level = from + 1;
        LevelChange::Rise {
            from,
            to: self.level,
        }
    }

    /// Idle time: refines `matrix` (of a default-rotation lightsphere level) one level, up to
    /// `max_idle_level`, computing only the new directions. Returns the new level, or `None`
    /// when it is already at (or above) the maximum.
    ///
    /// # Errors
    /// [`OcclusionError::NotARefinement`] when the matrix's directions are not a
    /// [`Lightsphere::new`] level, and the errors of [`VisibilityEngine::refine`].
    pub fn refine_idle(
        &self,
        engine: &mut VisibilityEngine,
        scene: &Scene,
        matrix: &mut VisibilityMatrix,
    ) -> Result<Option<u32>, OcclusionError> {
        let k = matrix.directions_len();
        let Some(level) = (0..=MAX_LEVEL).find(|&s| direction_count(s) == k) else {
            return Err(OcclusionError::NotARefinement {
                have: k,
                requested: k,
            });
        };
        if level >= self.params.max_idle_level {
            return Ok(None);
        }
        engine.refine(scene, matrix, &sphere(level + 1)?)?;
        Ok(Some(level + 1))
    }
}

fn sphere(level: u32) -> Result<Lightsphere, OcclusionError> {
    Lightsphere::new(level).map_err(|_| invalid("lightsphere level", level.into(), "≤ 8"))
}
