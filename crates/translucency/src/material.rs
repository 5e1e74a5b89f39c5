//! Scattering materials: σ_a, σ′_s per RGB channel and η, with the dipole's derived
//! coefficients (Jensen et al. 2001: σ′_t = σ_a + σ′_s, σ_tr = √(3 σ_a σ′_t); SEED-NOTES §5.5)
//! and presets from published measurements.
//!
//! # Presets
//!
//! Jensen, Marschner, Levoy & Hanrahan, "A Practical Model for Subsurface Light Transport",
//! SIGGRAPH 2001, Fig. 5's table of measured σ′_s and σ_a in **mm⁻¹** (R, G, B), as pbrt and
//! Mitsuba carry it. η is 1.3 for all but marble (1.5), as in those renderers' tables. Where
//! the two copies disagree (chicken1's red σ_a: pbrt 0.015, Mitsuba 0.0015) we follow pbrt,
//! whose value is in line with chicken2's 0.018.
//!
//! Lengths in the scene are converted to millimetres by [`Material::mm_per_unit`] (default
//! 1000: scene units are metres, glTF's convention).

use crate::error::{TranslucencyError, bad_parameter};

/// One preset: name, σ′_s (mm⁻¹), σ_a (mm⁻¹), η.
pub type Preset = (&'static str, [f64; 3], [f64; 3], f64);

/// Jensen et al. 2001's measured materials (see the module docs for the source).
pub const PRESETS: [Preset; 12] = [
    ("apple", [2.29, 2.39, 1.97], [0.0030, 0.0034, 0.046], 1.3),
    ("chicken1", [0.15, 0.21, 0.38], [0.015, 0.077, 0.19], 1.3),
    ("chicken2", [0.19, 0.25, 0.32], [0.018, 0.088, 0.20], 1.3),
    ("cream", [7.38, 5.47, 3.15], [0.0002, 0.0028, 0.0163], 1.3),
    ("ketchup", [0.18, 0.07, 0.03], [0.061, 0.97, 1.45], 1.3),
    ("marble", [2.19, 2.62, 3.00], [0.0021, 0.0041, 0.0071], 1.5),
    ("potato", [0.68, 0.70, 0.55], [0.0024, 0.0090, 0.12], 1.3),
    (
        "skimmilk",
        [0.70, 1.22, 1.90],
        [0.0014, 0.0025, 0.0142],
        1.3,
    ),
    ("skin1", [0.74, 0.88, 1.01], [0.032, 0.17, 0.48], 1.3),
    ("skin2", [1.09, 1.59, 1.79], [0.013, 0.070, 0.145], 1.3),
    ("spectralon", [11.6, 20.4, 14.9], [0.0, 0.0, 0.0], 1.3),
    (
        "wholemilk",
        [2.55, 3.21, 3.77],
        [0.0011, 0.0024, 0.014],
        1.3,
    ),
];

/// The default scale: scene units are metres.
pub const DEFAULT_MM_PER_UNIT: f64 = 1000.0;

/// A homogeneous scattering material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Absorption coefficient σ_a per channel, mm⁻¹.
    pub sigma_a: [f64; 3],
    /// Reduced scattering coefficient σ′_s per channel, mm⁻¹.
    pub sigma_s_prime: [f64; 3],
    /// Relative index of refraction η (inside / outside).
    pub eta: f64,
    /// Millimetres per scene unit.
    pub mm_per_unit: f64,
}

impl Default for Material {
    /// Jensen et al.'s marble.
    fn default() -> Self {
        Self::preset("marble").expect("marble is a preset")
    }
}

impl Material {
    /// A material from its coefficients, validated.
    ///
    /// # Errors
    /// A negative or non-finite σ, σ′_t = 0 in some channel, η not finite or ≤ 0, a scale
    /// not finite or ≤ 0 — named with its value.
    pub fn new(
        sigma_a: [f64; 3],
        sigma_s_prime: [f64; 3],
        eta: f64,
    ) -> Result<Self, TranslucencyError> {
        for (name, v) in [("sigma_a", sigma_a), ("sigma_s", sigma_s_prime)] {
            if v.iter().any(|x| !x.is_finite() || *x < 0.0) {
                return Err(bad_parameter(
                    name,
                    format!("{v:?}"),
                    "must be finite and ≥ 0 (mm⁻¹)",
                ));
            }
        }
        if (0..3).any(|c| sigma_a[c] + sigma_s_prime[c] <= 0.0) {
            return Err(bad_parameter(
                "sigma_a + sigma_s",
                format!(
                    "{:?}",
                    std::array::from_fn::<f64, 3, _>(|c| sigma_a[c] + sigma_s_prime[c])
                ),
                "the extinction σ′_t must be > 0 in every channel",
            ));
        }
        if !eta.is_finite() || eta <= 0.0 {
            return Err(bad_parameter("eta", eta, "must be finite and > 0"));
        }
        Ok(Self {
            sigma_a,
            sigma_s_prime,
            eta,
            mm_per_unit: DEFAULT_MM_PER_UNIT,
        })
    }

    /// A preset by name (case-insensitive), see [`PRESETS`].
    ///
    /// # Errors
    /// [`TranslucencyError::UnknownMaterial`], listing the presets.
    pub fn preset(name: &str) -> Result<Self, TranslucencyError> {
        let lower = name.to_ascii_lowercase();
        PRESETS
            .iter()
            .find(|p| p.0 == lower)
            .map(|&(_, s, a, eta)| Self::new(a, s, eta).expect("the presets are valid"))
            .ok_or_else(|| TranslucencyError::UnknownMaterial {
                name: name.to_string(),
                known: PRESETS.iter().map(|p| p.0).collect::<Vec<_>>().join(", "),
            })
    }

    /// The same material with `mm_per_unit` millimetres per scene unit.
    ///
    /// # Errors
    /// A scale that is not finite and > 0.
    pub fn with_scale(mut self, mm_per_unit: f64) -> Result<Self, TranslucencyError> {
        if !mm_per_unit.is_finite() || mm_per_unit <= 0.0 {
            return Err(bad_parameter(
                "mm_per_unit",
                mm_per_unit,
                "must be finite and > 0",
            ));
        }
        self.mm_per_unit = mm_per_unit;
        Ok(self)
    }

    /// Reduced extinction σ′_t = σ_a + σ′_s (mm⁻¹).
    #[must_use]
    pub fn sigma_t_prime(&self) -> [f64; 3] {
        std::array::from_fn(|c| self.sigma_a[c] + self.sigma_s_prime[c])
    }

    /// The distance (mm) below which eq. 12's attenuation is clamped: 1 / min σ′_t, one
    /// transport mean free path of the most weakly scattering channel
    /// ([`crate::model::attenuation_clamped`]).
    #[must_use]
    pub fn clamp_distance(&self) -> f64 {
        1.0 / self
            .sigma_t_prime()
            .into_iter()
            .fold(f64::INFINITY, f64::min)
    }

    /// Effective extinction σ_tr = √(3 σ_a σ′_t) (mm⁻¹).
    #[must_use]
    pub fn sigma_tr(&self) -> [f64; 3] {
        let t = self.sigma_t_prime();
        std::array::from_fn(|c| (3.0 * self.sigma_a[c] * t[c]).sqrt())
    }

    /// The dipole's total diffuse reflectance R_d (Jensen et al. 2001, eq. for R_d with
    /// F_dr = −1.440/η² + 0.710/η + 0.668 + 0.0636 η, A = (1 + F_dr)/(1 − F_dr),
    /// α′ = σ′_s/σ′_t): R_d = (α′/2)(1 + e^{−(4/3) A √(3(1 − α′))}) e^{−√(3(1 − α′))}. It is
    /// the colour the material has under diffuse light, the albedo of its direct term in the
    /// frame; 1 for a non-absorbing material (spectralon), and marble's (0.83, 0.79, 0.75) is
    /// Jensen et al.'s table.
    #[must_use]
    pub fn diffuse_reflectance(&self) -> [f64; 3] {
        let eta = self.eta;
        let f_dr = -1.440 / (eta * eta) + 0.710 / eta + 0.668 + 0.0636 * eta;
        let a = (1.0 + f_dr) / (1.0 - f_dr);
        let t = self.sigma_t_prime();
        std::array::from_fn(|c| {
            let alpha = self.sigma_s_prime[c] / t[c];
            let root = (3.0 * (1.0 - alpha)).max(0.0).sqrt();
            alpha / 2.0 * (1.0 + (-4.0 / 3.0 * a * root).exp()) * (-root).exp()
        })
    }
}
