//! The measured-direction channel (thesis §5.5.2, Fig. 5.12): for every map pixel, the four
//! nearest of the 81 measured BTF directions (Table 5.1, H1 or H2) and their bilinear weights.
//!
//! The thesis stores these per pixel and per vertex because its maps hold world-frame cube-map
//! texels. Our maps live in the vertex's tangent frame (z = normal), so a pixel's direction, and
//! with it its four measured directions and weights, is the same for every vertex: the channel
//! is one table per layout, and a vertex only adds its open bits. The weights are
//! `btf::Sampling::view_weights` (θ bracketed between two rings, φ between two neighbours,
//! bilinear, wrapping at 360°; beyond the last ring clamped to it), so they **sum to 1** for every
//! pixel: the cosine and solid-angle weighting stays in ΔF, and the BTF's own horizon fade is the
//! renderer's business.

use btf::sampling::{DIRECTIONS, Sampling, Weights4};
use glam::{DVec3, Mat3, Vec3};
use rayon::prelude::*;

use crate::layout::PixelLayout;
use crate::maps::VisibilityMaps;

/// Per pixel, the measured directions and weights of one sampling.
#[derive(Clone, Debug)]
pub struct MeasuredChannel {
    sampling: Sampling,
    weights: Vec<Weights4>,
}

impl MeasuredChannel {
    /// The channel of `layout` for `sampling`.
    pub fn new(layout: &PixelLayout, sampling: Sampling) -> Self {
        let weights = layout
            .directions()
            .iter()
            .map(|d| sampling.view_weights(*d))
            .collect();
        Self { sampling, weights }
    }

    /// The sampling.
    pub fn sampling(&self) -> Sampling {
        self.sampling
    }

    /// Pixel p's measured directions (indices into Table 5.1's 81) and weights.
    pub fn pixel(&self, p: usize) -> &Weights4 {
        &self.weights[p]
    }

    /// Per vertex and measured direction m, the environment light arriving through the open
    /// pixels near m: E_m(v) = Σ_p V_p ΔF_p τ_pm L(dir_p), an `[N][81]` table (row-major; NaN
    /// rows for vertices used by no triangle). Σ_m E_m(v) equals the open-pixel sum of
    /// [`crate::lighting::radiance_from`] with albedo 1, because every pixel's weights sum to 1.
    pub fn per_direction_radiance<F>(&self, maps: &VisibilityMaps, radiance: F) -> Vec<Vec3>
    where
        F: Fn(Vec3) -> Vec3 + Sync,
    {
        let ff = maps.layout().form_factors();
        let dirs = maps.layout().directions();
        let rows: Vec<Vec<Vec3>> = (0..maps.len())
            .into_par_iter()
            .map(|i| {
                let Some(frame) = maps.frame(i) else {
                    return vec![Vec3::NAN; DIRECTIONS];
                };
                let m = Mat3::from_quat(frame.rotation);
                let mut row = vec![DVec3::ZERO; DIRECTIONS];
                for p in maps.open_pixels(i) {
                    let l = f64::from(ff[p]) * radiance(m * dirs[p]).as_dvec3();
                    for (index, w) in self.weights[p].iter() {
                        row[index] += f64::from(w) * l;
                    }
                }
                row.into_iter().map(|v| v.as_vec3()).collect()
            })
            .collect();
        rows.concat()
    }
}
