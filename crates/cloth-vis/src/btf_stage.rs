//! The `btf` effect: a compressed BTF (thesis §5.4) on the scene's objects, rendered per
//! vertex and per fragment as §5.5 describes (crate `btf`, eqs. 5.2–5.5), beside the same
//! objects under plain texture mapping — the comparison of the thesis's Fig. 5.16.
//!
//! The material is a `.btfpca` file or `synth:woven`, the woven-cloth BTF of `synth`
//! compressed in memory slot by slot (no image files). "Plain texturing" is the BTF's frontal
//! normtexture (view θ = 0, light θ = 0) used as an ordinary diffuse texture: every view slot
//! holds it times the light's cosine, so the same renderer draws both halves and only the
//! material differs.
//!
//! In a scene, both halves are full frames of the shared renderer (crate `render`): the BTF
//! objects are a [`btf::render::BtfDraw`] pass and every other object (the ball, the ground)
//! is drawn by the Gouraud pass with its lighting, all against one depth buffer, so BTF
//! objects and plain objects occlude each other.

use std::path::PathBuf;
use std::time::Instant;

use btf::render::{BtfMesh, GpuBtfRenderer, Light, RenderParams};
use btf::{BtfPca, BtfPcaParams, Sampling, ViewSlot};
use glam::{Vec2, Vec4};
use gpu_context::{GpuContext, HdrImage};
use render::{Background, Camera, FrameFormat, FramePass, Renderer};

use crate::Error;
use crate::object::WorldObject;

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

/// The tangent frames of `object` (it needs UVs).
pub(crate) fn tangents_of(object: &WorldObject) -> Result<(Vec<Vec4>, &[Vec2]), Error> {
    let uvs = object.uvs.as_deref().ok_or_else(|| Error::Request {
        path: PathBuf::from(&object.name),
        message: "a BTF needs texture coordinates and this object has none".to_owned(),
    })?;
    let tangents =
        btf::render::tangent_frames(&object.positions, &object.normals, uvs, &object.triangles)?;
    Ok((tangents, uvs))
}

pub(crate) fn btf_mesh<'a>(
    object: &'a WorldObject,
    tangents: &'a [Vec4],
    uvs: &'a [Vec2],
) -> BtfMesh<'a> {
    BtfMesh {
        positions: &object.positions,
        normals: &object.normals,
        tangents,
        uvs,
        triangles: &object.triangles,
    }
}

/// Renders `objects` (each with UVs) with `pca` through `camera` under `light`: on the GPU
/// when `gpu` is given, all objects in one single-sample frame with one depth buffer (so
/// they occlude each other; single-sample so the CPU reference compares pixel for pixel), and
/// on the CPU reference otherwise, each object over the previous where it covers pixels.
///
/// # Errors
/// An object without UVs ([`Error::Request`] naming it); renderer errors.
pub fn render_objects(
    gpu: Option<&GpuContext>,
    pca: &BtfPca,
    objects: &[&WorldObject],
    light: &Light,
    camera: &Camera,
    params: &RenderParams,
) -> Result<HdrImage, Error> {
    if objects.is_empty() {
        return Err(Error::Request {
            path: PathBuf::from("btf.objects"),
            message: "no object to draw with the BTF".to_owned(),
        });
    }
    let frames = objects
        .iter()
        .map(|o| tangents_of(o))
        .collect::<Result<Vec<_>, _>>()?;
    if let Some(g) = gpu {
        let mut renderer = Renderer::new(&g.device, FrameFormat::single_sample(&g.device));
        let btf = GpuBtfRenderer::for_frame(&g.device, &g.queue, pca, &renderer.pass_context())?;
        let draws = objects
            .iter()
            .zip(&frames)
            .map(|(o, (t, uv))| btf.prepare(&btf_mesh(o, t, uv), light, camera, params))
            .collect::<Result<Vec<_>, _>>()?;
        let passes: Vec<&dyn FramePass> = draws.iter().map(|d| d as &dyn FramePass).collect();
        let background = Background::Color(params.background.to_array());
        let image = renderer.render(&g.device, &g.queue, camera, background, &passes)?;
        return Ok(image);
    }
    // The CPU reference: each object over the previous where it covers pixels.
    let mut result: Option<Vec<[f32; 4]>> = None;
    for (object, (tangents, uvs)) in objects.iter().zip(&frames) {
        let mesh = btf_mesh(object, tangents, uvs);
        let image = btf::render::render_cpu(pca, &mesh, light, camera, params)?.to_rgba();
        match &mut result {
            None => result = Some(image),
            Some(below) => {
                for (b, p) in below.iter_mut().zip(image) {
                    if p[3] > 0.0 {
                        *b = p;
                    }
                }
            }
        }
    }
    let pixels = result.ok_or_else(|| Error::Request {
        path: PathBuf::from("btf.objects"),
        message: "no object to draw with the BTF".to_owned(),
    })?;
    Ok(HdrImage::new(camera.width, camera.height, pixels)?)
}

/// What fins cost in a frame of [`render_with_fins`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FinCost {
    /// Fins drawn.
    pub fins: usize,
    /// Milliseconds of silhouette extraction and fin building on the CPU.
    pub extract_ms: f64,
    /// Milliseconds of fin lighting (γ per end) and upload.
    pub prepare_ms: f64,
    /// Median milliseconds of the frame with fins (draw and read-back; 3 runs).
    pub frame_ms: f64,
    /// Median milliseconds of the same frame without fins (3 runs).
    pub frame_without_ms: f64,
}

/// Renders `objects` with `pca` on the GPU as [`render_objects`] does, then again with the
/// fins of `fins` on every object (thesis §5.7): the image without fins, the image with them,
/// and what the fins cost.
///
/// # Errors
/// As [`render_objects`]; fin extraction and GPU-limit errors.
#[allow(clippy::too_many_arguments)] // one frame's inputs; a struct would only rename them
pub fn render_with_fins(
    g: &GpuContext,
    pca: &BtfPca,
    objects: &[&WorldObject],
    light: &Light,
    camera: &Camera,
    params: &RenderParams,
    fins: &btf::fin_pca::FinPca,
    look: &crate::fins_stage::FinLook,
) -> Result<(HdrImage, HdrImage, FinCost), Error> {
    let frames = objects
        .iter()
        .map(|o| tangents_of(o))
        .collect::<Result<Vec<_>, _>>()?;
    let mut renderer = Renderer::new(&g.device, FrameFormat::single_sample(&g.device));
    let btf = GpuBtfRenderer::for_frame(&g.device, &g.queue, pca, &renderer.pass_context())?;
    let fin_renderer = crate::fins_stage::fin_renderer(&g.device, fins, &renderer.pass_context())?;
    let draws = objects
        .iter()
        .zip(&frames)
        .map(|(o, (t, uv))| btf.prepare(&btf_mesh(o, t, uv), light, camera, params))
        .collect::<Result<Vec<_>, _>>()?;
    let fin_frame = crate::fins_stage::fin_frame(&fin_renderer, objects, light, camera, look)?;
    let background = Background::Color(params.background.to_array());
    let mut run = |with_fins: bool| -> Result<(HdrImage, f64), Error> {
        let mut passes: Vec<&dyn FramePass> = draws.iter().map(|d| d as &dyn FramePass).collect();
        if with_fins {
            passes.extend(fin_frame.draws.iter().map(|d| d as &dyn FramePass));
        }
        let mut times = Vec::with_capacity(3);
        let mut last = None;
        for _ in 0..3 {
            let start = Instant::now();
            last = Some(renderer.render(&g.device, &g.queue, camera, background, &passes)?);
            times.push(start.elapsed().as_secs_f64() * 1e3);
        }
        times.sort_by(f64::total_cmp);
        let image = last.ok_or_else(|| Error::Request {
            path: PathBuf::from("btf.fins"),
            message: "no frame was rendered".to_owned(),
        })?;
        Ok((image, times[1]))
    };
    let (without, frame_without_ms) = run(false)?;
    let (with, frame_ms) = run(true)?;
    Ok((
        without,
        with,
        FinCost {
            fins: fin_frame.fins,
            extract_ms: fin_frame.extract_ms,
            prepare_ms: fin_frame.prepare_ms,
            frame_ms,
            frame_without_ms,
        },
    ))
}

/// The seed's display of a BTF render: linear radiance clamped to [0, 1], then sRGB-encoded
/// (the normtextures are sRGB images, so a unit light shows them as measured); opaque.
fn display() -> render::tone::Display {
    render::tone::Display {
        exposure_ev: 0.0,
        curve: render::tone::ToneCurve::ClampSrgb,
    }
}

/// One image as 8-bit RGBA: clamped, sRGB-encoded (the seed's BTF display), opaque.
pub fn single(image: &HdrImage) -> image::RgbaImage {
    let rgba = render::output::to_rgba8(image, &display(), Background::Color([0.0; 3]));
    image::RgbaImage::from_raw(image.width(), image.height(), rgba)
        .unwrap_or_else(|| image::RgbaImage::new(image.width(), image.height()))
}

/// One image under an environment as 8-bit RGBA: automatic exposure from the object's pixels
/// (an HDR map's absolute radiance is arbitrary) and the filmic curve, as scene renders use,
/// so a sun-lit side keeps its gradation; opaque.
pub fn single_auto_exposed(image: &HdrImage) -> image::RgbaImage {
    single_exposed(image, render::output::auto_exposure(image))
}

/// As [`single_auto_exposed`] with a given exposure (EV), so a sequence keeps one exposure.
pub fn single_exposed(image: &HdrImage, exposure_ev: f32) -> image::RgbaImage {
    let display = render::tone::Display {
        exposure_ev,
        curve: render::tone::ToneCurve::AcesFitted,
    };
    let rgba = render::output::to_rgba8(image, &display, Background::Color([0.0; 3]));
    image::RgbaImage::from_raw(image.width(), image.height(), rgba)
        .unwrap_or_else(|| image::RgbaImage::new(image.width(), image.height()))
}

/// The triangles of `object` whose face material is `material` (per triangle in
/// `per_triangle`), as an object with the same vertices (so per-vertex data such as the
/// environment's W stays indexed alike); `None` when no triangle has it.
pub fn material_part(
    object: &WorldObject,
    per_triangle: &[Option<u32>],
    material: Option<u32>,
    name: &str,
) -> Option<WorldObject> {
    let triangles: Vec<[u32; 3]> = object
        .triangles
        .iter()
        .zip(per_triangle)
        .filter(|(_, m)| **m == material)
        .map(|(t, _)| *t)
        .collect();
    (!triangles.is_empty()).then(|| {
        WorldObject::textured(
            name,
            object.positions.clone(),
            object.normals.clone(),
            triangles,
            object.uvs.clone(),
        )
    })
}

/// Renders the parts of a mesh, each with its own BTF (thesis §5.6: garment parts), in one
/// GPU frame with one depth buffer, under `lit` (for [`Lit::Environment`], one W per part,
/// indexed by the part's vertices).
///
/// # Errors
/// A part without UVs; renderer errors.
pub fn render_parts(
    gpu: &GpuContext,
    parts: &[(&BtfPca, &WorldObject)],
    lit: &Lit,
    camera: &Camera,
    params: &RenderParams,
) -> Result<HdrImage, Error> {
    let mut renderer = Renderer::new(&gpu.device, FrameFormat::single_sample(&gpu.device));
    let background = Background::Color(params.background.to_array());
    render_items(
        gpu,
        &mut renderer,
        parts,
        lit,
        camera,
        background,
        params,
        &[],
    )
}

/// One frame of `renderer`: each item an object (or a part of one) with its BTF, a
/// [`btf::render::BtfDraw`] each, then `extra` passes (fins), under `lit`.
///
/// # Errors
/// An item without UVs; renderer errors.
#[allow(clippy::too_many_arguments)] // one frame's inputs; a struct would only rename them
pub(crate) fn render_items(
    gpu: &GpuContext,
    renderer: &mut Renderer,
    items: &[(&BtfPca, &WorldObject)],
    lit: &Lit,
    camera: &Camera,
    background: Background,
    params: &RenderParams,
    extra: &[&dyn FramePass],
) -> Result<HdrImage, Error> {
    let frames = items
        .iter()
        .map(|(_, o)| tangents_of(o))
        .collect::<Result<Vec<_>, _>>()?;
    let btfs = items
        .iter()
        .map(|(pca, _)| {
            GpuBtfRenderer::for_frame(&gpu.device, &gpu.queue, pca, &renderer.pass_context())
        })
        .collect::<Result<Vec<_>, _>>()?;
    let draws = items
        .iter()
        .zip(&frames)
        .zip(&btfs)
        .enumerate()
        .map(|(i, (((_, o), (t, uv)), btf))| {
            let mesh = btf_mesh(o, t, uv);
            match lit {
                Lit::Light(l) => btf.prepare(&mesh, l, camera, params),
                Lit::Environment(w) => btf.prepare_env(&mesh, &w[i], camera, params),
            }
        })
        .collect::<Result<Vec<_>, _>>()?;
    let mut passes: Vec<&dyn FramePass> = draws.iter().map(|d| d as &dyn FramePass).collect();
    passes.extend_from_slice(extra);
    Ok(renderer.render(&gpu.device, &gpu.queue, camera, background, &passes)?)
}

/// Two images of one size side by side, as 8-bit RGBA.
pub fn side_by_side(left: &HdrImage, right: &HdrImage) -> image::RgbaImage {
    let (l, r) = (single(left), single(right));
    let mut out = image::RgbaImage::new(l.width() + r.width(), l.height().max(r.height()));
    for (x0, img) in [(0, &l), (l.width(), &r)] {
        for (x, y, p) in img.enumerate_pixels() {
            out.put_pixel(x0 + x, y, *p);
        }
    }
    out
}

/// How the BTF objects of a frame are lit.
#[derive(Clone, Debug)]
pub enum Lit {
    /// One light.
    Light(Light),
    /// Per chosen object, the environment binned per vertex (`btf::env`).
    Environment(Vec<Vec<btf::env::EnvLightWeights>>),
}
