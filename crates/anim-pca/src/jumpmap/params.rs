//! The parameters of the jump-map analysis (thesis §3.2.2, eqs. 3.3–3.8) and their checks.

use super::analysis::WHAT;
#[cfg(doc)]
use super::analysis::{Clip, JumpMap};
use crate::error::{Result, invalid};

/// Parameters of the analysis (thesis §3.2.2). Defaults are the thesis's figures: c = 10,
/// c* = 5, σ = σ* = 0.05 (its avatar value), q = q* = 0 (eq. 3.7, both coherences count fully).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JumpMapParams {
    /// c: PCA components of the frame vectors A_i (eq. 3.1). At least 1; a clip of lower rank
    /// gets fewer (see [`JumpMap::components`]).
    pub components: usize,
    /// c*: PCA components of the central velocities (eq. 3.4–3.5). At least 1 (use
    /// `q_velocity = 1` to ignore velocity coherence).
    pub velocity_components: usize,
    /// σ of eq. 3.3, in units of the mean off-diagonal distance (> 0; +∞ allowed: uniform).
    ///
    /// The unit is a typical distance between *any* two frames. On a clip with global motion
    /// (a walk that crosses the scene) that is many frame steps, so the same σ admits coarser
    /// jumps than on a cycle in place: the chicken crossing needs σ ≈ 0.01 for jumps below
    /// 2 d̄, the horse gallop is clean at 0.05.
    pub sigma: f64,
    /// σ* of eq. 3.6, in units of the mean off-diagonal velocity distance (> 0; +∞ allowed).
    pub sigma_velocity: f64,
    /// q ∈ [0, 1] of eq. 3.8: base probability of the position term (1 ignores positions).
    pub q: f64,
    /// q* ∈ [0, 1] of eq. 3.8: base probability of the velocity term (1 ignores velocities).
    pub q_velocity: f64,
    /// Weight of the normals in A_i relative to the positions, for
    /// [`JumpMap::analyze_with_normals`]: the normals are scaled so that their total variance
    /// is `normal_weight²` times that of the positions (≥ 0, finite).
    pub normal_weight: f64,
    /// Components of the separate attribute PCA (R_i, [`Clip::with_attributes`]); ≥ 1.
    pub attribute_components: usize,
    /// Whether the clip's travel through the scene is analysed with the shape or taken out
    /// first (see [`RootMotion`]).
    pub root_motion: RootMotion,
}

/// What to do with a clip's global translation (its *root motion*).
///
/// The thesis's sequences move in place. A clip that travels (a walk across a room) never
/// returns to an earlier position, so no frame resembles a frame a period earlier and the jump
/// map finds almost nothing: D measures where the body is, not what it does. Extracting the root motion analyses the *shape* — every frame moved so that
/// its vertex centroid is at the origin — and plays the travel back by integrating the
/// clip's own centroid velocities along the generated frames ([`JumpMap::root_offsets`]), as
/// game engines do with root motion.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum RootMotion {
    /// Analyse positions as given (the thesis's method).
    #[default]
    Keep,
    /// Remove each frame's vertex centroid before the analysis and replay it as integrated
    /// velocity.
    Extract,
}

impl Default for JumpMapParams {
    fn default() -> Self {
        Self {
            components: 10,
            velocity_components: 5,
            sigma: 0.05,
            sigma_velocity: 0.05,
            q: 0.0,
            q_velocity: 0.0,
            normal_weight: 1.0,
            attribute_components: 4,
            root_motion: RootMotion::Keep,
        }
    }
}

impl JumpMapParams {
    pub(super) fn validate(&self) -> Result<()> {
        if self.components == 0 {
            return Err(invalid(WHAT, "components", 0, "c must be ≥ 1 (eq. 3.1)"));
        }
        if self.velocity_components == 0 {
            return Err(invalid(
                WHAT,
                "velocity_components",
                0,
                "c* must be ≥ 1; to ignore velocities set q_velocity = 1",
            ));
        }
        if self.attribute_components == 0 {
            return Err(invalid(
                WHAT,
                "attribute_components",
                0,
                "the attribute PCA needs ≥ 1 component",
            ));
        }
        for (name, s) in [
            ("sigma", self.sigma),
            ("sigma_velocity", self.sigma_velocity),
        ] {
            if s.is_nan() || s <= 0.0 {
                return Err(invalid(
                    WHAT,
                    name,
                    s,
                    "σ must be > 0 (+∞ gives uniform rows)",
                ));
            }
        }
        for (name, q) in [("q", self.q), ("q_velocity", self.q_velocity)] {
            if !(0.0..=1.0).contains(&q) {
                return Err(invalid(WHAT, name, q, "q must lie in [0, 1] (eq. 3.8)"));
            }
        }
        if !(self.normal_weight.is_finite() && self.normal_weight >= 0.0) {
            return Err(invalid(
                WHAT,
                "normal_weight",
                self.normal_weight,
                "the normal weight must be finite and ≥ 0",
            ));
        }
        Ok(())
    }
}
