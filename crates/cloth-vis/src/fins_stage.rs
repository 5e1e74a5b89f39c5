//! Fins on BTF objects: silhouette enhancement of fuzzy cloth (thesis §5.7). Per frame, each
//! object's silhouette edges for the camera's eye are extruded into fins ([`btf::fins`]) and
//! drawn with the fin BTF ([`btf::fin_pca`]) after the opaque BTF surface, in the two
//! order-independent passes of [`btf::render::GpuFinRenderer`].
//!
//! The fin material is a `.finpca` file or `synth:wool`: the synthetic wool of
//! `synth::fins`, its 81 images of Table 5.3 rendered and compressed in memory.
//! Sizes: one material unit (one repeat of the fin image along the silhouette) is
//! [`FinLook::size`] world units; fins stand [`FinLook::height`] material units tall (the
//! synthetic images are square, so 1 shows the whole image).

use std::path::{Path, PathBuf};
use std::time::Instant;

use btf::fin_pca::{FIN_SAMPLING, FinPca};
use btf::fins::{FinBuilder, FinMesh, FinParams, Viewer};
use btf::render::{FinDraw, FinShading, GpuFinRenderer, Light};
use btf::{BtfPcaParams, DIRECTIONS, ViewSlot};
use render::{Camera, PassContext};

use crate::Error;
use crate::object::WorldObject;

/// The synthetic fin material's name in scenes and on the command line.
pub const SYNTH_WOOL: &str = "synth:wool";
/// Default world length of one fin material unit, as a fraction of the drawn objects'
/// bounding-sphere radius.
pub const DEFAULT_SIZE_FRACTION: f32 = 0.04;
/// Default fin height in material units (the whole synthetic image).
pub const DEFAULT_HEIGHT: f32 = 1.0;

/// The 81 images of the synthetic wool under Table 5.3's lights (light i = image i), linear
/// RGB over black.
///
/// # Errors
/// [`Error::Synth`] for bad generator parameters; [`Error::Btf`] if the images do not form a
/// fin set.
pub fn wool_images(params: &synth::fins::WoolFinParams) -> Result<ViewSlot, Error> {
    let wool = synth::fins::WoolFins::new(params)?;
    let mut data = Vec::with_capacity(DIRECTIONS * 3 * params.width * params.height);
    for i in 0..DIRECTIONS {
        let image = wool.image(FIN_SAMPLING.vector(i));
        data.extend(image.rgba.iter().flat_map(|p| [p[0], p[1], p[2]]));
    }
    Ok(ViewSlot::new(0, params.width, params.height, data)?)
}

/// Where a fin material comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum FinSource {
    /// [`SYNTH_WOOL`], rendered and compressed in memory.
    SynthWool,
    /// A `.finpca` file.
    File(PathBuf),
}

impl FinSource {
    /// `synth:wool` or a path.
    pub fn parse(text: &str) -> Self {
        if text == SYNTH_WOOL {
            Self::SynthWool
        } else {
            Self::File(PathBuf::from(text))
        }
    }

    /// Loads (or makes) the material with `components` eigen-images for `synth:wool`.
    ///
    /// # Errors
    /// File errors naming the file; generator and compression errors.
    pub fn load(&self, components: usize) -> Result<FinPca, Error> {
        match self {
            Self::SynthWool => {
                let images = wool_images(&synth::fins::WoolFinParams::default())?;
                let params = BtfPcaParams {
                    components,
                    ..Default::default()
                };
                Ok(FinPca::from_images(&images, &params)?)
            }
            Self::File(path) => Ok(FinPca::read(path)?),
        }
    }
}

/// How large fins are drawn.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FinLook {
    /// World length of one material unit (one repeat of the fin image along the edge).
    pub size: f32,
    /// Fin height in material units.
    pub height: f32,
}

impl FinLook {
    /// The default look for objects of bounding radius `radius`.
    pub fn for_radius(radius: f32, height: Option<f32>, size: Option<f32>) -> Self {
        Self {
            size: size.unwrap_or(DEFAULT_SIZE_FRACTION * radius),
            height: height.unwrap_or(DEFAULT_HEIGHT),
        }
    }

    /// Checks both values, naming `what` (a flag or scene key prefix) in the error.
    ///
    /// # Errors
    /// [`Error::Request`] for a size or height that is not finite and > 0.
    pub fn validate(&self, what: &Path) -> Result<(), Error> {
        for (name, v) in [("size", self.size), ("height", self.height)] {
            if !(v.is_finite() && v > 0.0 && v < 1e9) {
                return Err(Error::Request {
                    path: what.to_path_buf(),
                    message: format!("fin {name} {v}: must be finite and > 0"),
                });
            }
        }
        Ok(())
    }
}

/// The fins of one frame and what they cost on the CPU.
#[derive(Debug)]
pub struct FinFrame {
    /// One draw per object.
    pub draws: Vec<FinDraw>,
    /// Fins in all draws.
    pub fins: usize,
    /// Milliseconds of silhouette extraction and fin building (all objects).
    pub extract_ms: f64,
    /// Milliseconds of lighting (γ per fin end) and upload (all objects).
    pub prepare_ms: f64,
}

/// Extracts and lights the fins of `objects` for `camera`'s eye under `light`, ready to draw
/// into the frame `ctx` belongs to.
///
/// # Errors
/// A triangle naming a missing vertex ([`Error::Request`] naming the object); GPU limits.
pub fn fin_frame(
    renderer: &GpuFinRenderer,
    objects: &[&WorldObject],
    light: &Light,
    camera: &Camera,
    look: &FinLook,
) -> Result<FinFrame, Error> {
    let params = FinParams {
        material_size: look.size,
        height: look.height,
        offset: 0.0,
    };
    let mut frame = FinFrame {
        draws: Vec::with_capacity(objects.len()),
        fins: 0,
        extract_ms: 0.0,
        prepare_ms: 0.0,
    };
    let mut mesh = FinMesh::default();
    for object in objects {
        let start = Instant::now();
        let welded = welded_triangles(&object.positions, &object.triangles);
        let mut builder =
            FinBuilder::new(&welded, object.positions.len()).map_err(|e| Error::Request {
                path: PathBuf::from(&object.name),
                message: format!("cannot carry fins: {e}"),
            })?;
        builder.build(
            &object.positions,
            &object.normals,
            Viewer::Eye(camera.eye),
            &params,
            &mut mesh,
        );
        let built = Instant::now();
        frame.extract_ms += (built - start).as_secs_f64() * 1e3;
        frame.fins += mesh.len();
        frame.draws.push(renderer.prepare(
            &mesh,
            &object.positions,
            &object.normals,
            light,
            camera.eye,
            &FinShading::default(),
        )?);
        frame.prepare_ms += built.elapsed().as_secs_f64() * 1e3;
    }
    Ok(frame)
}

/// The triangles with every vertex replaced by the first vertex at the same position, and
/// the triangles that collapse dropped: UV seams (split into vertex copies for texturing) and
/// the rings of a UV sphere's poles would otherwise be border edges, and every border edge
/// carries a fin.
pub fn welded_triangles(positions: &[glam::Vec3], triangles: &[[u32; 3]]) -> Vec<[u32; 3]> {
    let mut first = std::collections::HashMap::with_capacity(positions.len());
    let id: Vec<u32> = positions
        .iter()
        .enumerate()
        .map(|(i, p)| {
            *first
                .entry(p.to_array().map(f32::to_bits))
                .or_insert(i as u32)
        })
        .collect();
    triangles
        .iter()
        .filter_map(|t| {
            let w = t.map(|v| id.get(v as usize).copied().unwrap_or(v));
            (w[0] != w[1] && w[1] != w[2] && w[0] != w[2]).then_some(w)
        })
        .collect()
}

/// Builds the fin renderer for a frame.
///
/// # Errors
/// GPU limits ([`Error::Btf`]).
pub fn fin_renderer(
    device: &wgpu::Device,
    fins: &FinPca,
    ctx: &PassContext<'_>,
) -> Result<GpuFinRenderer, Error> {
    Ok(GpuFinRenderer::for_frame(device, fins, ctx)?)
}
