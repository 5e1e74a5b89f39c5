//! Analysis of a clip: PCA weights, velocities, D, D*, P, P*, P̂ (thesis §3.2.2, eqs. 3.1–3.8).

use clustering::{ComponentCount, Pca, PcaMethod, PcaParams};
use faer::{Mat, MatRef};
use glam::Vec3;

use super::cells::Layout;
use super::graph;
pub use super::params::{JumpMapParams, RootMotion};
use super::player::GeneratedFrame;
use super::probability::{
    jump_map, l1_distances, normalise_by_mean_off_diagonal, shifted_cost, transition_probabilities,
};
use super::reconstruct::{AttributeReconstructor, Reconstructor};
pub(crate) use super::validate::validate_clip;
use super::validate::validate_clips;
use crate::error::Result;
use crate::matrix::SquareMatrix;

pub(super) const WHAT: &str = "JumpMap::analyze";

/// One clip handed to [`JumpMap::analyze_cells`]: vertex positions per frame, optionally
/// normals (in A_i, eq. 3.1) and an attribute vector R_i per frame (thesis §3.2.2 "Adding
/// vertex attributes").
#[derive(Clone, Copy, Debug)]
pub struct Clip<'a> {
    /// `positions[i][n]`: vertex n of frame i.
    pub positions: &'a [Vec<Vec3>],
    /// Normals per frame and vertex, if any.
    pub normals: Option<&'a [Vec<Vec3>]>,
    /// R_i per frame (any length ≥ 1, the same for every frame), if any.
    pub attributes: Option<&'a [Vec<f32>]>,
}

impl<'a> Clip<'a> {
    /// A clip of positions only.
    pub fn new(positions: &'a [Vec<Vec3>]) -> Self {
        Self {
            positions,
            normals: None,
            attributes: None,
        }
    }

    /// With normals in A_i.
    pub fn with_normals(self, normals: &'a [Vec<Vec3>]) -> Self {
        Self {
            normals: Some(normals),
            ..self
        }
    }

    /// With attribute vectors R_i.
    pub fn with_attributes(self, attributes: &'a [Vec<f32>]) -> Self {
        Self {
            attributes: Some(attributes),
            ..self
        }
    }
}

/// The attribute PCA and every frame's weights.
#[derive(Clone, Debug)]
struct Attributes {
    weights: Vec<f64>,
    reconstructor: AttributeReconstructor,
}

impl Attributes {
    fn new(pca: &Pca, weights: Vec<f64>) -> Self {
        Self {
            weights,
            reconstructor: AttributeReconstructor::from_pca(pca),
        }
    }
}

/// The analysed clip: PCA weights of every frame, the matrices D, D*, P, P*, P̂ and the pruned
/// sampling matrix the [`Player`](super::Player) draws from.
#[derive(Clone, Debug)]
pub struct JumpMap {
    params: JumpMapParams,
    n_frames: usize,
    n_vertices: usize,
    layout: Layout,
    pca: Pca,
    velocity_pca: Pca,
    weights: Vec<f64>,
    velocity_weights: Vec<f64>,
    attributes: Option<Attributes>,
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
    roots: Vec<Vec3>,
    reconstructor: Reconstructor,
}

impl JumpMap {
    /// Analyses a clip given as vertex positions per frame (`positions[i][n]` = p_in).
    ///
    /// A_i holds the positions only. See [`JumpMap::analyze_with_normals`] for eq. 3.1 with
    /// normals and [`JumpMap::analyze_cells`] for attributes and several clips.
    ///
    /// # Errors
    /// [`crate::AnimPcaError::EmptyClip`] (no frames or no vertices), [`crate::AnimPcaError::TooFewFrames`]
    /// (one frame), [`crate::AnimPcaError::VertexCountMismatch`], [`crate::AnimPcaError::NonFinite`],
    /// [`crate::AnimPcaError::InvalidParameter`] for c = 0, c* = 0, σ ≤ 0 or NaN, q ∉ [0, 1], and
    /// [`crate::AnimPcaError::Pca`] if the decomposition fails.
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
        Self::analyze_cells(&[Clip::new(positions)], params)
    }

    /// Analyses a clip with per-vertex normals in A_i (thesis §3.2.2 "Besides the vertex
    /// positions, the vertex normals are also included in the vectors A_i"). The normals are
    /// scaled by [`JumpMapParams::normal_weight`] relative to the positions' spread, so that
    /// neither swamps the PCA. Velocities use positions only.
    ///
    /// # Errors
    /// As [`JumpMap::analyze`]; also [`crate::AnimPcaError::TooFewFrames`] /
    /// [`crate::AnimPcaError::VertexCountMismatch`] when `normals` does not match `positions`.
    pub fn analyze_with_normals(
        positions: &[Vec<Vec3>],
        normals: &[Vec<Vec3>],
        params: &JumpMapParams,
    ) -> Result<Self> {
        Self::analyze_cells(&[Clip::new(positions).with_normals(normals)], params)
    }

    /// Analyses one or several clips (the thesis's *cells*, §3.2.2 "Motion Control") with one
    /// common PCA, so that frames of different clips are comparable and the player can cross
    /// from cell to cell ([`Player::set_target_cell`](super::Player::set_target_cell)).
    ///
    /// Frames are numbered consecutively, clip after clip; natural play never runs from the
    /// last frame of a clip into the next clip. Random play stays in its cell: each cell gets
    /// its own dead-end-free core ([`graph`](super::graph)), and D, D*, P, P*, P̂ span all
    /// frames so that cross-cell transitions can be looked up.
    ///
    /// Attributes R_i ([`Clip::with_attributes`], thesis §3.2.2 "Adding vertex attributes")
    /// get their own PCA with [`JumpMapParams::attribute_components`] components, so that
    /// quantities of other units and scales (reflectance, wetness, per-vertex colour) neither
    /// distort nor are distorted by the geometry's PCA. They follow the frames they belong
    /// to but do not enter D: the jump structure is the motion's (eqs. 3.2, 3.5).
    ///
    /// # Errors
    /// As [`JumpMap::analyze`] for every clip; [`crate::AnimPcaError::InvalidCell`] when no clip is
    /// given, or the clips disagree on vertex count, on having normals or attributes, or on
    /// the attribute length.
    ///
    /// # Examples
    /// ```
    /// use anim_pca::{Clip, JumpMap, JumpMapParams};
    /// use glam::Vec3;
    /// // Two cells: a point circling left, and one circling right.
    /// let circle = |x0: f32| -> Vec<Vec<Vec3>> {
    ///     (0..24)
    ///         .map(|t| {
    ///             let a = t as f32 * std::f32::consts::TAU / 8.0;
    ///             vec![Vec3::new(x0 + a.cos(), a.sin(), 0.0), Vec3::Z]
    ///         })
    ///         .collect()
    /// };
    /// let (left, right) = (circle(-1.0), circle(1.0));
    /// let map = JumpMap::analyze_cells(
    ///     &[Clip::new(&left), Clip::new(&right)],
    ///     &JumpMapParams::default(),
    /// )
    /// .unwrap();
    /// assert_eq!(map.n_cells(), 2);
    /// assert_eq!(map.cell_range(1), 24..48);
    /// ```
    pub fn analyze_cells(clips: &[Clip<'_>], params: &JumpMapParams) -> Result<Self> {
        params.validate()?;
        let n_vertices = validate_clips(clips)?;
        let layout = Layout::new(&clips.iter().map(|c| c.positions.len()).collect::<Vec<_>>());
        let l = layout.n();
        let (centred, roots) = match params.root_motion {
            RootMotion::Keep => (Vec::new(), vec![Vec3::ZERO; l]),
            RootMotion::Extract => {
                let roots: Vec<Vec3> = clips
                    .iter()
                    .flat_map(|c| c.positions.iter().map(|f| centroid(f)))
                    .collect();
                let centred: Vec<Vec<Vec3>> = clips
                    .iter()
                    .flat_map(|c| c.positions.iter())
                    .zip(&roots)
                    .map(|(f, r)| f.iter().map(|v| *v - *r).collect())
                    .collect();
                (centred, roots)
            }
        };
        let positions: Vec<&[Vec3]> = if centred.is_empty() {
            clips
                .iter()
                .flat_map(|c| c.positions.iter().map(Vec::as_slice))
                .collect()
        } else {
            centred.iter().map(Vec::as_slice).collect()
        };
        let normals: Option<Vec<&[Vec3]>> = clips[0].normals.is_some().then(|| {
            clips
                .iter()
                .flat_map(|c| c.normals.unwrap_or_default().iter().map(Vec::as_slice))
                .collect()
        });

        // A_i (eq. 3.1): positions, then scaled normals.
        let dp = 3 * n_vertices;
        let normal_scale = normals.as_ref().map(|n| {
            let (vp, vn) = (total_variance(&positions), total_variance(n));
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
            if let (Some(n), Some(s)) = (&normals, normal_scale) {
                data.extend(n[i].iter().flat_map(|v| (*v * s as f32).to_array()));
            }
        }
        let a = MatRef::from_row_major_slice(&data, l, d);
        let pca = fit(a, params.components)?;
        let weights = flatten(&pca.project(a)?);
        drop(data);

        // V_i (eq. 3.4) cell by cell, and their own PCA.
        let mut vel = Vec::with_capacity(l * dp);
        for r in layout.ranges() {
            let c = pca.n_components();
            let (before_first, after_last) =
                closing_neighbours(&weights[r.start * c..r.end * c], r.len(), c);
            vel.extend(velocities(&positions[r.clone()], before_first, after_last));
        }
        let v = MatRef::from_row_major_slice(&vel, l, dp);
        let velocity_pca = fit(v, params.velocity_components)?;
        let velocity_weights = flatten(&velocity_pca.project(v)?);
        drop(vel);
        drop(positions);
        drop(centred);

        // R_i: a PCA of its own.
        let attributes = match clips[0].attributes {
            None => None,
            Some(first) => {
                let m = first[0].len();
                let flat: Vec<f32> = clips
                    .iter()
                    .flat_map(|c| c.attributes.unwrap_or_default().iter().flatten().copied())
                    .collect();
                let r = MatRef::from_row_major_slice(&flat, l, m);
                let rpca = fit(r, params.attribute_components)?;
                let rw = flatten(&rpca.project(r)?);
                Some(Attributes::new(&rpca, rw))
            }
        };

        let (c, cv) = (pca.n_components(), velocity_pca.n_components());
        let mut dm = l1_distances(&weights, l, c); // eq. 3.2
        let distance_unit = normalise_by_mean_off_diagonal(&mut dm);
        let mut dvm = l1_distances(&velocity_weights, l, cv); // eq. 3.5
        let velocity_distance_unit = normalise_by_mean_off_diagonal(&mut dvm);
        let p = transition_probabilities(&layout, &dm, params.sigma); // eq. 3.3
        let pv = transition_probabilities(&layout, &dvm, params.sigma_velocity); // eq. 3.6
        let p_hat = jump_map(&layout, &p, &pv, params.q, params.q_velocity); // eq. 3.8
        let pruned = graph::prune_cells(&p_hat, &layout);

        let reconstructor = Reconstructor::from_pca(&pca, n_vertices, normal_scale);
        let mut map = Self {
            params: *params,
            n_frames: l,
            n_vertices,
            layout,
            pca,
            velocity_pca,
            weights,
            velocity_weights,
            attributes,
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
            roots,
            reconstructor,
        };
        let steps: Vec<f64> = (0..l)
            .filter_map(|i| map.layout.successor(i).map(|s| map.geometry_distance(i, s)))
            .collect();
        map.mean_step = steps.iter().sum::<f64>() / steps.len().max(1) as f64;
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

    /// Number of cells (clips given to [`JumpMap::analyze_cells`]; 1 for a single clip).
    pub fn n_cells(&self) -> usize {
        self.layout.ranges().len()
    }

    /// The frame range of cell `cell` in the consecutive numbering.
    ///
    /// # Panics
    /// If `cell ≥ n_cells()`.
    pub fn cell_range(&self, cell: usize) -> std::ops::Range<usize> {
        self.layout.ranges()[cell].clone()
    }

    /// The cell frame i belongs to.
    ///
    /// # Panics
    /// If `i ≥ n_frames()`.
    pub fn cell_of(&self, i: usize) -> usize {
        self.layout.cell_of(i)
    }

    /// The natural successor of frame i: i + 1 when it is in the same cell, `None` at the end
    /// of a cell.
    pub fn successor(&self, i: usize) -> Option<usize> {
        self.layout.successor(i)
    }

    pub(crate) fn layout(&self) -> &Layout {
        &self.layout
    }

    /// The reconstructor of attribute vectors R_i, if the map was analysed with attributes.
    pub fn attribute_reconstructor(&self) -> Option<&AttributeReconstructor> {
        self.attributes.as_ref().map(|a| &a.reconstructor)
    }

    /// Attribute weights of frame i (empty without attributes).
    ///
    /// # Panics
    /// If `i ≥ n_frames()`.
    pub fn attribute_weights(&self, i: usize) -> &[f64] {
        match &self.attributes {
            Some(a) => {
                let c = a.reconstructor.components();
                &a.weights[i * c..(i + 1) * c]
            }
            None => &[],
        }
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
    /// other than i itself), in any cell: the best "jump". `None` when frame i has no other
    /// candidate.
    ///
    /// # Panics
    /// If `i ≥ n_frames()`.
    pub fn best_jump(&self, i: usize) -> Option<usize> {
        let row = self.p_hat.row(i);
        (0..self.n_frames)
            .filter(|&j| j != i && self.layout.is_jump(i, j) && self.layout.is_candidate(i, j))
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

    /// d̄: the mean of ‖Ã_{i+1} − Ã_i‖₂ over the clip (over every cell's natural steps), the unit of the smoothness s (eq. 3.11).
    pub fn mean_frame_distance(&self) -> f64 {
        self.mean_step
    }

    /// The discontinuity a jump i → j leaves: ‖Ã_{i+1} − Ã_j‖₂ (‖Ã_i − Ã_{j−1}‖₂ from the
    /// last frame of a cell), the geometry counterpart of the shifted distance in eq. 3.3. 0
    /// for the natural successor.
    pub fn jump_residual(&self, i: usize, j: usize) -> f64 {
        if let Some(s) = self.layout.successor(i) {
            self.geometry_distance(s, j)
        } else if let Some(p) = self.layout.predecessor(j) {
            self.geometry_distance(i, p)
        } else {
            0.0
        }
    }

    /// The normalised distance eq. 3.3 uses for the transition i → j (D_{i+1,j}, or
    /// D_{i,j−1} from the last frame of a cell).
    pub fn shifted_distance(&self, i: usize, j: usize) -> f64 {
        shifted_cost(&self.layout, &self.d, i, j)
    }

    /// The normalised velocity distance eq. 3.6 uses for i → j (D*_{i+1,j}, as
    /// [`JumpMap::shifted_distance`]).
    pub fn shifted_velocity_distance(&self, i: usize, j: usize) -> f64 {
        shifted_cost(&self.layout, &self.dv, i, j)
    }

    /// The *unnormalised* eq. 3.8 for i → j: [q + (1−q)·e^{−D_{i+1,j}/σ}]·[q* + (1−q*)·
    /// e^{−D*_{i+1,j}/σ*}], i.e. P̂ before each row is divided by its sum. Unlike P̂ its values
    /// compare across rows, which is what choosing *where* to leave a cell needs
    /// ([`Player::set_target_cell`](super::Player::set_target_cell)). In (0, 1]; 1 for a
    /// perfect match.
    pub fn transition_score(&self, i: usize, j: usize) -> f64 {
        let (q, qv) = (self.params.q, self.params.q_velocity);
        let term = |d: f64, sigma: f64| (-(d / sigma)).exp();
        (q + (1.0 - q) * term(self.shifted_distance(i, j), self.params.sigma))
            * (qv
                + (1.0 - qv)
                    * term(
                        self.shifted_velocity_distance(i, j),
                        self.params.sigma_velocity,
                    ))
    }

    /// The extracted root position (vertex centroid) of clip frame i; zero when the root
    /// motion was kept ([`RootMotion::Keep`]).
    ///
    /// # Panics
    /// If `i ≥ n_frames()`.
    pub fn root(&self, i: usize) -> Vec3 {
        self.roots[i]
    }

    /// The root's velocity at clip frame i: root(i + 1) − root(i), or root(i) − root(i − 1) at
    /// the end of a cell (cells have ≥ 2 frames, so one of the two exists).
    pub fn root_velocity(&self, i: usize) -> Vec3 {
        match (self.layout.successor(i), self.layout.predecessor(i)) {
            (Some(s), _) => self.roots[s] - self.roots[i],
            (None, Some(p)) => self.roots[i] - self.roots[p],
            (None, None) => Vec3::ZERO,
        }
    }

    /// Where to put each generated frame: the offset to add to its reconstructed vertices.
    ///
    /// With [`RootMotion::Extract`] the offsets integrate the clip's root velocities along the
    /// run, starting at the root of `frames[0]`: o_0 = root(`frames[0]`), o_{t+1} = o_t + v_t,
    /// where v_t blends the root velocities of frame t's two clip frames with its α. A
    /// walk therefore keeps walking forward through jumps and blends instead of snapping back
    /// to where the clip frame was recorded. With [`RootMotion::Keep`] all offsets are zero
    /// (the reconstructed frames are already in place).
    pub fn root_offsets(&self, frames: &[GeneratedFrame]) -> Vec<Vec3> {
        if self.params.root_motion == RootMotion::Keep {
            return vec![Vec3::ZERO; frames.len()];
        }
        let mut out = Vec::with_capacity(frames.len());
        let mut o = frames.first().map_or(Vec3::ZERO, |f| {
            self.roots[f.from].lerp(self.roots[f.to], f.alpha as f32)
        });
        for f in frames {
            out.push(o);
            let a = f.alpha as f32;
            o += self.root_velocity(f.from) * (1.0 - a) + self.root_velocity(f.to) * a;
        }
        out
    }

    /// The reconstructor of frames from PCA weights.
    pub fn reconstructor(&self) -> &Reconstructor {
        &self.reconstructor
    }
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
pub(crate) fn velocities<F: AsRef<[Vec3]>>(
    positions: &[F],
    before_first: Option<usize>,
    after_last: Option<usize>,
) -> Vec<f32> {
    let l = positions.len();
    let mut out = Vec::with_capacity(l * positions[0].as_ref().len() * 3);
    for i in 0..l {
        let (a, b, s) = match i {
            0 => before_first.map_or((0, 1, 1.0), |k| (k, 1, 0.5)),
            _ if i == l - 1 => after_last.map_or((l - 2, l - 1, 1.0), |k| (l - 2, k, 0.5)),
            _ => (i - 1, i + 1, 0.5),
        };
        out.extend(
            positions[a]
                .as_ref()
                .iter()
                .zip(positions[b].as_ref())
                .flat_map(|(p, q)| ((*q - *p) * s).to_array()),
        );
    }
    out
}

/// The vertex centroid of a frame, accumulated in f64.
fn centroid(frame: &[Vec3]) -> Vec3 {
    let mut s = [0.0f64; 3];
    for v in frame {
        for k in 0..3 {
            s[k] += f64::from(v[k]);
        }
    }
    let n = frame.len().max(1) as f64;
    Vec3::new((s[0] / n) as f32, (s[1] / n) as f32, (s[2] / n) as f32)
}

/// Σ over frames and coordinates of the squared deviation from the mean frame, in f64.
fn total_variance(frames: &[&[Vec3]]) -> f64 {
    let l = frames.len() as f64;
    let n = frames[0].len();
    let mut mean = vec![[0.0f64; 3]; n];
    for f in frames {
        for (m, v) in mean.iter_mut().zip(f.iter()) {
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
