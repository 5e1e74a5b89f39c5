//! One API over the backends: compute M for a scene and a lightsphere, refine it to a finer
//! level reusing the columns already computed (paper 000 §3.4, §4.2), read the ambient term.

use lightsphere::Lightsphere;

use crate::cpu::{CpuParams, CpuTracer, compute_columns};
use crate::gpu::{DepthParams, DepthPipelines};
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
}

impl Backend {
    /// The backend's name as the CLI spells it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Cpu => "cpu",
            Self::Depth => "depth",
        }
    }
}

/// Tuning knobs of all backends.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[non_exhaustive]
pub struct VisibilityParams {
    /// `cpu` backend knobs.
    pub cpu: CpuParams,
    /// `depth` backend knobs.
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

struct Gpu {
    device: wgpu::Device,
    queue: wgpu::Queue,
    pipelines: Option<DepthPipelines>,
}

/// Computes visibility matrices with a chosen backend.
pub struct VisibilityEngine {
    backend: Backend,
    params: VisibilityParams,
    gpu: Option<Gpu>,
    last_rays: u64,
}

impl VisibilityEngine {
    /// The `cpu` backend.
    pub fn cpu(params: VisibilityParams) -> Self {
        Self {
            backend: Backend::Cpu,
            params,
            gpu: None,
            last_rays: 0,
        }
    }

    /// Any backend; GPU backends run on `device` and `queue` (cloned handles are kept). The
    /// pipelines are built on first use.
    pub fn with_gpu(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        backend: Backend,
        params: VisibilityParams,
    ) -> Self {
        Self {
            backend,
            params,
            gpu: Some(Gpu {
                device: device.clone(),
                queue: queue.clone(),
                pipelines: None,
            }),
            last_rays: 0,
        }
    }

    /// The backend in use.
    pub fn backend(&self) -> Backend {
        self.backend
    }

    /// The parameters in use.
    pub fn params(&self) -> &VisibilityParams {
        &self.params
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

    /// The ambient term a_i only. On the `depth` backend it is accumulated on the GPU and
    /// only N floats are read back; on `cpu` it is derived from M.
    ///
    /// # Errors
    /// As [`VisibilityEngine::compute`].
    pub fn ambient(
        &mut self,
        scene: &Scene,
        sphere: &Lightsphere,
    ) -> Result<Vec<f32>, OcclusionError> {
        match self.backend {
            Backend::Cpu => Ok(self.compute(scene, sphere)?.ambient()),
            Backend::Depth => {
                let prepared = Prepared::new(scene)?;
                let params = self.params.depth;
                let (gpu, pipelines) = self.gpu_pipelines()?;
                let run = pipelines.run(
                    &gpu.device,
                    &gpu.queue,
                    &prepared,
                    sphere.directions(),
                    sphere.solid_angles(),
                    0,
                    &params,
                )?;
                run.read_ambient(&gpu.device, &gpu.queue)
            }
        }
    }

    fn gpu_pipelines(&mut self) -> Result<(&Gpu, &DepthPipelines), OcclusionError> {
        let backend = self.backend.name();
        let gpu = self
            .gpu
            .as_mut()
            .ok_or(OcclusionError::NoDevice { backend })?;
        if gpu.pipelines.is_none() {
            gpu.pipelines = Some(DepthPipelines::new(&gpu.device));
        }
        let gpu = &*gpu;
        match &gpu.pipelines {
            Some(pipelines) => Ok((gpu, pipelines)),
            None => unreachable!("pipelines were just built"),
        }
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
        if first_new >= k {
            return Ok(());
        }
        match self.backend {
            Backend::Cpu => {
                let tracer = CpuTracer::new(prepared);
                let words_per_row = matrix.words_per_row();
                let directions = matrix.directions().to_vec();
                self.last_rays = compute_columns(
                    prepared,
                    &tracer,
                    &directions,
                    first_new..k,
                    &self.params.cpu,
                    matrix.bits_mut(),
                    words_per_row,
                );
                Ok(())
            }
            Backend::Depth => {
                let params = self.params.depth;
                let directions = matrix.directions().to_vec();
                let solid_angles = matrix.solid_angles().to_vec();
                let (gpu, pipelines) = self.gpu_pipelines()?;
                let run = pipelines.run(
                    &gpu.device,
                    &gpu.queue,
                    prepared,
                    &directions,
                    &solid_angles,
                    first_new,
                    &params,
                )?;
                run.read_bits_into(&gpu.device, &gpu.queue, matrix, first_new)
            }
        }
    }
}
