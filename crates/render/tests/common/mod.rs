//! Helpers shared by the render crate's tests.
#![allow(dead_code)]

use glam::Vec3;
use gpu_context::GpuContext;
use render::{DrawMesh, RenderError, Renderer};

/// Give the Gouraud pass exactly one mesh.
pub fn one_mesh(
    renderer: &mut Renderer,
    gpu: &GpuContext,
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    front: &[Vec3],
    back: &[Vec3],
) -> Result<(), RenderError> {
    renderer.gouraud.set_meshes(
        &gpu.device,
        &gpu.queue,
        &[DrawMesh {
            positions,
            triangles,
            front,
            back,
        }],
    )
}
