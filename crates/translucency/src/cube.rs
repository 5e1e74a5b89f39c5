//! Cube maps: the face layout shared by the GPU pass and the CPU reference, texel directions
//! and exact texel solid angles (SEED-NOTES §5.6).
//!
//! Faces in wgpu's (Vulkan's, D3D's) order +X, −X, +Y, −Y, +Z, −Z; each face is `size` × `size`
//! texels, row 0 at the top. Texel (row, col) of a face with axes (forward, right, up) looks
//! along forward + u·right + v·up with u = 2(col + ½)/size − 1 and v = 1 − 2(row + ½)/size —
//! the same (u, v) as the face camera's normalised device coordinates, so a face rendered with
//! clip = (p·right, p·up, …, p·forward) lands texel for texel.
//!
//! The solid angle of the texel spanning [x0, x1] × [y0, y1] on the face plane at distance 1 is
//! A(x0, y0) − A(x0, y1) − A(x1, y0) + A(x1, y1) with A(x, y) = atan2(xy, √(x² + y² + 1)) —
//! exact, and it sums to 4π over the cube (tested); Δω ≈ ΔA/(u² + v² + 1)^{3/2} is its
//! first-order form.

use glam::DVec3;

use crate::error::{TranslucencyError, bad_parameter};
use crate::sh::{SH_COUNT, basis};

/// (forward, right, up) of each face, in wgpu's order.
pub const FACES: [[DVec3; 3]; 6] = [
    [DVec3::X, DVec3::NEG_Z, DVec3::Y],
    [DVec3::NEG_X, DVec3::Z, DVec3::Y],
    [DVec3::Y, DVec3::X, DVec3::NEG_Z],
    [DVec3::NEG_Y, DVec3::X, DVec3::Z],
    [DVec3::Z, DVec3::X, DVec3::Y],
    [DVec3::NEG_Z, DVec3::NEG_X, DVec3::Y],
];

/// Largest accepted face size (a 4096² face is 400 MB of f32 RGB over six faces).
pub const MAX_FACE_SIZE: usize = 4096;

/// A cube map of linear RGB texels, six faces in [`FACES`] order.
#[derive(Clone, Debug, PartialEq)]
pub struct CubeMap {
    size: usize,
    texels: Vec<[f32; 3]>,
}

impl CubeMap {
    /// A cube map from 6 × `size`² texels (face-major, then row-major).
    ///
    /// # Errors
    /// A zero or too large size, a texel count that does not match, or a non-finite texel.
    pub fn new(size: usize, texels: Vec<[f32; 3]>) -> Result<Self, TranslucencyError> {
        if size == 0 || size > MAX_FACE_SIZE {
            return Err(bad_parameter("cube face size", size, "must be 1 ..= 4096"));
        }
        if texels.len() != 6 * size * size {
            return Err(bad_parameter(
                "cube texel count",
                texels.len(),
                "must be 6 × size²",
            ));
        }
        if let Some(i) = texels.iter().position(|t| t.iter().any(|v| !v.is_finite())) {
            return Err(bad_parameter(
                "cube texel",
                format!("#{i} = {:?}", texels[i]),
                "must be finite",
            ));
        }
        Ok(Self { size, texels })
    }

    /// A cube map whose texel values are `f` at each texel centre's direction.
    ///
    /// # Errors
    /// As [`CubeMap::new`].
    pub fn from_fn(
        size: usize,
        mut f: impl FnMut(DVec3) -> [f32; 3],
    ) -> Result<Self, TranslucencyError> {
        if size == 0 || size > MAX_FACE_SIZE {
            return Err(bad_parameter("cube face size", size, "must be 1 ..= 4096"));
        }
        let texels = (0..6 * size * size)
            .map(|i| f(texel_direction(size, i)))
            .collect();
        Self::new(size, texels)
    }

    /// Texels per face edge.
    #[must_use]
    pub fn size(&self) -> usize {
        self.size
    }

    /// All texels, face-major then row-major.
    #[must_use]
    pub fn texels(&self) -> &[[f32; 3]] {
        &self.texels
    }

    /// Per texel, Y_lm(centre) · Δω (the weights of [`crate::Sh9::project_cube`] and of the
    /// GPU reduction).
    #[must_use]
    pub fn projection_weights(&self) -> Vec<[f64; SH_COUNT]> {
        projection_weights(self.size)
    }
}

/// Unit direction of texel `index` (face-major, row-major) of a cube with `size`² faces.
#[must_use]
pub fn texel_direction(size: usize, index: usize) -> DVec3 {
    let face = index / (size * size);
    let rest = index % (size * size);
    let (row, col) = (rest / size, rest % size);
    let n = size as f64;
    let u = 2.0 * (col as f64 + 0.5) / n - 1.0;
    let v = 1.0 - 2.0 * (row as f64 + 0.5) / n;
    let [f, r, up] = FACES[face];
    (f + u * r + v * up).normalize()
}

/// Exact solid angle of texel (row, col) of any face of a cube with `size`² faces.
#[must_use]
pub fn texel_solid_angle(size: usize, row: usize, col: usize) -> f64 {
    let n = size as f64;
    let x0 = 2.0 * col as f64 / n - 1.0;
    let x1 = 2.0 * (col + 1) as f64 / n - 1.0;
    let y0 = 2.0 * row as f64 / n - 1.0;
    let y1 = 2.0 * (row + 1) as f64 / n - 1.0;
    let a = |x: f64, y: f64| (x * y).atan2((x * x + y * y + 1.0).sqrt());
    a(x0, y0) - a(x0, y1) - a(x1, y0) + a(x1, y1)
}

/// Per texel of a `size`² cube, Y_lm(centre) · Δω.
#[must_use]
pub fn projection_weights(size: usize) -> Vec<[f64; SH_COUNT]> {
    let face: Vec<f64> = (0..size * size)
        .map(|i| texel_solid_angle(size, i / size, i % size))
        .collect();
    (0..6 * size * size)
        .map(|i| {
            let omega = face[i % (size * size)];
            basis(texel_direction(size, i)).map(|y| y * omega)
        })
        .collect()
}
