//! Lights that cast volumes: a point (position) or a directional light (unit vector *towards*
//! the light), in f64 so that a caster 1e5 away from the origin keeps its facing tests exact.

use glam::DVec3;

use crate::ShadowError;

/// A light that casts hard shadows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// A point light at a world-space position.
    Point(DVec3),
    /// A directional light; the vector points from the scene *towards* the light (the sun's
    /// direction), normalised by [`Light::validated`].
    Directional(DVec3),
}

impl Light {
    /// The light with a finite position or a finite, non-zero direction (normalised).
    ///
    /// # Errors
    /// [`ShadowError::Light`] naming the value.
    pub fn validated(self) -> Result<Self, ShadowError> {
        match self {
            Self::Point(p) if p.is_finite() => Ok(self),
            Self::Point(p) => Err(ShadowError::Light(format!(
                "point light position {p} is not finite"
            ))),
            Self::Directional(d) if d.is_finite() && d.length_squared() > 0.0 => {
                Ok(Self::Directional(d.normalize()))
            }
            Self::Directional(d) => Err(ShadowError::Light(format!(
                "light direction {d} must be finite and non-zero"
            ))),
        }
    }

    /// Unit vector from `p` towards the light (zero when `p` is the point light itself).
    pub fn towards(&self, p: DVec3) -> DVec3 {
        match *self {
            Self::Point(l) => (l - p).normalize_or_zero(),
            Self::Directional(d) => d,
        }
    }

    /// The vector from `p` to the light: `L − p` for a point light (its length is the
    /// distance), the unit direction for a directional light (the light is at infinity).
    pub fn to_light(&self, p: DVec3) -> DVec3 {
        match *self {
            Self::Point(l) => l - p,
            Self::Directional(d) => d,
        }
    }

    /// The same light seen from coordinates whose origin is `origin` (a point light moves, a
    /// direction does not).
    pub fn relative_to(&self, origin: DVec3) -> Self {
        match *self {
            Self::Point(l) => Self::Point(l - origin),
            Self::Directional(d) => Self::Directional(d),
        }
    }
}
