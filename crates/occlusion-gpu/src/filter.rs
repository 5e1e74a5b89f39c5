//! Vertex filtering using temporal coherence (paper 000 §4.1) and its per-frame driver.
//!
//! > "during a viewpoint change only a small number of polygons become visible for the first
//! > time (at most those that cross the object silhouette). Consequently, we can compute the
//! > visibility matrix M lazily, thereby distributing the computation effort over several
//! > frames. More precisely, we maintain two lists of triangles: a list of "unseen" triangles,
//! > U, containing all triangles that have not yet been visible and a list T ("todo"),
//! > containing triangles that will be seen in the next frame for the first time. […] when U
//! > contains less triangles than a certain threshold, we do not gain any performance any
//! > more. In that case, we just add all triangles from U to T and skip this optimization in
//! > the remaining frames. Note that for this optimization we need to consider triangles, not
//! > vertices." (§4.1)
//!
//! > "If there are several objects changing positions relative to each other or an object
//! > changes shape, than the complete visibility matrix M needs to be re-computed. […] We only
//! > need to re-initialize list U." (§6)
//!
//! [`VertexFilter`] keeps U and T as bitsets over the scene's triangles. Per frame, given the
//! visible triangles V: T = V ∩ U, then U −= T; the rows to compute are the receiver vertices
//! of T's triangles ([`triangle_rows`]), computed by [`crate::VisibilityEngine::compute_rows`]
//! (every triangle still occludes). [`VertexFilter::reset`] re-initialises U for a deforming
//! mesh, so each deforming frame computes exactly the vertices of the triangles visible in it.
//! [`FilteredVisibility`] drives it all per frame and does not recompute, for a static mesh, a
//! vertex already computed through another triangle, so each vertex is computed at most once.
//!
//! Deviation: T comes from one triangle-id pass instead of one occlusion query per triangle
//! of U (see [`TriangleIdRenderer`] for why), with a CPU rasteriser as reference and fallback.

pub(crate) mod camera;
mod raster;
mod triangle_set;
#[cfg(feature = "gpu")]
pub(crate) mod visible;

use std::time::{Duration, Instant};

use glam::Vec3;
use lightsphere::Lightsphere;

pub use camera::Camera;
pub use raster::visible_triangles_cpu;
pub use triangle_set::TriangleSet;
#[cfg(feature = "gpu")]
pub use visible::TriangleIdRenderer;

use crate::{OcclusionError, Scene, VisibilityEngine, VisibilityMatrix};

/// Default [`FilterThreshold::Fraction`]: filtering stops when fewer than 2% of the triangles
/// are still unseen. Not tuned by measurement: with the id pass costing one draw per frame,
/// the remaining rows (≤ 2% of N plus their shared vertices) cost about as much as a few id
/// passes on the meshes of `examples/filtering.rs`, so filtering on gains nothing below it.
pub const DEFAULT_FILTER_THRESHOLD_FRACTION: f64 = 0.02;

/// When filtering stops (§4.1's "certain threshold"): once U holds fewer triangles than this
/// at the start of a frame, all of U moves to T and the filter is off until
/// [`VertexFilter::reset`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FilterThreshold {
    /// A fraction in [0, 1] of the scene's triangle count.
    Fraction(f64),
    /// A triangle count.
    Count(usize),
}

/// Knobs of [`VertexFilter`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct FilterParams {
    /// When filtering stops; default [`DEFAULT_FILTER_THRESHOLD_FRACTION`] of the triangles.
    pub threshold: FilterThreshold,
}

impl Default for FilterParams {
    fn default() -> Self {
        Self {
            threshold: FilterThreshold::Fraction(DEFAULT_FILTER_THRESHOLD_FRACTION),
        }
    }
}

impl FilterParams {
    /// The same parameters with another threshold.
    pub fn with_threshold(mut self, threshold: FilterThreshold) -> Self {
        self.threshold = threshold;
        self
    }
}

/// The lists U ("unseen") and T ("todo") of paper 000 §4.1, at triangle granularity.
#[derive(Clone, Debug)]
pub struct VertexFilter {
    unseen: TriangleSet,
    todo: TriangleSet,
    threshold: FilterThreshold,
    active: bool,
}

impl VertexFilter {
    /// A filter over `triangle_count` triangles, all unseen.
    ///
    /// # Errors
    /// [`OcclusionError::InvalidParameter`] for a fraction outside [0, 1].
    pub fn new(triangle_count: usize, params: FilterParams) -> Result<Self, OcclusionError> {
        if let FilterThreshold::Fraction(f) = params.threshold
            && !(0.0..=1.0).contains(&f)
        {
            return Err(camera::invalid("filter threshold fraction", f, "in [0, 1]"));
        }
        Ok(Self {
            unseen: TriangleSet::full(triangle_count),
            todo: TriangleSet::empty(triangle_count),
            threshold: params.threshold,
            active: true,
        })
    }

    /// Number of triangles the filter ranges over.
    pub fn triangle_count(&self) -> usize {
        self.unseen.len()
    }

    /// U: the triangles not seen yet.
    pub fn unseen(&self) -> &TriangleSet {
        &self.unseen
    }

    /// T of the last [`VertexFilter::update`]: the triangles whose vertices that frame needs.
    pub fn todo(&self) -> &TriangleSet {
        &self.todo
    }

    /// Whether filtering is still on (false after the threshold switched it off, or once every
    /// triangle has been seen).
    pub fn is_active(&self) -> bool {
        self.active
    }

    /// Re-initialises U to all triangles and switches filtering back on (§6: a deforming mesh
    /// or a relative motion of objects).
    pub fn reset(&mut self) {
        self.unseen = TriangleSet::full(self.unseen.len());
        self.todo.clear();
        self.active = true;
    }

    /// Advances one frame and returns T. When filtering is on and U is at or above the
    /// threshold, `visible` is called for the frame's visible triangles V and T = V ∩ U,
    /// U −= T. Below the threshold T = U, U = ∅ and filtering switches off without calling
    /// `visible`; when off, T = ∅.
    ///
    /// # Errors
    /// The error of `visible`, or [`OcclusionError::SizeMismatch`] when V does not range
    /// over the filter's triangles.
    pub fn update(
        &mut self,
        visible: impl FnOnce() -> Result<TriangleSet, OcclusionError>,
    ) -> Result<&TriangleSet, OcclusionError> {
        self.todo.clear();
        if !self.active {
            return Ok(&self.todo);
        }
        let unseen = self.unseen.count();
        if unseen == 0 {
            self.active = false;
            return Ok(&self.todo);
        }
        let below = match self.threshold {
            FilterThreshold::Fraction(f) => (unseen as f64) < f * self.unseen.len() as f64,
            FilterThreshold::Count(c) => unseen < c,
        };
        if below {
            std::mem::swap(&mut self.todo, &mut self.unseen);
            self.active = false;
            return Ok(&self.todo);
        }
        let visible = visible()?;
        if visible.len() != self.unseen.len() {
            return Err(OcclusionError::SizeMismatch {
                what: "visible triangle set",
                given: visible.len(),
                expected: self.unseen.len(),
            });
        }
        self.todo = visible;
        self.todo.intersect_with(&self.unseen);
        self.unseen.subtract(&self.todo);
        Ok(&self.todo)
    }
}

/// The receiver rows of the vertices of `triangles`' triangles, ascending and unique
/// (vertices of occluder-only objects have no rows).
///
/// # Errors
/// [`OcclusionError::SizeMismatch`] when the set does not range over the scene's triangles.
pub fn triangle_rows(scene: &Scene, triangles: &TriangleSet) -> Result<Vec<u32>, OcclusionError> {
    let mut rows = vec![false; scene.receiver_count()];
    mark_rows(scene, triangles, &mut rows)?;
    Ok(rows
        .iter()
        .enumerate()
        .filter(|(_, r)| **r)
        .map(|(i, _)| i as u32)
        .collect())
}

/// Sets `rows[r]` for every receiver row r of a vertex of the set's triangles.
fn mark_rows(
    scene: &Scene,
    triangles: &TriangleSet,
    rows: &mut [bool],
) -> Result<(), OcclusionError> {
    if triangles.len() != scene.triangle_count() {
        return Err(OcclusionError::SizeMismatch {
            what: "triangle set",
            given: triangles.len(),
            expected: scene.triangle_count(),
        });
    }
    let (mut first_triangle, mut first_row) = (0usize, 0usize);
    for object in scene.objects() {
        if object.receiver {
            let end = first_triangle + object.triangles.len();
            for t in triangles
                .iter()
                .skip_while(|&t| t < first_triangle)
                .take_while(|&t| t < end)
            {
                for &v in &object.triangles[t - first_triangle] {
                    rows[first_row + v as usize] = true;
                }
            }
            first_row += object.positions.len();
        }
        first_triangle += object.triangles.len();
    }
    Ok(())
}

/// What one [`FilteredVisibility::frame`] did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameStats {
    /// Matrix rows computed this frame.
    pub rows_computed: usize,
    /// Matrix rows in all (what a full computation computes).
    pub rows_total: usize,
    /// Triangles visible this frame, when the visibility pass ran.
    pub triangles_visible: Option<usize>,
    /// |T|: triangles seen for the first time this frame (all of U when the filter switched
    /// off this frame).
    pub triangles_new: usize,
    /// |U| after the frame.
    pub triangles_unseen: usize,
    /// Whether filtering is still on after the frame.
    pub filter_active: bool,
    /// Time of the visibility pass (zero when it did not run).
    pub visibility_time: Duration,
    /// Time of the row computation.
    pub compute_time: Duration,
}

/// The per-frame driver: a [`VisibilityEngine`], a [`VertexFilter`] and the visibility matrix
/// it keeps up to date for the rows the camera needs.
pub struct FilteredVisibility {
    engine: VisibilityEngine,
    visibility: TriangleVisibility,
    params: FilterParams,
    filter: Option<VertexFilter>,
    matrix: Option<VisibilityMatrix>,
    computed: Vec<bool>,
    last_visible: Option<TriangleSet>,
}

impl FilteredVisibility {
    /// A driver computing rows with `engine` and finding visible triangles with `visibility`.
    ///
    /// # Errors
    /// As [`VertexFilter::new`].
    pub fn new(
        engine: VisibilityEngine,
        visibility: TriangleVisibility,
        params: FilterParams,
    ) -> Result<Self, OcclusionError> {
        VertexFilter::new(0, params)?;
        Ok(Self {
            engine,
            visibility,
            params,
            filter: None,
            matrix: None,
            computed: Vec::new(),
            last_visible: None,
        })
    }

    /// One frame: when `deforming` (or the receiver count, triangle count or lightsphere
    /// changed) U is re-initialised, then T is found for `camera` and the rows of T's vertices
    /// not computed yet are computed. Afterwards every vertex of every triangle visible from
    /// `camera` has its row equal to a full computation of `scene` (the other rows hold
    /// older or no results: their normals are zero until computed).
    ///
    /// `deforming` must be true whenever vertex positions or transforms changed since the last
    /// frame; a camera motion alone is not a deformation.
    ///
    /// # Errors
    /// An invalid scene or camera, and the errors of the engine and the visibility pass.
    pub fn frame(
        &mut self,
        scene: &Scene,
        sphere: &Lightsphere,
        camera: &Camera,
        deforming: bool,
    ) -> Result<FrameStats, OcclusionError> {
        let rows_total = scene.receiver_count();
        let triangles = scene.triangle_count();
        let compatible = self
            .matrix
            .as_ref()
            .is_some_and(|m| m.rows() == rows_total && m.directions() == sphere.directions())
            && self
                .filter
                .as_ref()
                .is_some_and(|f| f.triangle_count() == triangles);
        if !compatible {
            self.matrix = None;
            self.filter = None;
        }
        let filter = match &mut self.filter {
            Some(filter) => filter,
            empty => empty.insert(VertexFilter::new(triangles, self.params)?),
        };
        let matrix = self
            .matrix
            .get_or_insert_with(|| VisibilityMatrix::zeros(vec![Vec3::ZERO; rows_total], sphere));
        if deforming || !compatible {
            filter.reset();
            self.computed = vec![false; rows_total];
        }
        let start = Instant::now();
        let (visibility, last_visible) = (&mut self.visibility, &mut self.last_visible);
        *last_visible = None;
        filter.update(|| {
            let visible = visibility.visible(scene, camera)?;
            *last_visible = Some(visible.clone());
            Ok(visible)
        })?;
        let todo = filter.todo();
        let visibility_time = if last_visible.is_some() {
            start.elapsed()
        } else {
            Duration::ZERO
        };
        let mut needed = vec![false; rows_total];
        mark_rows(scene, todo, &mut needed)?;
        let rows: Vec<u32> = needed
            .iter()
            .zip(&self.computed)
            .enumerate()
            .filter(|(_, (need, done))| **need && !**done)
            .map(|(i, _)| i as u32)
            .collect();
        let start = Instant::now();
        self.engine.compute_rows(scene, matrix, &rows)?;
        let compute_time = start.elapsed();
        for &r in &rows {
            self.computed[r as usize] = true;
        }
        Ok(FrameStats {
            rows_computed: rows.len(),
            rows_total,
            triangles_visible: self.last_visible.as_ref().map(TriangleSet::count),
            triangles_new: todo.count(),
            triangles_unseen: filter.unseen().count(),
            filter_active: filter.is_active(),
            visibility_time,
            compute_time,
        })
    }

    /// The matrix kept up to date (None before the first frame).
    pub fn matrix(&self) -> Option<&VisibilityMatrix> {
        self.matrix.as_ref()
    }

    /// The filter (None before the first frame).
    pub fn filter(&self) -> Option<&VertexFilter> {
        self.filter.as_ref()
    }

    /// The visible triangles of the last frame, when its visibility pass ran.
    pub fn last_visible(&self) -> Option<&TriangleSet> {
        self.last_visible.as_ref()
    }

    /// The engine (e.g. to refine the matrix's level while idle).
    pub fn engine_mut(&mut self) -> &mut VisibilityEngine {
        &mut self.engine
    }

    /// Rows computed so far since U was last re-initialised.
    pub fn computed_rows(&self) -> usize {
        self.computed.iter().filter(|&&c| c).count()
    }
}

/// Where the visible triangles come from: the GPU id pass or the CPU rasteriser.
pub enum TriangleVisibility {
    /// The GPU id pass (`TriangleIdRenderer`) on a wgpu device (boxed: it is much larger than `Cpu`).
    #[cfg(feature = "gpu")]
    Gpu(Box<TriangleIdRenderer>),
    /// [`visible_triangles_cpu`] (no adapter needed).
    Cpu,
}

impl TriangleVisibility {
    /// The GPU id pass on `device` (`TriangleIdRenderer::new`).
    #[cfg(feature = "gpu")]
    pub fn gpu(device: &wgpu::Device, queue: &wgpu::Queue) -> Self {
        Self::Gpu(Box::new(TriangleIdRenderer::new(device, queue)))
    }

    /// The triangles `camera` sees in `scene`.
    ///
    /// # Errors
    /// As the GPU id pass (`TriangleIdRenderer::visible_triangles`) or [`visible_triangles_cpu`].
    pub fn visible(
        &mut self,
        scene: &Scene,
        camera: &Camera,
    ) -> Result<TriangleSet, OcclusionError> {
        match self {
            #[cfg(feature = "gpu")]
            Self::Gpu(renderer) => renderer.visible_triangles(scene, camera),
            Self::Cpu => visible_triangles_cpu(scene, camera),
        }
    }
}
