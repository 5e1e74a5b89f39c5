//! One API over the backends: compute M for a scene and a lightsphere, refine it to a finer
//! level reusing the columns already computed (paper 000 §3.4, §4.2), read the ambient term.

use lightsphere::Lightsphere;

use crate::cpu::{ColumnsTarget, CpuParams, Tracer, compute_columns};
use crate::depth_params::DepthParams;
#[cfg(feature = "gpu")]
use crate::gpu::{DepthPipelines, DepthRun, GpuVisibility, QueryPipelines, RayPipelines, RayTree};
use crate::progress::{ProgressFn, Ticker};
use crate::scene::Prepared;
use crate::{OcclusionError, Scene, VisibilityMatrix};

/// Which algorithm computes M.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Backend {
    /// Exact ray casting on the CPU with a BVH (the reference; no GPU needed).
    Cpu,
    /// GPU: orthographic depth maps per direction, then a compute pass that depth-tests every
    /// vertex against them with a slope-scaled bias (the seed's future work, §8.1).
    Depth,
    /// GPU, as published (§3.2, Figure 2): per direction the scene into a depth map, then
    /// every vertex drawn as a point inside its own hardware occlusion query; the query
    /// results are resolved and packed into M on the GPU. Slow by nature (N·k draws): the
    /// published baseline. Uses the [`DepthParams`] knobs of `depth`.
    Query,
    /// GPU, exact: the `cpu` backend's rays (origin offset, [`CpuParams::max_distance`],
    /// edge tolerance) cast by a compute shader through a BVH built on the CPU — M equals
    /// `cpu`'s up to rays within rounding of a triangle edge or the tangent plane. No depth
    /// map, so nothing of [`DepthParams`] applies.
    Rays,
}

impl Backend {
    /// The backend's name as the CLI spells it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Cpu => "cpu",
            Self::Depth => "depth",
            Self::Query => "query",
            Self::Rays => "rays",
        }
    }
}

/// How the `cpu` or `rays` backend's BVH was brought to the last scene it traced.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BvhUpdate {
    /// Nothing traced yet, or a depth-map backend (`depth`, `query`).
    None,
    /// The geometry had not changed: the tree was reused as it was.
    Reused,
    /// Only positions changed: the boxes were refitted; the tree's SAH cost over its cost
    /// when built.
    Refitted {
        /// SAH cost ratio, ≤ [`crate::REBUILD_SAH_RATIO`].
        sah_ratio: f32,
    },
    /// Built from scratch: new topology or method, refitting off, or a refit whose tree would
    /// cost more in traversal than a build — (SAH ratio − 1) × the expected traversal time on
    /// a fresh tree above the last build's time — or degraded past
    /// [`crate::REBUILD_SAH_RATIO`].
    Built,
}

/// What the last `cpu` or `rays` computation spent on its BVH (for `rays`: on the CPU,
/// upload included).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BvhStats {
    /// How the tree was obtained.
    pub update: BvhUpdate,
    /// Time spent on it, milliseconds.
    pub millis: f64,
}

/// Tuning knobs of all backends.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[non_exhaustive]
pub struct VisibilityParams {
    /// `cpu` backend knobs.
    pub cpu: CpuParams,
    /// `depth` backend knobs, also used by `query` (resolution, bias, normal offset).
    pub depth: DepthParams,
}

impl VisibilityParams {
    /// The same parameters with other `depth` knobs.
    pub fn with_depth(mut self, depth: DepthParams) -> Self {
        self.depth = depth;
        self
    }

    /// The same parameters with other `cpu` knobs.
    pub fn with_cpu(mut self, cpu: CpuParams) -> Self {
        self.cpu = cpu;
        self
    }
}

/// The device a GPU backend runs on.
#[cfg(feature = "gpu")]
struct Gpu {
    device: wgpu::Device,
    queue: wgpu::Queue,
}

/// What each backend keeps between calls: the `cpu` and `rays` backends' BVH of the last
/// scene (reused while the geometry is unchanged: refinement, vertex filtering on a static
/// mesh, an idle scene; refitted when only positions moved), the GPU backends' device and
/// pipelines (built on first use).
enum State {
    Cpu {
        tracer: Option<Tracer>,
        costs: TreeCosts,
    },
    #[cfg(feature = "gpu")]
    Depth {
        gpu: Gpu,
        pipelines: Option<DepthPipelines>,
    },
    #[cfg(feature = "gpu")]
    Query {
        gpu: Gpu,
        pipelines: Option<(DepthPipelines, QueryPipelines)>,
    },
    #[cfg(feature = "gpu")]
    Rays {
        gpu: Gpu,
        pipelines: Option<RayPipelines>,
        tree: Option<RayTree>,
    },
}

/// What the last trees cost, for the refit-or-rebuild decision: a refit costs nothing to
/// speak of but leaves a tree whose traversal is dearer; a build costs `build_ms`. Rebuild
/// when the extra traversal a refitted tree costs exceeds `build_ms` — the larger of the
/// extra time measured on the last refitted frame and (SAH ratio − 1) × the fresh tree's
/// time. The SAH ratio alone underestimates it: on the drape at k = 258 a tree refitted to
/// SAH 1.2 traced 19 % slower on average, and with the slabs of the fan traversal the
/// refitted frames cost 36.2 ms against 33.0 ms rebuilding every frame.
#[derive(Clone, Copy, Debug, Default)]
struct TreeCosts {
    /// Milliseconds of the last build.
    build_ms: f64,
    /// Traversal milliseconds per (row × column) on the last freshly built tree.
    fresh_ms_per_cell: f64,
    /// Traversal milliseconds per (row × column) on the last traced tree (fresh or refitted).
    last_ms_per_cell: f64,
}

impl TreeCosts {
    /// Whether a tree refitted to SAH ratio `ratio` is kept for `cells` (row × column)
    /// traversals: never beyond [`crate::REBUILD_SAH_RATIO`]; when `timed`, only while the
    /// extra traversal time it is expected to cost stays below a build's.
    fn worth_keeping(&self, ratio: f32, cells: f64, timed: bool) -> bool {
        let measured = (self.last_ms_per_cell - self.fresh_ms_per_cell).max(0.0);
        let predicted = (f64::from(ratio) - 1.0) * self.fresh_ms_per_cell;
        ratio <= crate::REBUILD_SAH_RATIO
            && (!timed || measured.max(predicted) * cells <= self.build_ms)
    }
}

const NO_BVH: BvhStats = BvhStats {
    update: BvhUpdate::None,
    millis: 0.0,
};

/// Computes visibility matrices with a chosen backend.
pub struct VisibilityEngine {
    state: State,
    params: VisibilityParams,
    last_rays: u64,
    last_bvh: BvhStats,
    progress: Option<ProgressFn>,
}

impl VisibilityEngine {
    /// The `cpu` backend.
    pub fn cpu(params: VisibilityParams) -> Self {
        Self {
            state: State::Cpu {
                tracer: None,
                costs: TreeCosts::default(),
            },
            params,
            last_rays: 0,
            last_bvh: NO_BVH,
            progress: None,
        }
    }

    /// Any backend; GPU backends run on `device` and `queue` (cloned handles are kept). The
    /// pipelines are built on first use. (Feature `gpu`.)
    #[cfg(feature = "gpu")]
    pub fn with_gpu(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        backend: Backend,
        params: VisibilityParams,
    ) -> Self {
        let gpu = Gpu {
            device: device.clone(),
            queue: queue.clone(),
        };
        let state = match backend {
            Backend::Cpu => State::Cpu {
                tracer: None,
                costs: TreeCosts::default(),
            },
            Backend::Depth => State::Depth {
                gpu,
                pipelines: None,
            },
            Backend::Query => State::Query {
                gpu,
                pipelines: None,
            },
            Backend::Rays => State::Rays {
                gpu,
                pipelines: None,
                tree: None,
            },
        };
        Self {
            state,
            params,
            last_rays: 0,
            last_bvh: NO_BVH,
            progress: None,
        }
    }

    /// The backend in use.
    pub fn backend(&self) -> Backend {
        match self.state {
            State::Cpu { .. } => Backend::Cpu,
            #[cfg(feature = "gpu")]
            State::Depth { .. } => Backend::Depth,
            #[cfg(feature = "gpu")]
            State::Query { .. } => Backend::Query,
            #[cfg(feature = "gpu")]
            State::Rays { .. } => Backend::Rays,
        }
    }

    /// The parameters in use.
    pub fn params(&self) -> &VisibilityParams {
        &self.params
    }

    /// Reports progress inside every later computation ([`ProgressFn`]: cells done of the
    /// call's rows × new columns), or stops reporting (`None`). The result does not depend on
    /// it.
    ///
    /// # Examples
    /// ```
    /// # use std::sync::{Arc, atomic::{AtomicU64, Ordering}};
    /// # use occlusion_gpu::{Scene, SceneObject, VisibilityEngine, VisibilityParams};
    /// # use glam::Vec3;
    /// let mut scene = Scene::new();
    /// scene.push(SceneObject::new(
    ///     vec![Vec3::ZERO, Vec3::X, Vec3::Z],
    ///     vec![Vec3::Y; 3],
    ///     vec![[0, 1, 2]],
    /// ))?;
    /// let sphere = lightsphere::Lightsphere::new(2)?;
    /// let seen = Arc::new(AtomicU64::new(0));
    /// let mut engine = VisibilityEngine::cpu(VisibilityParams::default());
    /// let last = Arc::clone(&seen);
    /// engine.set_progress(Some(Arc::new(move |done, _total| {
    ///     last.fetch_max(done, Ordering::Relaxed);
    /// })));
    /// engine.compute(&scene, &sphere)?;
    /// assert_eq!(seen.load(Ordering::Relaxed), 3 * sphere.len() as u64);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn set_progress(&mut self, progress: Option<ProgressFn>) {
        self.progress = progress;
    }

    /// A counter over `rows` × the columns `first..k` reporting to the caller's function.
    fn ticker(&self, rows: usize, columns: usize) -> Ticker {
        Ticker::new((rows * columns) as u64, self.progress.clone())
    }

    /// How the last `cpu` or `rays` computation obtained its BVH (reused, refitted, built)
    /// and the time it took; [`BvhUpdate::None`] on the depth-map backends.
    pub fn last_bvh(&self) -> BvhStats {
        self.last_bvh
    }

    /// Rays cast by the last `cpu` computation (after n·l culling); 0 for GPU backends.
    pub fn last_ray_count(&self) -> u64 {
        self.last_rays
    }

    /// Computes the full visibility matrix of the scene's receiver vertices.
    ///
    /// # Errors
    /// Invalid or empty scene ([`OcclusionError`]), a GPU backend without a device, GPU limits
    /// or read-back failures.
    pub fn compute(
        &mut self,
        scene: &Scene,
        sphere: &Lightsphere,
    ) -> Result<VisibilityMatrix, OcclusionError> {
        let prepared = Prepared::new(scene)?;
        let normals = prepared.receivers.iter().map(|r| r.normal).collect();
        let mut matrix = VisibilityMatrix::zeros(normals, sphere);
        self.fill(&prepared, &mut matrix, 0)?;
        Ok(matrix)
    }

    /// Refines `matrix` to the finer level `sphere`, computing only the new directions (the
    /// first k directions of a finer level are the coarser level's, §3.4). The scene must be
    /// the one the matrix was computed for.
    ///
    /// # Errors
    /// [`OcclusionError::NotARefinement`] when `sphere` does not extend the matrix's
    /// directions, [`OcclusionError::RowCountMismatch`] when the scene's receiver count
    /// differs, and the errors of [`VisibilityEngine::compute`].
    pub fn refine(
        &mut self,
        scene: &Scene,
        matrix: &mut VisibilityMatrix,
        sphere: &Lightsphere,
    ) -> Result<(), OcclusionError> {
        let prepared = Prepared::new(scene)?;
        if prepared.receivers.len() != matrix.rows() {
            return Err(OcclusionError::RowCountMismatch {
                matrix: matrix.rows(),
                scene: prepared.receivers.len(),
            });
        }
        let first_new = matrix.directions_len();
        matrix.grow(sphere)?;
        self.fill(&prepared, matrix, first_new)
    }

    /// (Re)computes only the receiver rows `rows` of `matrix`, for all of its directions, with
    /// this engine's backend: every triangle of `scene` still occludes, only the listed
    /// vertices are tested (paper 000 §4.1, vertex filtering). The rows' normals are updated
    /// from `scene` too (a deforming mesh); rows not listed are left as they are. The result
    /// of a listed row is bit-identical to the same row of [`VisibilityEngine::compute`].
    /// Duplicate indices are allowed (computed twice); an empty list does nothing.
    ///
    /// # Errors
    /// [`OcclusionError::RowCountMismatch`] when the scene's receiver count differs from the
    /// matrix's rows, [`OcclusionError::RowOutOfRange`] for an index ≥ the row count, and the
    /// errors of [`VisibilityEngine::compute`].
    pub fn compute_rows(
        &mut self,
        scene: &Scene,
        matrix: &mut VisibilityMatrix,
        rows: &[u32],
    ) -> Result<(), OcclusionError> {
        let prepared = Prepared::new(scene)?;
        if prepared.receivers.len() != matrix.rows() {
            return Err(OcclusionError::RowCountMismatch {
                matrix: matrix.rows(),
                scene: prepared.receivers.len(),
            });
        }
        if let Some(&row) = rows.iter().find(|&&r| r as usize >= matrix.rows()) {
            return Err(OcclusionError::RowOutOfRange {
                row,
                rows: matrix.rows(),
            });
        }
        self.last_rays = 0;
        if rows.is_empty() {
            return Ok(());
        }
        let subset = prepared.with_receivers(rows);
        let normals = subset.receivers.iter().map(|r| r.normal).collect();
        let mut compact = matrix.zeros_like(normals);
        self.fill(&subset, &mut compact, 0)?;
        matrix.scatter_rows(&compact, rows);
        Ok(())
    }

    /// The ambient term a_i only. On the GPU backends it is accumulated on the GPU and only N
    /// floats are read back; on `cpu` it is derived from M.
    ///
    /// # Errors
    /// As [`VisibilityEngine::compute`].
    pub fn ambient(
        &mut self,
        scene: &Scene,
        sphere: &Lightsphere,
    ) -> Result<Vec<f32>, OcclusionError> {
        #[cfg(feature = "gpu")]
        if self.backend() != Backend::Cpu {
            let prepared = Prepared::new(scene)?;
            let (gpu, run) =
                self.run_gpu(&prepared, sphere.directions(), sphere.solid_angles(), 0)?;
            return run.read_ambient(&gpu.device, &gpu.queue);
        }
        Ok(self.compute(scene, sphere)?.ambient())
    }

    /// Computes the full visibility matrix and a_i on the GPU and keeps them there: M stays
    /// on the GPU from frame to frame; only what is asked for is read back (paper 000 §8.1).
    /// [`GpuVisibility::read_matrix`] equals [`VisibilityEngine::compute`] and
    /// [`GpuVisibility::read_ambient`] equals [`VisibilityEngine::ambient`].
    ///
    /// # Errors
    /// [`OcclusionError::NotGpuResident`] on the `cpu` backend, and the errors of
    /// [`VisibilityEngine::compute`].
    ///
    /// Feature `gpu`.
    ///
    /// # Examples
    /// ```no_run
    /// # use occlusion_gpu::{Backend, Scene, VisibilityEngine, VisibilityParams};
    /// # fn demo(
    /// #     device: &wgpu::Device,
    /// #     queue: &wgpu::Queue,
    /// #     scene: &Scene,
    /// # ) -> Result<(), Box<dyn std::error::Error>> {
    /// let sphere = lightsphere::Lightsphere::new(2)?;
    /// let params = VisibilityParams::default();
    /// let mut engine = VisibilityEngine::with_gpu(device, queue, Backend::Query, params);
    /// let resident = engine.compute_resident(scene, &sphere)?;
    /// // A renderer binds resident.bits_buffer() and resident.ambient_buffer() directly;
    /// // read back only what is needed:
    /// let ambient = resident.read_ambient()?;
    /// assert_eq!(ambient.len(), resident.rows());
    /// # Ok(())
    /// # }
    /// ```
    #[cfg(feature = "gpu")]
    pub fn compute_resident(
        &mut self,
        scene: &Scene,
        sphere: &Lightsphere,
    ) -> Result<GpuVisibility, OcclusionError> {
        if self.backend() == Backend::Cpu {
            return Err(OcclusionError::NotGpuResident {
                backend: Backend::Cpu.name(),
            });
        }
        let prepared = Prepared::new(scene)?;
        self.last_rays = 0;
        let (gpu, run) = self.run_gpu(&prepared, sphere.directions(), sphere.solid_angles(), 0)?;
        let normals = prepared.receivers.iter().map(|r| r.normal).collect();
        Ok(GpuVisibility::new(
            run,
            &gpu.device,
            &gpu.queue,
            sphere,
            normals,
        ))
    }

    /// Runs the GPU backend in use for the columns `first..k` (pipelines built on first use);
    /// the results stay on the GPU.
    #[cfg(feature = "gpu")]
    fn run_gpu(
        &mut self,
        prepared: &Prepared,
        directions: &[glam::Vec3],
        solid_angles: &[f64],
        first: usize,
    ) -> Result<(&Gpu, DepthRun), OcclusionError> {
        self.check_params()?;
        let params = self.params.depth;
        let cpu_params = self.params.cpu;
        let ticker = std::sync::Arc::new(self.ticker(
            prepared.receivers.len(),
            directions.len().saturating_sub(first),
        ));
        let Self {
            state, last_bvh, ..
        } = self;
        match state {
            State::Cpu { .. } => Err(OcclusionError::NoDevice {
                backend: Backend::Cpu.name(),
            }),
            State::Depth { gpu, pipelines } => {
                let depth = pipelines.get_or_insert_with(|| DepthPipelines::new(&gpu.device));
                let run = depth.run(
                    &gpu.device,
                    &gpu.queue,
                    prepared,
                    directions,
                    solid_angles,
                    first,
                    &params,
                    &ticker,
                )?;
                Ok((gpu, run))
            }
            State::Query { gpu, pipelines } => {
                let (depth, query) = pipelines.get_or_insert_with(|| {
                    (
                        DepthPipelines::new(&gpu.device),
                        QueryPipelines::new(&gpu.device),
                    )
                });
                let run = query.run(
                    depth,
                    &gpu.device,
                    &gpu.queue,
                    prepared,
                    directions,
                    solid_angles,
                    first,
                    &params,
                    &ticker,
                )?;
                Ok((gpu, run))
            }
            State::Rays {
                gpu,
                pipelines,
                tree,
            } => {
                let rays = pipelines.get_or_insert_with(|| RayPipelines::new(&gpu.device));
                let (run, stats) = rays.run(
                    &gpu.device,
                    &gpu.queue,
                    prepared,
                    directions,
                    solid_angles,
                    first,
                    &cpu_params,
                    tree,
                    &ticker,
                )?;
                *last_bvh = stats;
                Ok((gpu, run))
            }
        }
    }

    /// Checks the parameters against the backend in use: the `cpu` knobs, and no
    /// `max_distance` on the depth-map backends (they cannot bound their rays).
    fn check_params(&self) -> Result<(), OcclusionError> {
        self.params.cpu.validate()?;
        let max_distance = self.params.cpu.max_distance;
        if max_distance.is_finite() && matches!(self.backend(), Backend::Depth | Backend::Query) {
            return Err(OcclusionError::InvalidParameter {
                what: "max_distance",
                value: f64::from(max_distance),
                expected: "infinite on the depth and query backends (only the cpu and rays \
                           backends bound their rays)",
            });
        }
        Ok(())
    }

    /// Computes the columns `first_new..k` of `matrix`.
    fn fill(
        &mut self,
        prepared: &Prepared,
        matrix: &mut VisibilityMatrix,
        first_new: usize,
    ) -> Result<(), OcclusionError> {
        let k = matrix.directions_len();
        self.last_rays = 0;
        self.check_params()?;
        if first_new >= k {
            return Ok(());
        }
        let ticker = self.ticker(matrix.rows(), k - first_new);
        match &mut self.state {
            State::Cpu {
                tracer: cached,
                costs,
            } => {
                let method = self.params.cpu.method.resolve(k - first_new);
                let cells = (matrix.rows() * (k - first_new)) as f64;
                let start = std::time::Instant::now();
                let timed = self.params.cpu.refit_timed;
                let worth_keeping = |ratio: f32| costs.worth_keeping(ratio, cells, timed);
                let mut update = match cached.as_mut() {
                    Some(t) if t.fits(prepared, method) => BvhUpdate::Reused,
                    Some(t) if self.params.cpu.refit => match t.refit(prepared, method) {
                        Some(sah_ratio) if worth_keeping(sah_ratio) => {
                            BvhUpdate::Refitted { sah_ratio }
                        }
                        _ => BvhUpdate::Built,
                    },
                    _ => BvhUpdate::Built,
                };
                if update == BvhUpdate::Built {
                    *cached = None;
                }
                let tracer = cached.get_or_insert_with(|| {
                    update = BvhUpdate::Built;
                    Tracer::new(prepared, method)
                });
                let bvh_ms = start.elapsed().as_secs_f64() * 1e3;
                self.last_bvh = BvhStats {
                    update,
                    millis: bvh_ms,
                };
                let words_per_row = matrix.words_per_row();
                let directions = matrix.directions().to_vec();
                let start = std::time::Instant::now();
                self.last_rays = compute_columns(
                    prepared,
                    tracer,
                    &directions,
                    first_new..k,
                    &self.params.cpu,
                    ColumnsTarget {
                        bits: matrix.bits_mut(),
                        words_per_row,
                        ticker: &ticker,
                    },
                );
                let per_cell = start.elapsed().as_secs_f64() * 1e3 / cells.max(1.0);
                match update {
                    BvhUpdate::Built => {
                        *costs = TreeCosts {
                            build_ms: bvh_ms,
                            fresh_ms_per_cell: per_cell,
                            last_ms_per_cell: per_cell,
                        };
                    }
                    BvhUpdate::Refitted { .. } => costs.last_ms_per_cell = per_cell,
                    BvhUpdate::Reused | BvhUpdate::None => {}
                }
                Ok(())
            }
            #[cfg(feature = "gpu")]
            State::Depth { .. } | State::Query { .. } | State::Rays { .. } => {
                let directions = matrix.directions().to_vec();
                let solid_angles = matrix.solid_angles().to_vec();
                let (gpu, run) = self.run_gpu(prepared, &directions, &solid_angles, first_new)?;
                run.read_bits_into(&gpu.device, &gpu.queue, matrix, first_new)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::TreeCosts;

    #[test]
    fn a_refitted_tree_is_kept_while_its_extra_traversal_costs_less_than_a_build() {
        // The drape at k = 258: a 2.2 ms build, 37 ms of traversal on a fresh tree.
        let cells = 1000.0;
        let fresh = 37.0 / cells;
        let costs = TreeCosts {
            build_ms: 2.2,
            fresh_ms_per_cell: fresh,
            last_ms_per_cell: fresh,
        };
        // 5 % more traversal (1.85 ms) is cheaper than a build, 7 % (2.59 ms) is not.
        assert!(costs.worth_keeping(1.05, cells, true));
        assert!(!costs.worth_keeping(1.07, cells, true));
        // Without the clock only the SAH cap decides.
        assert!(costs.worth_keeping(1.4, cells, false));
        assert!(costs.worth_keeping(crate::REBUILD_SAH_RATIO, cells, false));
        assert!(!costs.worth_keeping(crate::REBUILD_SAH_RATIO + 0.01, cells, false));
        assert!(!costs.worth_keeping(crate::REBUILD_SAH_RATIO + 0.01, 0.0, true));
        // A refitted frame measured 10 % slower (3.7 ms more) than the fresh tree: rebuild,
        // even where the SAH ratio alone (1.02: 0.74 ms) would keep it.
        let slowed = TreeCosts {
            last_ms_per_cell: fresh * 1.1,
            ..costs
        };
        assert!(costs.worth_keeping(1.02, cells, true));
        assert!(!slowed.worth_keeping(1.02, cells, true));
        assert!(slowed.worth_keeping(1.02, cells, false));
    }
}
