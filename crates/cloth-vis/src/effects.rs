//! The effects a scene may ask for, and which of them this build can run.
//!
//! DESIGN.md, "Simulate only the effects a scene calls for": a scene lists effects by name and
//! the facade plans only the stages those effects need ([`crate::Plan`]).

use std::fmt;
use std::str::FromStr;

/// An appearance effect a scene can request.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Effect {
    /// Image-based diffuse lighting without visibility: c_i = (ρ/π) Σ_j max(0, n_i·l_j) I_j ω_j
    /// over a lightsphere level (paper 000 §3.3 with M_ij = max(0, n_i·l_j), i.e. all visible).
    Lighting,
    /// Per-vertex self-shadowing from the visibility matrix M (paper 000; occlusion-gpu).
    SelfShadowing,
    /// Static self-shadowing from per-vertex visibility maps (thesis §4.3; hemicube).
    StaticShadowing,
    /// Measured-material (BTF) rendering (thesis §5.3–5.6).
    Btf,
    /// Shadow volumes with smooth boundaries (thesis §4.2, §5.5.1).
    ShadowVolumes,
    /// Spherical-harmonics translucency (paper 004).
    Translucency,
}

impl Effect {
    /// Every effect, in the order stages run.
    pub const ALL: [Effect; 6] = [
        Effect::Lighting,
        Effect::SelfShadowing,
        Effect::StaticShadowing,
        Effect::Btf,
        Effect::ShadowVolumes,
        Effect::Translucency,
    ];

    /// The name used in scene files.
    pub fn name(self) -> &'static str {
        match self {
            Effect::Lighting => "lighting",
            Effect::SelfShadowing => "self-shadowing",
            Effect::StaticShadowing => "static-shadowing",
            Effect::Btf => "btf",
            Effect::ShadowVolumes => "shadow-volumes",
            Effect::Translucency => "translucency",
        }
    }
}

impl fmt::Display for Effect {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// An effect name that is not one of [`Effect::ALL`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UnknownEffect(pub String);

impl FromStr for Effect {
    type Err = UnknownEffect;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Effect::ALL
            .into_iter()
            .find(|e| e.name() == s)
            .ok_or_else(|| UnknownEffect(s.to_owned()))
    }
}

/// The known effect names, comma-separated, for error messages.
pub fn known_effect_names() -> String {
    Effect::ALL
        .iter()
        .map(|e| e.name())
        .collect::<Vec<_>>()
        .join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for e in Effect::ALL {
            assert_eq!(e.name().parse::<Effect>(), Ok(e));
        }
        assert_eq!(
            "shadows".parse::<Effect>(),
            Err(UnknownEffect("shadows".into()))
        );
    }
}
