//! A Lambertian BTF: every image is albedo · cos θ_l (no mesostructure, no view dependence) —
//! the oracle of environment lighting: under a uniform environment of radiance L with nothing
//! in the way, a Lambertian surface reflects ρ L whatever the view, the light sampling or the
//! map's resolution.

use glam::Vec3;

use crate::error::{Result, check_range};

/// A `res × res` Lambertian material: a checkerboard of two albedos (4 × 4 squares), so a
/// texel lookup that lands on the wrong texel shows.
///
/// ```
/// use glam::Vec3;
/// let btf = synth::LambertianBtf::new(8, Vec3::splat(0.8), Vec3::splat(0.2))?;
/// let lit = btf.image(Vec3::new(0.6, 0.0, 0.8)); // cos θ = 0.8
/// assert_eq!(lit[0], [0.8 * 0.8; 3]);
/// assert_eq!(btf.albedo(2, 0), Vec3::splat(0.2));
/// assert!(btf.image(Vec3::new(0.0, 0.6, -0.8)).iter().all(|t| *t == [0.0; 3]));
/// assert!(synth::LambertianBtf::new(0, Vec3::ONE, Vec3::ONE).is_err());
/// # Ok::<(), synth::SynthError>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct LambertianBtf {
    res: usize,
    albedo: Vec<Vec3>,
}

impl LambertianBtf {
    /// The checkerboard of `a` and `b` (linear RGB albedos in [0, 1]) at `res × res`
    /// (1 ..= 4096).
    ///
    /// # Errors
    /// [`crate::SynthError::InvalidParameter`] naming `res`, `a` or `b`.
    pub fn new(res: usize, a: Vec3, b: Vec3) -> Result<Self> {
        check_range(
            "LambertianBtf res",
            res as f32,
            1.0,
            4096.0,
            "1 ..= 4096 texels",
        )?;
        for (name, c) in [("LambertianBtf a", a), ("LambertianBtf b", b)] {
            for v in c.to_array() {
                check_range(name, v, 0.0, 1.0, "albedos in [0, 1]")?;
            }
        }
        let square = res.div_ceil(4).max(1);
        let albedo = (0..res * res)
            .map(|i| {
                let (x, y) = (i % res, i / res);
                if (x / square + y / square).is_multiple_of(2) {
                    a
                } else {
                    b
                }
            })
            .collect();
        Ok(Self { res, albedo })
    }

    /// Texels per side.
    pub fn res(&self) -> usize {
        self.res
    }

    /// The albedo ρ of texel (x, y), row-major.
    pub fn albedo(&self, x: usize, y: usize) -> Vec3 {
        self.albedo[y * self.res + x]
    }

    /// The image under a directional light (unit `light_dir_in_tangent`, z = normal) of
    /// irradiance π at normal incidence: ρ · max(cos θ_l, 0) per texel, for any view.
    pub fn image(&self, light_dir_in_tangent: Vec3) -> Vec<[f32; 3]> {
        let cos = light_dir_in_tangent.z.max(0.0);
        self.albedo.iter().map(|a| (*a * cos).to_array()).collect()
    }
}
