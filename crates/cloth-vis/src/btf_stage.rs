//! The `btf` effect: a compressed BTF (thesis §5.4) on the scene's objects, rendered per
//! vertex and per fragment as §5.5 describes (crate `btf`, eqs. 5.2–5.5), beside the same
//! objects under plain texture mapping — the comparison of the thesis's Fig. 5.16.
//!
//! The material is a `.btfpca` file or `synth:woven`, the woven-cloth BTF of `synth`
//! compressed in memory slot by slot (no image files). "Plain texturing" is the BTF's frontal
//! normtexture (view θ = 0, light θ = 0) used as an ordinary diffuse texture: every view slot
//! holds it times the light's cosine, so the same renderer draws both halves and only the
//! material differs. Objects are drawn in scene order, each over the previous where it covers
//! pixels (no depth test between objects).

use std::path::{Path, PathBuf};
use std::time::Instant;

use btf::render::{BtfMesh, Camera as BtfCamera, Light, RenderParams, RenderedImage};
use btf::{BtfPca, BtfPcaParams, Sampling, ViewSlot};
use glam::{Vec2, Vec3};
use gpu_context::GpuContext;
use serde_json::json;

use crate::Error;
use crate::camera::{Camera, bounding_sphere};
use crate::run::WorldObject;
use crate::scene::Scene;

/// The woven BTF generated for `synth:woven`, compressed in memory with `components` terms
/// per view slot (H1 sampling).
///
/// # Errors
/// [`Error::Synth`] for bad generator parameters, [`Error::Btf`] if compression fails.
pub fn synth_material(res: usize, components: usize) -> Result<BtfPca, Error> {
    let woven = synth::WovenBtf::new(&synth::WovenBtfParams {
        res,
        ..Default::default()
    })?;
    let s = Sampling::H1;
    let load = |j: usize| -> btf::Result<ViewSlot> {
        let hits = woven
            .view(s.vector(j))
            .map_err(|e| btf::BtfError::InvalidParameter {
                what: "synth:woven",
                name: "view slot",
                value: format!("{j} ({e})"),
                reason: "the woven generator refused this view direction",
            })?;
        let data: Vec<f32> = (0..btf::DIRECTIONS)
            .flat_map(|i| hits.shade(s.vector(i)))
            .flatten()
            .collect();
        ViewSlot::new(j, res, res, data)
    };
    let params = BtfPcaParams {
        components,
        ..Default::default()
    };
    Ok(BtfPca::compress_with(s, res, res, &params, load, None)?.0)
}

/// Plain texture mapping in BTF form: the frontal normtexture of `pca` (view 0, light 0) times
/// max(cos θ_l, 0) for every view and light, one component per slot.
///
/// # Errors
/// [`Error::Btf`] if compression fails.
pub fn plain_material(pca: &BtfPca) -> Result<BtfPca, Error> {
    let s = pca.sampling();
    let (w, h) = (pca.width(), pca.height());
    // Light 0 is the pole, θ = 0: the texture under a frontal light, cosine 1.
    let frontal: Vec<[f32; 3]> = pca.image(0, 0);
    let load = |j: usize| {
        let data: Vec<f32> = (0..btf::DIRECTIONS)
            .flat_map(|i| {
                let cos = s.vector(i).z.max(0.0);
                frontal
                    .iter()
                    .flat_map(move |t| t.map(|c| c.max(0.0) * cos))
            })
            .collect();
        ViewSlot::new(j, w, h, data)
    };
    let params = BtfPcaParams {
        components: 1,
        ..Default::default()
    };
    Ok(BtfPca::compress_with(s, w, h, &params, load, None)?.0)
}

/// A rendered image: linear RGB and which pixels some object covers.
#[derive(Clone, Debug, PartialEq)]
pub struct Layer {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Linear RGB, row-major, top row first.
    pub pixels: Vec<[f32; 3]>,
    /// Whether an object covers the pixel.
    pub covered: Vec<bool>,
}

impl Layer {
    fn from_image(image: &RenderedImage) -> Self {
        Self {
            width: image.width(),
            height: image.height(),
            pixels: image.pixels().to_vec(),
            covered: image.coverage().to_vec(),
        }
    }

    /// Draws `image` over this layer where it covers pixels.
    fn over(&mut self, image: &RenderedImage) {
        for ((p, c), (q, d)) in self
            .pixels
            .iter_mut()
            .zip(self.covered.iter_mut())
            .zip(image.pixels().iter().zip(image.coverage()))
        {
            if *d {
                *p = *q;
                *c = true;
            }
        }
    }

    /// 8-bit sRGB (clamped to [0, 1] first).
    pub fn to_srgb8(&self) -> Vec<[u8; 3]> {
        self.pixels
            .iter()
            .map(|p| p.map(|c| btf::linear_to_srgb8(c.clamp(0.0, 1.0))))
            .collect()
    }
}

/// Renders `objects` (each with UVs) with `pca` through `camera` under `light`, on the GPU
/// when `gpu` is given and on the CPU reference otherwise, compositing them in order.
///
/// # Errors
/// An object without UVs ([`Error::Request`] naming it); renderer errors.
pub fn render_objects(
    gpu: Option<&GpuContext>,
    pca: &BtfPca,
    objects: &[&WorldObject],
    light: &Light,
    camera: &BtfCamera,
    params: &RenderParams,
) -> Result<Layer, Error> {
    let renderer = match gpu {
        Some(g) => Some(btf::render::GpuBtfRenderer::new(&g.device, &g.queue, pca)?),
        None => None,
    };
    let mut result: Option<Layer> = None;
    for object in objects {
        let uvs = object.uvs.as_deref().ok_or_else(|| Error::Request {
            path: PathBuf::from(&object.name),
            message: "a BTF needs texture coordinates and this object has none".to_owned(),
        })?;
        let tangents = btf::render::tangent_frames(
            &object.positions,
            &object.normals,
            uvs,
            &object.triangles,
        )?;
        let mesh = BtfMesh {
            positions: &object.positions,
            normals: &object.normals,
            tangents: &tangents,
            uvs,
            triangles: &object.triangles,
        };
        let image = match &renderer {
            Some(r) => r.render(&mesh, light, camera, params)?,
            None => btf::render::render_cpu(pca, &mesh, light, camera, params)?,
        };
        match &mut result {
            None => result = Some(Layer::from_image(&image)),
            Some(below) => below.over(&image),
        }
    }
    result.ok_or_else(|| Error::Request {
        path: PathBuf::from("btf.objects"),
        message: "no object to draw with the BTF".to_owned(),
    })
}

/// One image as 8-bit sRGB.
pub fn single(image: &Layer) -> image::RgbaImage {
    let mut out = image::RgbaImage::new(image.width, image.height);
    for (i, p) in image.to_srgb8().iter().enumerate() {
        let (x, y) = (i as u32 % image.width, i as u32 / image.width);
        out.put_pixel(x, y, image::Rgba([p[0], p[1], p[2], 255]));
    }
    out
}

/// Two images side by side, as 8-bit sRGB.
pub fn side_by_side(left: &Layer, right: &Layer) -> image::RgbaImage {
    let (w, h) = (left.width, left.height);
    let mut out = image::RgbaImage::new(2 * w, h);
    for (x0, img) in [(0, left), (w, right)] {
        for (i, p) in img.to_srgb8().iter().enumerate() {
            let (x, y) = (i as u32 % w, i as u32 / w);
            out.put_pixel(x0 + x, y, image::Rgba([p[0], p[1], p[2], 255]));
        }
    }
    out
}

/// Runs the `btf` stage of a scene: material, plain companion, both renderings, the PNG.
///
/// # Errors
/// Material, object and rendering errors; write errors naming the PNG.
pub(crate) fn run(
    scene: &Scene,
    out_dir: &Path,
    gpu: &GpuContext,
    objects: &[WorldObject],
) -> Result<(Vec<PathBuf>, serde_json::Value), Error> {
    let desc = &scene.btf;
    let start = Instant::now();
    let (pca, source) = match scene.btf_source()? {
        crate::scene::BtfSource::SynthWoven => (
            synth_material(desc.res, desc.components)?,
            format!("synth:woven ({0}x{0})", desc.res),
        ),
        crate::scene::BtfSource::File(path) => (BtfPca::read(&path)?, path.display().to_string()),
    };
    let material_ms = start.elapsed().as_secs_f64() * 1e3;
    let plain = plain_material(&pca)?;
    let chosen: Vec<&WorldObject> = objects
        .iter()
        .filter(|o| {
            if desc.objects.is_empty() {
                o.uvs.is_some()
            } else {
                desc.objects.contains(&o.name)
            }
        })
        .collect();
    let (centre, radius) = bounding_sphere(objects.iter().flat_map(|o| o.positions.iter()))
        .unwrap_or((Vec3::ZERO, 1.0));
    let framed = Camera::frame(&scene.camera, centre, radius);
    let camera = BtfCamera::look_at(
        framed.eye,
        framed.target,
        Vec3::from(scene.camera.up),
        scene.camera.fov_deg,
        scene.camera.width,
        scene.camera.height,
    );
    let light = Light::Directional {
        dir_to_light_world: Vec3::from(desc.light_dir),
        radiance: Vec3::from(desc.radiance),
    };
    let mut params = RenderParams::default();
    params.uv_scale = Vec2::splat(desc.uv_scale);
    let render_start = Instant::now();
    let with_btf = render_objects(Some(gpu), &pca, &chosen, &light, &camera, &params)?;
    let with_plain = render_objects(Some(gpu), &plain, &chosen, &light, &camera, &params)?;
    let render_ms = render_start.elapsed().as_secs_f64() * 1e3;
    let path = out_dir.join(&desc.png);
    crate::strip::write_png(&path, &side_by_side(&with_btf, &with_plain))?;
    let kept = pca.slots().iter().map(|s| s.components());
    let params = json!({
        "source": source,
        "objects": chosen.iter().map(|o| o.name.clone()).collect::<Vec<_>>(),
        "size": [pca.width(), pca.height()],
        "components": [kept.clone().min().unwrap_or(0), kept.max().unwrap_or(0)],
        "light_dir": desc.light_dir,
        "uv_scale": desc.uv_scale,
        "material_ms": material_ms,
        "render_ms": render_ms,
        "image": "left: BTF (§5.5), right: plain texture mapping (frontal normtexture)",
    });
    Ok((vec![path], params))
}
