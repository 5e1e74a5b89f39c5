//! Light-space frames of the `depth` backend: one orthographic box per direction, fitted to
//! the scene's bounding sphere (paper 000 §3.2: "We do this in orthographic projection mode").

use glam::{Mat4, Vec3, Vec4};

/// Relative margin added to the bounding-sphere radius so geometry exactly on the sphere is
/// not clipped by the box (tuned: any value ≫ f32 epsilon works).
pub const BOX_MARGIN: f32 = 1e-3;

/// One light as the shaders see it (`struct Light` in both WGSL files).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct LightGpu {
    pub clip_from_world: [f32; 16],
    /// xyz: unit l_j; w: ω_j / π.
    pub direction_weight: [f32; 4],
}

/// The orthographic light box of a scene centred at the origin with bounding radius `radius`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LightBox {
    /// Half-width of the box (and half its depth range).
    pub half_extent: f32,
}

impl LightBox {
    pub(crate) fn new(radius: f32) -> Self {
        // A scene of coincident points still needs a non-empty box.
        let radius = if radius > 0.0 && radius.is_finite() {
            radius
        } else {
            1.0
        };
        Self {
            half_extent: radius * (1.0 + BOX_MARGIN),
        }
    }

    /// clip_from_world for light direction `l` (unit, pointing towards the light): the eye
    /// at 2R along l looking at the centre, near = R, far = 3R, so the sphere maps into depth
    /// 0..1 with the depth range equal to the box width.
    pub(crate) fn clip_from_world(&self, l: Vec3) -> Mat4 {
        let r = self.half_extent;
        let up = if l.y.abs() < 0.9 { Vec3::Y } else { Vec3::X };
        let view = glam::camera::rh::view::look_at_mat4(l * (2.0 * r), Vec3::ZERO, up);
        let proj = glam::camera::rh::proj::directx::orthographic(-r, r, -r, r, r, 3.0 * r);
        proj * view
    }

    /// All lights of a direction set with solid-angle weights.
    pub(crate) fn lights(&self, directions: &[Vec3], solid_angles: &[f64]) -> Vec<LightGpu> {
        directions
            .iter()
            .zip(solid_angles)
            .map(|(&l, &omega)| LightGpu {
                clip_from_world: self.clip_from_world(l).to_cols_array(),
                direction_weight: Vec4::from((l, (omega / std::f64::consts::PI) as f32)).to_array(),
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sphere_maps_into_the_unit_depth_range() {
        let light_box = LightBox::new(2.0);
        for l in [Vec3::X, Vec3::Y, -Vec3::Y, Vec3::new(0.6, 0.0, 0.8)] {
            let m = light_box.clip_from_world(l);
            // The point nearest the light has depth ≈ 0, the farthest ≈ 1, the centre ½.
            let near = m.project_point3(l * 2.0);
            let far = m.project_point3(-l * 2.0);
            let centre = m.project_point3(Vec3::ZERO);
            assert!(near.z.abs() < 2e-3, "{l}: near depth {}", near.z);
            assert!((far.z - 1.0).abs() < 2e-3, "{l}: far depth {}", far.z);
            assert!((centre.z - 0.5).abs() < 1e-5 && centre.x.abs() < 1e-5);
        }
    }
}
