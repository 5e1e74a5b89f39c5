//! Radiance per light direction I_j (paper 000 §3.3 and §5: c_i = Σ_j M_ij I_j, "I_j is the
//! 3-component (RGB) color of the light coming from direction l_j").
//!
//! Two methods:
//! * [`RadianceMethod::CellMean`] (default): the mean radiance over direction j's Voronoi
//!   cell. The map (texels split into s × s sub-texels with exact sub-solid angles when the
//!   cells are small against texels) is integrated over each cell in f64 — exactly along φ,
//!   by the midpoint rule along θ (see `cell_mean.rs`) — and I_j is that integral divided by
//!   ω_j. Hence Σ_j I_j·ω_j equals ∫L dω (the texel-exact [`Environment::total_power`]) up to
//!   f32 rounding of I_j, for any level and any map, a sun included.
//! * [`RadianceMethod::PrefilteredLookup`]: the seed's method — bilinear look-up of the
//!   Gaussian-prefiltered map at l_j. It is not power preserving; its error is what
//!   [`Environment::relative_power_error`] reports.

use super::Environment;
use crate::{Lightsphere, LightsphereError};
use glam::Vec3;

/// Default sub-samples per Voronoi cell for the automatic supersampling. Tuned on a constant
/// 1024×512 map, where I_j/L − 1 = sampled area/ω_j − 1 (rms / max over cells): level 4
/// (s = 1) 0.4 % / 1.9 %, level 5 (s = 2) 0.5 % / 3.3 %, level 6 (s = 3) 0.6 % / 5.3 %; the
/// error falls like 1/s and the cost grows like s².
const DEFAULT_SAMPLES_PER_CELL: usize = 256;

/// Default cap on the total number of sub-samples (2^23 ≈ 8.4 M nearest queries, ~1 s).
const DEFAULT_MAX_SAMPLES: usize = 1 << 23;

/// Largest supersampling factor per texel side.
const MAX_SUPERSAMPLING: u32 = 4096;

/// How the per-direction radiance I_j is computed.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum RadianceMethod {
    /// Mean radiance over each direction's Voronoi cell with default [`CellMeanParams`]
    /// (power preserving: Σ_j I_j·ω_j = ∫L dω).
    #[default]
    CellMean,
    /// The seed's method: bilinear look-up at l_j of the map prefiltered with a spherical
    /// Gaussian of angular standard deviation `sigma_deg` (see [`super::matched_sigma_deg`]).
    PrefilteredLookup {
        /// σ in degrees.
        sigma_deg: f64,
    },
}

/// What I_j is divided by in [`RadianceMethod::CellMean`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum CellNormalization {
    /// Divide by the exact Voronoi area ω_j: Σ_j I_j·ω_j = ∫L dω exactly; a constant map
    /// gives I_j = L·(sampled area / ω_j), within the sampling error of the cell's area.
    #[default]
    ExactSolidAngle,
    /// Divide by the sampled area of the cell: a constant map gives I_j = L exactly; the
    /// power is then preserved only up to the sampling error of the cell areas.
    SampledSolidAngle,
}

/// Tuning knobs of [`Environment::cell_mean`].
///
/// Construct with struct-update syntax: `Params { field: value, ..Default::default() }`.
#[derive(Clone, Debug, PartialEq)]
pub struct CellMeanParams {
    /// Fixed sub-samples per texel side; `None` picks the smallest s giving about
    /// `samples_per_cell` samples per cell, within `max_samples`.
    pub supersampling: Option<u32>,
    /// Target number of samples per Voronoi cell for the automatic choice.
    pub samples_per_cell: usize,
    /// Cap on the total number of samples for the automatic choice.
    pub max_samples: usize,
    /// Divide by ω_j (default) or by the sampled cell area.
    pub normalization: CellNormalization,
}

impl Default for CellMeanParams {
    fn default() -> Self {
        Self {
            supersampling: None,
            samples_per_cell: DEFAULT_SAMPLES_PER_CELL,
            max_samples: DEFAULT_MAX_SAMPLES,
            normalization: CellNormalization::default(),
        }
    }
}

/// Result of [`Environment::cell_mean`].
#[derive(Clone, Debug, PartialEq)]
pub struct CellMean {
    /// I_j, one per direction, in the lightsphere's order.
    pub radiance: Vec<Vec3>,
    /// The solid angle of the samples assigned to each direction (≈ ω_j).
    pub sampled_solid_angle: Vec<f64>,
    /// The sub-samples per texel side that were used.
    pub supersampling: u32,
    /// Directions that received no sample (map far coarser than the cells); their I_j is the
    /// texel value at l_j.
    pub empty_cells: usize,
}

impl Environment {
    /// Radiance per light direction I_j of `sphere` (world frame; this map's rotation is
    /// applied).
    ///
    /// # Errors
    /// [`LightsphereError::InvalidSigma`] for a bad σ in
    /// [`RadianceMethod::PrefilteredLookup`].
    pub fn radiance_per_direction(
        &self,
        sphere: &Lightsphere,
        method: RadianceMethod,
    ) -> Result<Vec<Vec3>, LightsphereError> {
        match method {
            RadianceMethod::CellMean => {
                Ok(self.cell_mean(sphere, &CellMeanParams::default())?.radiance)
            }
            RadianceMethod::PrefilteredLookup { sigma_deg } => {
                let filtered = self.prefiltered(sigma_deg)?;
                Ok(sphere
                    .directions_f64()
                    .iter()
                    .map(|&l| filtered.radiance_f64(l))
                    .collect())
            }
        }
    }

    /// Mean radiance over each Voronoi cell of `sphere`, with diagnostics.
    ///
    /// # Errors
    /// [`LightsphereError::InvalidParameter`] for `supersampling == Some(0)` or a zero
    /// `samples_per_cell` / `max_samples`.
    pub fn cell_mean(
        &self,
        sphere: &Lightsphere,
        params: &CellMeanParams,
    ) -> Result<CellMean, LightsphereError> {
        let s = self.supersampling(sphere.len(), params)?;
        let cells = super::cell_mean::integrate_cells(self, sphere, s as usize);
        let (sums, areas) = (cells.sums, cells.areas);
        let mut empty_cells = 0;
        let radiance = sphere
            .directions_f64()
            .iter()
            .enumerate()
            .map(|(j, &l)| {
                if areas[j] == 0.0 {
                    empty_cells += 1;
                    return self.texel_at(l);
                }
                let denominator = match params.normalization {
                    CellNormalization::ExactSolidAngle => sphere.solid_angles()[j],
                    CellNormalization::SampledSolidAngle => areas[j],
                };
                Vec3::from_array(sums[j].map(|v| (v / denominator) as f32))
            })
            .collect();
        Ok(CellMean {
            radiance,
            sampled_solid_angle: areas,
            supersampling: s,
            empty_cells,
        })
    }

    /// Sub-samples per texel side for `k` cells.
    fn supersampling(&self, k: usize, params: &CellMeanParams) -> Result<u32, LightsphereError> {
        let invalid = |name, value: f64| LightsphereError::InvalidParameter {
            name,
            value,
            requirement: "at least 1",
        };
        if let Some(s) = params.supersampling {
            if s == 0 || s > MAX_SUPERSAMPLING {
                return Err(LightsphereError::InvalidParameter {
                    name: "supersampling",
                    value: f64::from(s),
                    requirement: "in 1..=4096",
                });
            }
            return Ok(s);
        }
        if params.samples_per_cell == 0 {
            return Err(invalid("samples_per_cell", 0.0));
        }
        if params.max_samples == 0 {
            return Err(invalid("max_samples", 0.0));
        }
        let texels = (self.width * self.height) as f64;
        let wanted = (params.samples_per_cell as f64 * k as f64 / texels)
            .sqrt()
            .ceil();
        let allowed = (params.max_samples as f64 / texels).sqrt().floor();
        Ok(wanted.min(allowed).clamp(1.0, f64::from(MAX_SUPERSAMPLING)) as u32)
    }

    /// (Σ_j I_j·ω_j − ∫L dω) / ∫L dω per channel: how far a per-direction radiance is from
    /// preserving this map's power (0 when both are zero, ±∞ when only the map's is zero).
    ///
    /// # Errors
    /// [`LightsphereError::RadianceCount`] when `radiance.len() != sphere.len()`.
    pub fn relative_power_error(
        &self,
        sphere: &Lightsphere,
        radiance: &[Vec3],
    ) -> Result<[f64; 3], LightsphereError> {
        let represented = sphere.power(radiance)?;
        let exact = self.total_power();
        Ok(std::array::from_fn(|c| {
            let difference = represented[c] - exact[c];
            if difference == 0.0 {
                0.0
            } else {
                difference / exact[c]
            }
        }))
    }
}
