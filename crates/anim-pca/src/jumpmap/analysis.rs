//! Analysis of a clip: PCA weights, velocities, D, D*, P, P*, P̂ (thesis §3.2.2, eqs. 3.1–3.8).

use clustering::{ComponentCount, Pca, PcaMethod, PcaParams};
use faer::{Mat, MatRef};
use glam::Vec3;

use super::graph;
use super::probability::{
    is_candidate, jump_map, l1_distances, normalise_by_mean_off_diagonal, shifted_cost,
    transition_probabilities,
};
use super::reconstruct::Reconstructor;
use crate::error::{AnimPcaError, Result, invalid};
use crate::matrix::SquareMatrix;

const WHAT: &str = "JumpMap::analyze";

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
        }
    }
}

impl JumpMapParams {
    fn validate(&self) -> Result<()> {
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

/// The analysed clip: PCA weights of every frame, the matrices D, D*, P, P*, P̂ and the pruned
/// sampling matrix the [`Player`](super::Player) draws from.
#[derive(Clone, Debug)]
pub struct JumpMap {
    params: JumpMapParams,
    n_frames: usize,
    n_vertices: usize,
    pca: Pca,
    velocity_pca: Pca,
    weights: Vec<f64>,
    velocity_weights: Vec<f64>,
    distance_unit: f64,
    velocity_distance_unit: f64,
    d: SquareMatrix,
    dv: SquareMatrix,
    p: SquareMatrix,
    pv: SquareMatrix,
    p_hat: SquareMatrix,
    sampling: SquareMatrix,
    in_core: Vec<bool>,
    mean_step: f64,
    reconstructor: Reconstructor,
}

impl JumpMap {
    /// Analyses a clip given as vertex positions per frame (`positions[i][n]` = p_in).
    ///
    /// A_i holds the positions only. See [`JumpMap::analyze_with_normals`] for eq. 3.1 with
    /// normals.
    ///
    /// # Errors
    /// [`AnimPcaError::EmptyClip`] (no frames or no vertices), [`AnimPcaError::TooFewFrames`]
    /// (one frame), [`AnimPcaError::VertexCountMismatch`], [`AnimPcaError::NonFinite`],
    /// [`AnimPcaError::InvalidParameter`] for c = 0, c* = 0, σ ≤ 0 or NaN, q ∉ [0, 1], and
    /// [`AnimPcaError::Pca`] if the decomposition fails.
    ///
    /// # Examples
    /// ```
    /// use anim_pca::{JumpMap, JumpMapParams};
    /// use glam::Vec3;
    /// // A point on a circle, 3 turns of 8 frames.
    /// let frames: Vec<Vec<Vec3>> = (0..24)
    ///     .map(|t| {
    ///         let a = t as f32 * std::f32::consts::TAU / 8.0;
    ///         vec![Vec3::new(a.cos(), a.sin(), 0.0), Vec3::Z]
    ///     })
    ///     .collect();
    /// let map = JumpMap::analyze(&frames, &JumpMapParams::default()).unwrap();
    /// // From frame 3 the best jump (other than going on to 4) is to frame 4 ± 8.
    /// assert!(matches!(map.best_jump(3), Some(12 | 20)));
    /// ```
    pub fn analyze(positions: &[Vec<Vec3>], params: &JumpMapParams) -> Result<Self> {
        Self::analyze_impl(positions, None, params)
    }

    /// Analyses a clip with per-vertex normals in A_i (thesis §3.2.2 "Besides the vertex
    /// positions, the vertex normals are also included in the vectors A_i"). The normals are
    /// scaled by [`JumpMapParams::normal_weight`] relative to the positions' spread, so that
    /// neither swamps the PCA (the thesis's R_i concern). Velocities use positions only.
    ///
    /// # Errors
    /// As [`JumpMap::analyze`]; also [`AnimPcaError::TooFewFrames`] /
    /// [`AnimPcaError::VertexCountMismatch`] when `normals` does not match `positions`.
    pub fn analyze_with_normals(
        positions: &[Vec<Vec3>],
        normals: &[Vec<Vec3>],
        params: &JumpMapParams,
    ) -> Result<Self> {
        Self::analyze_impl(positions, Some(normals), params)
    }

    fn analyze_impl(
        positions: &[Vec<Vec3>],
        normals: Option<&[Vec<Vec3>]>,
        params: &JumpMapParams,
    ) -> Result<Self> {
        params.validate()?;
        let n_vertices = validate_clip(WHAT, positions)?;
        let l = positions.len();
        if let Some(nrm) = normals {
            if nrm.len() != l {
                return Err(AnimPcaError::TooFewFrames {
                    what: "JumpMap::analyze_with_normals normals",
                    frames: nrm.len(),
                    min: l,
                });
            }
            validate_frames("JumpMap::analyze_with_normals normals", nrm, n_vertices)?;
        }

        // A_i (eq. 3.1): positions, then scaled normals.
        let dp = 3 * n_vertices;
        let normal_scale = normals.map(|n| {
            let (vp, vn) = (total_variance(positions), total_variance(n));
            if vp > 0.0 && vn > 0.0 {
                params.normal_weight * (vp / vn).sqrt()
            } else {
                params.normal_weight
            }
        });
        let d = if normals.is_some() { 2 * dp } else { dp };
        let mut data = Vec::with_capacity(l * d);
        for i in 0..l {
            data.extend(positions[i].iter().flat_map(|v| v.to_array()));
            if let (Some(n), Some(s)) = (normals, normal_scale) {
                data.extend(n[i].iter().flat_map(|v| (*v * s as f32).to_array()));
            }
        }
        let a = MatRef::from_row_major_slice(&data, l, d);
        let pca = fit(a, params.components)?;
        let weights = flatten(&pca.project(a)?);
        drop(data);

        // V_i (eq. 3.4) and its own PCA.
        let (before_first, after_last) = closing_neighbours(&weights, l, pca.n_components());
        let vel = velocities(positions, before_first, after_last);
        let v = MatRef::from_row_major_slice(&vel, l, dp);
        let velocity_pca = fit(v, params.velocity_components)?;
        let velocity_weights = flatten(&velocity_pca.project(v)?);
        drop(vel);

        let (c, cv) = (pca.n_components(), velocity_pca.n_components());
        let mut dm = l1_distances(&weights, l, c); // eq. 3.2
        let distance_unit = normalise_by_mean_off_diagonal(&mut dm);
        let mut dvm = l1_distances(&velocity_weights, l, cv); // eq. 3.5
        let velocity_distance_unit = normalise_by_mean_off_diagonal(&mut dvm);
        let p = transition_probabilities(&dm, params.sigma); // eq. 3.3
        let pv = transition_probabilities(&dvm, params.sigma_velocity); // eq. 3.6
        let p_hat = jump_map(&p, &pv, params.q, params.q_velocity); // eq. 3.8
        let pruned = graph::prune(&p_hat);

        let reconstructor = Reconstructor::from_pca(&pca, n_vertices, normal_scale);
        let mut map = Self {
            params: *params,
            n_frames: l,
            n_vertices,
            pca,
            velocity_pca,
            weights,
            velocity_weights,
            distance_unit,
            velocity_distance_unit,
            d: dm,
            dv: dvm,
            p,
            pv,
            p_hat,
            sampling: pruned.sampling,
            in_core: pruned.in_core,
            mean_step: 0.0,
            reconstructor,
        };
        map.mean_step = (0..l - 1)
            .map(|i| map.geometry_distance(i, i + 1))
            .sum::<f64>()
            / (l - 1) as f64;
        Ok(map)
    }

    /// The parameters the map was built with.
    pub fn params(&self) -> &JumpMapParams {
        &self.params
    }

    /// Number of frames l of the clip.
    pub fn n_frames(&self) -> usize {
        self.n_frames
    }

    /// Number of vertices N per frame.
    pub fn n_vertices(&self) -> usize {
        self.n_vertices
    }

    /// Components c actually kept (≤ requested: at most the clip's numerical rank, so 0 for a
    /// static clip and ≤ l − 1 always).
    pub fn components(&self) -> usize {
        self.pca.n_components()
    }

    /// Velocity components c* actually kept.
    pub fn velocity_components(&self) -> usize {
        self.velocity_pca.n_components()
    }

    /// The PCA of the frame vectors A_i (eq. 3.1; eigenframes are its components).
    pub fn pca(&self) -> &Pca {
        &self.pca
    }

    /// The PCA of the central velocities V_i (eq. 3.4).
    pub fn velocity_pca(&self) -> &Pca {
        &self.velocity_pca
    }

    /// PCA weights w_i of frame i (length [`JumpMap::components`]).
    ///
    /// # Panics
    /// If `i ≥ n_frames()`.
    pub fn weights(&self, i: usize) -> &[f64] {
        let c = self.components();
        &self.weights[i * c..(i + 1) * c]
    }

    /// Velocity PCA weights w*_i of frame i (length [`JumpMap::velocity_components`]).
    ///
    /// # Panics
    /// If `i ≥ n_frames()`.
    pub fn velocity_weights(&self, i: usize) -> &[f64] {
        let c = self.velocity_components();
        &self.velocity_weights[i * c..(i + 1) * c]
    }

    /// D (eq. 3.2) divided by its mean off-diagonal entry [`JumpMap::distance_unit`].
    pub fn distances(&self) -> &SquareMatrix {
        &self.d
    }

    /// D* (eq. 3.5) divided by its mean off-diagonal entry.
    pub fn velocity_distances(&self) -> &SquareMatrix {
        &self.dv
    }

    /// The mean off-diagonal entry of the raw D (eq. 3.2) that [`JumpMap::distances`] is
    /// divided by; 0 for a static clip (D is then all zero).
    pub fn distance_unit(&self) -> f64 {
        self.distance_unit
    }

    /// The mean off-diagonal entry of the raw D* (eq. 3.5).
    pub fn velocity_distance_unit(&self) -> f64 {
        self.velocity_distance_unit
    }

    /// P (eq. 3.3), row-normalised; see the [module docs](super) for the last row.
    pub fn position_probabilities(&self) -> &SquareMatrix {
        &self.p
    }

    /// P* (eq. 3.6), row-normalised.
    pub fn velocity_probabilities(&self) -> &SquareMatrix {
        &self.pv
    }

    /// The jump map P̂ (eq. 3.8), row-normalised.
    pub fn jump_map(&self) -> &SquareMatrix {
        &self.p_hat
    }

    /// P̂ after dead-end pruning (see [`graph`](super::graph)): what the player samples from.
    pub fn sampling_matrix(&self) -> &SquareMatrix {
        &self.sampling
    }

    /// Whether each frame belongs to the core (the largest strongly connected set of
    /// significant transitions); a run enters the core and never leaves it.
    pub fn core(&self) -> &[bool] {
        &self.in_core
    }

    /// The most probable target of frame i in P̂ other than its natural successor i + 1 (and
    /// other than i itself): the best "jump". `None` when frame i has no other candidate.
    ///
    /// # Panics
    /// If `i ≥ n_frames()`.
    pub fn best_jump(&self, i: usize) -> Option<usize> {
        let row = self.p_hat.row(i);
        (0..self.n_frames)
            .filter(|&j| j != i + 1 && j != i && is_candidate(self.n_frames, i, j))
            .max_by(|&a, &b| row[a].total_cmp(&row[b]).then(b.cmp(&a)))
    }

    /// ‖Ã_a − Ã_b‖₂, the Euclidean distance of the reconstructed frames (positions and scaled
    /// normals), computed exactly from the weights because the eigenframes are orthonormal.
    pub fn geometry_distance(&self, a: usize, b: usize) -> f64 {
        let (wa, wb) = (self.weights(a), self.weights(b));
        wa.iter()
            .zip(wb)
            .map(|(x, y)| (x - y) * (x - y))
            .sum::<f64>()
            .sqrt()
    }

    /// d̄: the mean of ‖Ã_{i+1} − Ã_i‖₂ over the clip, the unit of the smoothness s (eq. 3.11).
    pub fn mean_frame_distance(&self) -> f64 {
        self.mean_step
    }

    /// The discontinuity a jump i → j leaves: ‖Ã_{i+1} − Ã_j‖₂ (‖Ã_{l−1} − Ã_{j−1}‖₂ from the
    /// last frame), the geometry counterpart of the shifted distance in eq. 3.3. 0 for the
    /// natural successor.
    pub fn jump_residual(&self, i: usize, j: usize) -> f64 {
        let l = self.n_frames;
        if i + 1 < l {
            self.geometry_distance(i + 1, j)
        } else if j >= 1 {
            self.geometry_distance(l - 1, j - 1)
        } else {
            0.0
        }
    }

    /// The normalised distance eq. 3.3 uses for the transition i → j (D_{i+1,j}, or
    /// D_{l−1,j−1} from the last frame).
    pub fn shifted_distance(&self, i: usize, j: usize) -> f64 {
        shifted_cost(&self.d, i, j)
    }

    /// The reconstructor of frames from PCA weights.
    pub fn reconstructor(&self) -> &Reconstructor {
        &self.reconstructor
    }
}

/// Checks a clip and returns its vertex count.
pub(crate) fn validate_clip(what: &'static str, positions: &[Vec<Vec3>]) -> Result<usize> {
    let n = positions.first().map_or(0, Vec::len);
    if n == 0 {
        return Err(AnimPcaError::EmptyClip {
            what,
            frames: positions.len(),
            vertices: n,
        });
    }
    if positions.len() < 2 {
        return Err(AnimPcaError::TooFewFrames {
            what,
            frames: positions.len(),
            min: 2,
        });
    }
    validate_frames(what, positions, n)?;
    Ok(n)
}

fn validate_frames(what: &'static str, frames: &[Vec<Vec3>], n: usize) -> Result<()> {
    for (i, f) in frames.iter().enumerate() {
        if f.len() != n {
            return Err(AnimPcaError::VertexCountMismatch {
                what,
                frame: i,
                expected: n,
                found: f.len(),
            });
        }
        if let Some((k, v)) = f.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            let value = v
                .to_array()
                .into_iter()
                .find(|x| !x.is_finite())
                .unwrap_or(f32::NAN);
            return Err(AnimPcaError::NonFinite {
                what,
                frame: i,
                vertex: k,
                value,
            });
        }
    }
    Ok(())
}

/// PCA with `c` components (Gram path for few frames, chosen by `Auto`).
pub(crate) fn fit(a: MatRef<'_, f32>, c: usize) -> Result<Pca> {
    Ok(Pca::fit(
        a,
        &PcaParams {
            components: ComponentCount::Fixed(c),
            method: PcaMethod::Auto,
            seed: 0,
        },
    )?)
}

/// Row-major copy of an l × c weight matrix.
pub(crate) fn flatten(w: &Mat<f64>) -> Vec<f64> {
    let mut out = Vec::with_capacity(w.nrows() * w.ncols());
    for i in 0..w.nrows() {
        for k in 0..w.ncols() {
            out.push(w[(i, k)]);
        }
    }
    out
}

/// A clip end "closes" onto another frame when their reconstructed distance is at most this
/// fraction of the mean frame-to-frame distance d̄. Half a frame step: the horse gallop's
/// closing frame is at 0.00 d̄ from frame 0; an end that is merely near another pose (a frame
/// step or more away) keeps its one-sided difference.
pub const CLOSING_MATCH: f64 = 0.5;

/// The virtual predecessor of frame 0 and successor of frame l−1 for a clip whose ends repeat
/// other frames (a cycle with a closing frame): if frame l−1 matches frame k ≤ l−3 within
/// [`CLOSING_MATCH`]·d̄, the frame after it is k + 1; likewise frame 0 matching k ≥ 2 has the
/// predecessor k − 1.
fn closing_neighbours(weights: &[f64], l: usize, c: usize) -> (Option<usize>, Option<usize>) {
    if l < 3 || c == 0 {
        return (None, None);
    }
    let dist = |a: usize, b: usize| -> f64 {
        (0..c)
            .map(|k| (weights[a * c + k] - weights[b * c + k]).powi(2))
            .sum::<f64>()
            .sqrt()
    };
    let step = (0..l - 1).map(|i| dist(i, i + 1)).sum::<f64>() / (l - 1) as f64;
    let best = |from: usize, range: std::ops::Range<usize>| {
        range
            .map(|k| (dist(from, k), k))
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .filter(|(d, _)| *d <= CLOSING_MATCH * step)
            .map(|(_, k)| k)
    };
    (
        best(0, 2..l).map(|k| k - 1),
        best(l - 1, 0..l - 2).map(|k| k + 1),
    )
}

/// Central velocities (eq. 3.4), flattened l × 3N row-major.
///
/// Deviation: the thesis sets v_0 = v_l = 0. Zero end velocities would make the first and
/// last frame look like rest poses to D* and forbid exactly the jumps into and out of the clip
/// ends that a looping clip needs. Instead an end that closes onto another frame (see
/// [`closing_neighbours`]) uses that frame's neighbour in the central difference, and any
/// other end uses a one-sided difference (v_0 = p_1 − p_0, v_{l−1} = p_{l−1} − p_{l−2}).
pub(crate) fn velocities(
    positions: &[Vec<Vec3>],
    before_first: Option<usize>,
    after_last: Option<usize>,
) -> Vec<f32> {
    let l = positions.len();
    let mut out = Vec::with_capacity(l * positions[0].len() * 3);
    for i in 0..l {
        let (a, b, s) = match i {
            0 => before_first.map_or((0, 1, 1.0), |k| (k, 1, 0.5)),
            _ if i == l - 1 => after_last.map_or((l - 2, l - 1, 1.0), |k| (l - 2, k, 0.5)),
            _ => (i - 1, i + 1, 0.5),
        };
        out.extend(
            positions[a]
                .iter()
                .zip(&positions[b])
                .flat_map(|(p, q)| ((*q - *p) * s).to_array()),
        );
    }
    out
}

/// Σ over frames and coordinates of the squared deviation from the mean frame, in f64.
fn total_variance(frames: &[Vec<Vec3>]) -> f64 {
    let l = frames.len() as f64;
    let n = frames[0].len();
    let mut mean = vec![[0.0f64; 3]; n];
    for f in frames {
        for (m, v) in mean.iter_mut().zip(f) {
            for k in 0..3 {
                m[k] += f64::from(v[k]) / l;
            }
        }
    }
    frames
        .iter()
        .flat_map(|f| f.iter().zip(&mean))
        .map(|(v, m)| {
            (0..3)
                .map(|k| (f64::from(v[k]) - m[k]).powi(2))
                .sum::<f64>()
        })
        .sum()
}
