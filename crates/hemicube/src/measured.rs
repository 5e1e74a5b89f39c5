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

use btf::env::EnvLightWeights;
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

/// The light side of the channel for BTF rendering under environment light (thesis §5.5.2,
/// eq. 5.10 with the pixel's solid angle): per pixel, the four nearest measured **light**
/// directions and τ_m(d_p) · Δω_p / π (`btf::Sampling::light_weights`, with the horizon fade;
/// the cosine is in the BTF images, so the weight is the solid angle, not ΔF).
///
/// It assumes maps built in each vertex's texture tangent frame
/// ([`crate::build_with_frames`] with [`crate::VertexFrame::from_normal_tangent`]), so a pixel
/// has the same tangent-frame direction at every vertex; a vertex whose UVs are mirrored has
/// its bitangent flipped, and uses the mirrored table.
#[derive(Clone, Debug)]
pub struct BtfLightChannel {
    sampling: Sampling,
    /// Per pixel (right-handed tangent frame, mirrored), the (m, τ_m Δω / π) entries.
    weights: [Vec<Weights4>; 2],
}

impl BtfLightChannel {
    /// The channel of `layout` for `sampling`.
    pub fn new(layout: &PixelLayout, sampling: Sampling) -> Self {
        let table = |flip: f32| {
            layout
                .directions()
                .iter()
                .zip(layout.solid_angles())
                .map(|(d, &omega)| {
                    let mut w = sampling.light_weights(Vec3::new(d.x, flip * d.y, d.z));
                    w.weights
                        .iter_mut()
                        .for_each(|x| *x *= omega * std::f32::consts::FRAC_1_PI);
                    w
                })
                .collect()
        };
        Self {
            sampling,
            weights: [table(1.0), table(-1.0)],
        }
    }

    /// The sampling.
    pub fn sampling(&self) -> Sampling {
        self.sampling
    }

    /// W_i(m) = Σ_p V_p τ_m(d_p) L(R_i d_p) Δω_p / π of every vertex (the environment binned
    /// onto the BTF's measured light directions, `btf::env`), `radiance` the world radiance
    /// and `mirrored[i]` whether vertex i's bitangent is n × t negated. A vertex without a
    /// frame gets all zeros. Parallel over vertices.
    ///
    /// # Panics
    /// If `mirrored` has not one entry per map.
    pub fn light_weights<F>(
        &self,
        maps: &VisibilityMaps,
        mirrored: &[bool],
        radiance: F,
    ) -> Vec<EnvLightWeights>
    where
        F: Fn(Vec3) -> Vec3 + Sync,
    {
        assert_eq!(mirrored.len(), maps.len(), "one handedness per map");
        let dirs = maps.layout().directions();
        (0..maps.len())
            .into_par_iter()
            .map(|i| {
                let mut w = EnvLightWeights::default();
                let Some(frame) = maps.frame(i) else {
                    return w;
                };
                let table = &self.weights[usize::from(mirrored[i])];
                let m = Mat3::from_quat(frame.rotation);
                let mut acc = [DVec3::ZERO; DIRECTIONS];
                for p in maps.open_pixels(i) {
                    let l = radiance(m * dirs[p]).as_dvec3();
                    for (index, tau) in table[p].iter() {
                        acc[index] += f64::from(tau) * l;
                    }
                }
                for (o, a) in w.weights.iter_mut().zip(acc) {
                    *o = a.as_vec3();
                }
                w
            })
            .collect()
    }
}
