//! The CPU reference renderer: homogeneous rasterisation with a depth test, then per pixel the
//! Chen et al. (2002) blend of the three vertices' BTF textures (thesis §5.5, eqs. 5.4–5.5).

use glam::{DVec3, Mat4, Vec2, Vec3};
use rayon::prelude::*;

use super::image::RenderedImage;
use super::mesh::{BtfMesh, Camera, Light, RenderParams};
use super::shade::VertexShading;
use crate::env::EnvLightWeights;
use crate::error::Result;
use crate::model::BtfPca;

/// A pixel centre whose barycentric weight is above −this still counts as inside, so that a
/// pixel centre exactly on an edge shared by two triangles is covered by at least one of them
/// despite f64 rounding (the blend is continuous across edges, so either gives the same
/// colour). 10⁻⁹ is far above f64 rounding of O(1) weights and far below a pixel.
const INSIDE_EPS: f64 = 1e-9;

/// The nearest surface at one pixel: its triangle and perspective-correct barycentrics.
#[derive(Clone, Copy, Debug)]
struct Fragment {
    triangle: u32,
    bary: [f32; 3],
}

/// Renders `mesh` textured by `pca` under `light`, seen by `camera`, on the CPU.
///
/// Per vertex: view and light directions in the tangent frame, view slots and ω_m (eq. 5.5),
/// γ per slot (eq. 5.3). Per pixel: the nearest triangle (depth test), perspective-correct
/// barycentrics b_v, uv = Σ_v b_v uv_v, the nearest texel (wrap), and
/// g · Σ_v b_v Σ_m ω_{v,m} Σ_k γ_{v,k j_m} B_{k j_m}(texel). See the [module docs](super).
///
/// # Errors
/// [`BtfError::LengthMismatch`](crate::BtfError::LengthMismatch),
/// [`BtfError::InvalidParameter`](crate::BtfError::InvalidParameter) or
/// [`BtfError::NonFinite`](crate::BtfError::NonFinite) for an invalid mesh (see
/// [`BtfMesh::validate`]), camera ([`Camera::clip_from_world`]), light or parameters.
pub fn render_cpu(
    pca: &BtfPca,
    mesh: &BtfMesh<'_>,
    light: &Light,
    camera: &Camera,
    params: &RenderParams,
) -> Result<RenderedImage> {
    light.validate()?;
    let frames = mesh.frames()?;
    let shading = VertexShading::compute(pca, mesh, &frames, light, camera.eye);
    render_shaded(pca, mesh, &shading, light.radiance(), camera, params)
}

/// Renders `mesh` textured by `pca` under an environment on the CPU (thesis §5.5.2): as
/// [`render_cpu`], with RGB γ* per vertex and slot from `w[v]`, the environment binned for
/// vertex v ([`crate::env`]; its visibility and radiance are already in it).
///
/// # Errors
/// As [`render_cpu`]; [`crate::BtfError::LengthMismatch`] unless `w` has one entry per
/// vertex.
pub fn render_cpu_env(
    pca: &BtfPca,
    mesh: &BtfMesh<'_>,
    w: &[EnvLightWeights],
    camera: &Camera,
    params: &RenderParams,
) -> Result<RenderedImage> {
    check_env_len(mesh, w)?;
    let frames = mesh.frames()?;
    let shading = VertexShading::compute_env(pca, mesh, &frames, w, camera.eye);
    render_shaded(pca, mesh, &shading, Vec3::ONE, camera, params)
}

/// One environment entry per vertex.
pub(crate) fn check_env_len(mesh: &BtfMesh<'_>, w: &[EnvLightWeights]) -> Result<()> {
    if w.len() != mesh.positions.len() {
        return Err(crate::BtfError::LengthMismatch {
            what: "environment weights per vertex",
            expected: mesh.positions.len(),
            found: w.len(),
            hint: "bin the environment for every vertex (EnvTransfer::update)",
        });
    }
    Ok(())
}

fn render_shaded(
    pca: &BtfPca,
    mesh: &BtfMesh<'_>,
    shading: &VertexShading,
    radiance: Vec3,
    camera: &Camera,
    params: &RenderParams,
) -> Result<RenderedImage> {
    let clip_from_world = camera.clip_from_world()?;
    params.validate()?;
    let (w, h) = (camera.width as usize, camera.height as usize);
    let fragments = rasterize(mesh, clip_from_world, w, h);

    let mut pixels = vec![params.background.to_array(); w * h];
    pixels
        .par_chunks_mut(w)
        .zip(fragments.par_chunks(w))
        .for_each(|(row, frags)| {
            for (px, frag) in row.iter_mut().zip(frags) {
                if let Some(f) = frag {
                    let rgb = shade_fragment(pca, mesh, shading, f, params.uv_scale);
                    // A truncated PCA rings slightly below zero in dark texels: radiance
                    // is clamped at 0, as the GPU shader does.
                    *px = (radiance * Vec3::from_array(rgb))
                        .max(Vec3::ZERO)
                        .to_array();
                }
            }
        });
    let coverage = fragments.iter().map(Option::is_some).collect();
    Ok(RenderedImage::new(
        camera.width,
        camera.height,
        pixels,
        coverage,
    ))
}

/// Σ_v b_v T_v(uv) at one fragment (before the light's radiance).
fn shade_fragment(
    pca: &BtfPca,
    mesh: &BtfMesh<'_>,
    shading: &VertexShading,
    frag: &Fragment,
    uv_scale: Vec2,
) -> [f32; 3] {
    let ids = mesh.triangles[frag.triangle as usize].map(|i| i as usize);
    let [b0, b1, b2] = frag.bary;
    let uv = b0 * mesh.uvs[ids[0]] + b1 * mesh.uvs[ids[1]] + b2 * mesh.uvs[ids[2]];
    let (x, y) = pca.nearest_texel(uv.x * uv_scale.x, uv.y * uv_scale.y);
    let mut rgb = [0.0f32; 3];
    for (&v, &b) in ids.iter().zip(&frag.bary) {
        let mut texture = [0.0f32; 3];
        for m in 0..4 {
            let omega = shading.omega[v][m];
            if omega == 0.0 {
                continue;
            }
            let j = shading.slots[v][m] as usize;
            let t = if shading.rgb {
                let g = shading.gamma(v, m);
                let rgb: Vec<Vec3> = (0..pca.gamma_len(j))
                    .map(|k| Vec3::new(g[3 * k], g[3 * k + 1], g[3 * k + 2]))
                    .collect();
                pca.texel_rgb(j, &rgb, x, y)
            } else {
                pca.texel(j, &shading.gamma(v, m)[..pca.gamma_len(j)], x, y)
            };
            for (o, t) in texture.iter_mut().zip(t) {
                *o += omega * t;
            }
        }
        for (o, t) in rgb.iter_mut().zip(texture) {
            *o += b * t;
        }
    }
    rgb
}

/// The nearest fragment of every pixel (row-major, top row first), or `None`.
///
/// Homogeneous rasterisation (Olano & Greer 1997): with the clip-space (x, y, w) of the three
/// corners as columns c_i of a matrix, the weights λ_i = (c_{i+1} × c_{i+2}) · (x_ndc, y_ndc, 1)
/// are proportional to the perspective-correct barycentrics of the pixel centre, for any sign
/// of w, so no clipping is needed: the pixel is covered when all b = λ / Σλ are ≥ 0, the
/// point's w = Σ b_i w_i is > 0, and its depth z/w lies in [0, 1] (the near and far planes).
fn rasterize(
    mesh: &BtfMesh<'_>,
    clip_from_world: Mat4,
    width: usize,
    height: usize,
) -> Vec<Option<Fragment>> {
    let clip: Vec<[f64; 4]> = mesh
        .positions
        .iter()
        .map(|p| (clip_from_world * p.extend(1.0)).to_array().map(f64::from))
        .collect();
    let mut depth = vec![f64::INFINITY; width * height];
    let mut out: Vec<Option<Fragment>> = vec![None; width * height];
    let (wf, hf) = (width as f64, height as f64);
    for (t, tri) in mesh.triangles.iter().enumerate() {
        let c = tri.map(|i| clip[i as usize]);
        let cols = c.map(|v| DVec3::new(v[0], v[1], v[3]));
        let edges = [
            cols[1].cross(cols[2]),
            cols[2].cross(cols[0]),
            cols[0].cross(cols[1]),
        ];
        if cols[0].dot(edges[0]) == 0.0 {
            continue; // degenerate: zero area on screen
        }
        let (x_range, y_range) = pixel_bounds(&c, width, height);
        for py in y_range {
            let y_ndc = 1.0 - 2.0 * (py as f64 + 0.5) / hf;
            for px in x_range.clone() {
                let x_ndc = 2.0 * (px as f64 + 0.5) / wf - 1.0;
                let q = DVec3::new(x_ndc, y_ndc, 1.0);
                let lambda = edges.map(|e| e.dot(q));
                let sum: f64 = lambda.iter().sum();
                if sum == 0.0 {
                    continue;
                }
                let b = lambda.map(|l| l / sum);
                if b.iter().any(|&bi| bi < -INSIDE_EPS) {
                    continue;
                }
                let w = b[0] * c[0][3] + b[1] * c[1][3] + b[2] * c[2][3];
                if w <= 0.0 {
                    continue;
                }
                let z = (b[0] * c[0][2] + b[1] * c[1][2] + b[2] * c[2][2]) / w;
                let p = py * width + px;
                if !(0.0..=1.0).contains(&z) || z >= depth[p] {
                    continue;
                }
                depth[p] = z;
                out[p] = Some(Fragment {
                    triangle: t as u32,
                    bary: b.map(|bi| bi.max(0.0) as f32),
                });
            }
        }
    }
    out
}

/// The pixels whose centres can lie in the triangle: the screen bounding box when every
/// corner is in front of the eye (w > 0), else the whole image.
fn pixel_bounds(
    c: &[[f64; 4]; 3],
    width: usize,
    height: usize,
) -> (std::ops::Range<usize>, std::ops::Range<usize>) {
    if c.iter().any(|v| v[3] <= 0.0) {
        return (0..width, 0..height);
    }
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for v in c {
        // Pixel-centre coordinates: centre of pixel i is at i.
        let x = (v[0] / v[3] + 1.0) * 0.5 * width as f64 - 0.5;
        let y = (1.0 - v[1] / v[3]) * 0.5 * height as f64 - 0.5;
        (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
    }
    let range = |lo: f64, hi: f64, n: usize| {
        let lo = (lo.floor().max(0.0) as usize).min(n);
        let hi = ((hi.ceil() + 1.0).max(0.0) as usize).min(n);
        lo..hi.max(lo)
    };
    (range(x0, x1, width), range(y0, y1, height))
}
