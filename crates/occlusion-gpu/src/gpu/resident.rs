//! The GPU-resident visibility matrix (paper 000 §8.1: "It would be a great performance
//! increase, if this result would be available directly on the GPU"): M stays on the GPU from
//! frame to frame; only what is asked for is read back.

use lightsphere::Lightsphere;

use super::DepthRun;
use crate::{OcclusionError, VisibilityMatrix};

/// The visibility matrix M and the ambient term a_i of one `depth` or `query` computation,
/// kept in GPU storage buffers (from [`VisibilityEngine::compute_resident`]).
///
/// A renderer binds [`GpuVisibility::bits_buffer`] and [`GpuVisibility::ambient_buffer`]
/// directly, so M stays on the GPU from frame to frame (§8.1); only what is asked for is read
/// back: [`GpuVisibility::read_ambient`] reads N floats, [`GpuVisibility::read_matrix`] the
/// N·⌈k/32⌉ words of bits.
///
/// Layout of the bits buffer: row-major, [`GpuVisibility::words_per_row`] u32 words per
/// receiver vertex, direction j in bit `j % 32` of word `i · words_per_row + j / 32`; a set
/// bit means vertex i is unoccluded towards l_j and n_i·l_j > 0, so M_ij = n_i·l_j (§3.2).
/// The ambient buffer holds a_i = (1/π) Σ_j ω_j M_ij as one f32 per vertex; on the GPU a
/// vertex with a zero normal has an all-zero row and a_i = 0 (the read-back turns it to NaN).
///
/// [`VisibilityEngine::compute_resident`]: crate::VisibilityEngine::compute_resident
pub struct GpuVisibility {
    run: DepthRun,
    device: wgpu::Device,
    queue: wgpu::Queue,
    sphere: Lightsphere,
    normals: Vec<glam::Vec3>,
}

impl std::fmt::Debug for GpuVisibility {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GpuVisibility")
            .field("rows", &self.rows())
            .field("directions", &self.directions_len())
            .field("words_per_row", &self.words_per_row())
            .finish_non_exhaustive()
    }
}

impl GpuVisibility {
    pub(crate) fn new(
        run: DepthRun,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        sphere: &Lightsphere,
        normals: Vec<glam::Vec3>,
    ) -> Self {
        assert_eq!(run.rows(), normals.len(), "one normal per row");
        Self {
            run,
            device: device.clone(),
            queue: queue.clone(),
            sphere: sphere.clone(),
            normals,
        }
    }

    /// Number of rows N (receiver vertices).
    pub fn rows(&self) -> usize {
        self.run.rows()
    }

    /// Number of directions k (columns).
    pub fn directions_len(&self) -> usize {
        self.sphere.len()
    }

    /// u32 words per row of [`GpuVisibility::bits_buffer`], ⌈k/32⌉.
    pub fn words_per_row(&self) -> usize {
        self.run.words_per_row()
    }

    /// The lightsphere the columns belong to.
    pub fn lightsphere(&self) -> &Lightsphere {
        &self.sphere
    }

    /// The visibility bits (usage `STORAGE | COPY_SRC`, at least
    /// `rows · words_per_row · 4` bytes); see the type's docs for the layout.
    pub fn bits_buffer(&self) -> &wgpu::Buffer {
        self.run.bits_buffer()
    }

    /// a_i, one f32 per receiver vertex (usage `STORAGE | COPY_SRC`).
    pub fn ambient_buffer(&self) -> &wgpu::Buffer {
        self.run.ambient_buffer()
    }

    /// Reads a_i back (N floats; NaN for vertices with a zero normal).
    ///
    /// # Errors
    /// [`OcclusionError::Readback`] when mapping the buffer fails.
    pub fn read_ambient(&self) -> Result<Vec<f32>, OcclusionError> {
        self.run.read_ambient(&self.device, &self.queue)
    }

    /// Reads the bits back into a [`VisibilityMatrix`] (equal to what
    /// [`VisibilityEngine::compute`](crate::VisibilityEngine::compute) returns).
    ///
    /// # Errors
    /// [`OcclusionError::Readback`] when mapping the buffer fails.
    pub fn read_matrix(&self) -> Result<VisibilityMatrix, OcclusionError> {
        let mut matrix = VisibilityMatrix::zeros(self.normals.clone(), &self.sphere);
        self.run
            .read_bits_into(&self.device, &self.queue, &mut matrix, 0)?;
        Ok(matrix)
    }
}
