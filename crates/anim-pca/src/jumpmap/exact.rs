//! Generated frames from the clip's own vertices: exact key frames, blends in position space.
//!
//! The jump map *decides* in PCA space (eqs. 3.1–3.8: distances, probabilities and blend
//! lengths all use c-component weights), but the frames a user gets back need not be PCA
//! reconstructions: a key frame of the run is clip frame i itself, and a blend frame is the
//! cross-fade (1 − α)·A_from + α·A_to of two clip frames (eq. 3.9's weights applied to the
//! vertices). Reconstructing from c weights instead (eq. 3.1, [`Reconstructor`]) loses
//! the residual A_i − Ã_i of every frame: 2.7 % of the bounding-box diagonal at c = 10 on the
//! horse gallop, even where the run plays the clip unchanged.
//!
//! Position-space blending *is* PCA-space blending with the residuals added back: eq. 3.1 is
//! linear, so (1 − α)·A_from + α·A_to = F_0 + Σ_k ((1 − α)·w_from,k + α·w_to,k)·F_k +
//! (1 − α)·r_from + α·r_to with r_i = A_i − Ã_i. The two are one formula; there is nothing to
//! choose between them. With [`RootMotion::Extract`] the blended frames are the root-centred
//! clip frames A_i − root(i), placed at the run's [`JumpMap::root_offsets`].
//!
//! [`Reconstructor`]: super::Reconstructor

use glam::Vec3;

use super::{GeneratedFrame, JumpMap, RootMotion};
use crate::error::{AnimPcaError, Result};

impl JumpMap {
    /// The vertices of generated frame `frame` from the clip's own frames, into `out`: for a
    /// key frame, clip frame i bit for bit (with [`RootMotion::Keep`]; with
    /// [`RootMotion::Extract`], A_i − root(i) + `offset`); for a blend frame,
    /// (1 − α)·A_from + α·A_to, root-centred and offset likewise (see the [module](self)).
    ///
    /// `clip` holds every frame the map was analysed from, in the map's order (the cells'
    /// frames one after another), each with [`JumpMap::n_vertices`] vertices; `offset` is the
    /// frame's entry of [`JumpMap::root_offsets`] (zero with [`RootMotion::Keep`]).
    ///
    /// # Errors
    /// [`AnimPcaError::LengthMismatch`] when `clip` does not have the map's frame count, a
    /// frame or `out` does not have its vertex count, or `frame` names a frame outside the
    /// clip.
    ///
    /// # Examples
    /// ```
    /// use anim_pca::{JumpMap, JumpMapParams, PlaybackParams, Player};
    /// use glam::Vec3;
    /// let clip: Vec<Vec<Vec3>> = (0..40)
    ///     .map(|t| {
    ///         let a = t as f32 * std::f32::consts::TAU / 10.0;
    ///         (0..8).map(|v| Vec3::new(a.cos(), a.sin(), v as f32 * (0.1 + 0.05 * a.sin()))).collect()
    ///     })
    ///     .collect();
    /// let params = JumpMapParams { components: 2, ..JumpMapParams::default() };
    /// let map = JumpMap::analyze(&clip, &params).unwrap();
    /// let run = Player::new(&map, &PlaybackParams::default()).unwrap().generate(60);
    /// let frames: Vec<&[Vec3]> = clip.iter().map(Vec::as_slice).collect();
    /// let mut out = vec![Vec3::ZERO; 8];
    /// for f in run.frames.iter().filter(|f| f.is_key()) {
    ///     map.exact_frame_into(&frames, f, Vec3::ZERO, &mut out).unwrap();
    ///     assert_eq!(out, clip[f.from]); // the clip's frame, not a rank-2 reconstruction
    /// }
    /// ```
    pub fn exact_frame_into(
        &self,
        clip: &[&[Vec3]],
        frame: &GeneratedFrame,
        offset: Vec3,
        out: &mut [Vec3],
    ) -> Result<()> {
        let mismatch = |what, expected, found| {
            Err(AnimPcaError::LengthMismatch {
                what,
                expected,
                found,
            })
        };
        let n = self.n_vertices();
        if clip.len() != self.n_frames() {
            return mismatch(
                "JumpMap::exact_frame_into clip frames",
                self.n_frames(),
                clip.len(),
            );
        }
        if out.len() != n {
            return mismatch("JumpMap::exact_frame_into output vertices", n, out.len());
        }
        let index = frame.from.max(frame.to);
        if index >= clip.len() {
            return mismatch("JumpMap::exact_frame_into frame index", clip.len(), index);
        }
        let (a, b) = (clip[frame.from], clip[frame.to]);
        for part in [a, b] {
            if part.len() != n {
                return mismatch(
                    "JumpMap::exact_frame_into clip frame vertices",
                    n,
                    part.len(),
                );
            }
        }
        let keep = self.params().root_motion == RootMotion::Keep;
        if frame.is_key() {
            if keep {
                out.copy_from_slice(a);
            } else {
                let shift = offset - self.root(frame.from);
                for (o, p) in out.iter_mut().zip(a) {
                    *o = *p + shift;
                }
            }
            return Ok(());
        }
        let alpha = frame.alpha;
        let shift = if keep {
            Vec3::ZERO
        } else {
            offset
                - self
                    .root(frame.from)
                    .lerp(self.root(frame.to), alpha as f32)
        };
        for ((o, p), q) in out.iter_mut().zip(a).zip(b) {
            // In f64: the blend of two nearby f32 positions, rounded once.
            let mix = |x: f32, y: f32| ((1.0 - alpha) * f64::from(x) + alpha * f64::from(y)) as f32;
            *o = Vec3::new(mix(p.x, q.x), mix(p.y, q.y), mix(p.z, q.z)) + shift;
        }
        Ok(())
    }
}
