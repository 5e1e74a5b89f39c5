//! `cloth-vis visibility`: the visibility matrix M and the ambient term a_i of a mesh or of every
//! frame of an animation (paper 000), written as `.npy` arrays or a coloured `.ply`.
//!
//! Arrays keep the input's vertex order and count; a vertex used by no face has a zero normal
//! and gets a_i = NaN (and an all-zero row of M). Only the visibility computation is timed.

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use glam::Vec3;
use gpu_context::GpuContext;
use occlusion_gpu::{Backend, DepthParams, VisibilityEngine, VisibilityParams};

use crate::Error;

/// What `cloth-vis visibility` was asked to do.
#[derive(Clone, Debug)]
pub struct VisibilityRequest {
    /// A mesh, or an animation (folder of numbered OBJ, `.npy`, animated glTF).
    pub input: PathBuf,
    /// Lightsphere level.
    pub level: u32,
    /// Backend; `None` = depth on a hardware GPU, cpu otherwise.
    pub backend: Option<Backend>,
    /// Depth-map side for the depth backend.
    pub depth_resolution: u32,
    /// Environment for the colours of a `.ply` output (`None` = grey ambient).
    pub environment: Option<lightsphere::Environment>,
    /// Output file: `.npy` (a_i, or M with `matrix`) or `.ply` (mesh with colour and `ao`).
    pub out: Option<PathBuf>,
    /// Write M [N, k] instead of a_i.
    pub matrix: bool,
    /// Frames `start..end` of an animation (default all).
    pub frames: Option<(usize, usize)>,
}

/// What was computed.
#[derive(Clone, Debug, PartialEq)]
pub struct VisibilitySummary {
    /// Light directions k.
    pub directions: usize,
    /// Vertices per frame N.
    pub vertices: usize,
    /// Frames computed.
    pub frames: usize,
    /// Time of the visibility computation alone, all frames (ms).
    pub millis: f64,
    /// The backend that ran.
    pub backend: Backend,
}

impl VisibilitySummary {
    /// The one summary line: `visibility: K directions x N vertices in T ms (BACKEND)`.
    pub fn line(&self) -> String {
        let frames = if self.frames > 1 {
            format!(" x {} frames", self.frames)
        } else {
            String::new()
        };
        format!(
            "visibility: {} directions x {} vertices{frames} in {:.1} ms ({})",
            self.directions,
            self.vertices,
            self.millis,
            self.backend.name()
        )
    }
}

fn invalid(path: &Path, message: String) -> Error {
    Error::Request {
        path: path.to_owned(),
        message,
    }
}

/// Run the request. `gpu` is needed only for the depth backend.
///
/// # Errors
/// Loader, engine and output errors, naming the file; an unsupported output extension or a
/// frame range outside the animation is refused before any computation.
pub fn run_visibility(
    request: &VisibilityRequest,
    gpu: Option<&GpuContext>,
) -> Result<VisibilitySummary, Error> {
    let input = &request.input;
    let out_kind = match &request.out {
        None => None,
        Some(p) => match p
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("npy") => Some("npy"),
            Some("ply") if !request.matrix => Some("ply"),
            _ => {
                return Err(invalid(
                    p,
                    "output must be .npy (a_i, or M with --matrix) or .ply (mesh with colour and `ao`); .glb output is not built yet".to_owned(),
                ));
            }
        },
    };
    let sphere = lightsphere::Lightsphere::new(request.level)?;
    let (frames, triangles) = load_frames(input)?;
    let (start, end) = request.frames.unwrap_or((0, frames.len()));
    if start >= end || end > frames.len() {
        return Err(invalid(
            input,
            format!(
                "--frames {start}..{end} is outside the {} frames (0..{})",
                frames.len(),
                frames.len()
            ),
        ));
    }
    if out_kind == Some("ply") && end - start != 1 {
        return Err(invalid(
            input,
            "a .ply output holds one frame: pass --frames A..A+1".to_owned(),
        ));
    }
    let backend = request.backend.unwrap_or(match gpu {
        Some(g) if !g.summary().is_software => Backend::Depth,
        _ => Backend::Cpu,
    });
    let params = VisibilityParams::default()
        .with_depth(DepthParams::default().with_resolution(request.depth_resolution));
    let mut engine = match (backend, gpu) {
        (Backend::Cpu, _) => VisibilityEngine::cpu(params),
        (other, Some(g)) => VisibilityEngine::with_gpu(&g.device, &g.queue, other, params),
        (other, None) => {
            return Err(invalid(
                input,
                format!(
                    "backend {} needs a GPU adapter; use --backend cpu",
                    other.name()
                ),
            ));
        }
    };
    let n = frames[0].len();
    let mut ambient = Vec::with_capacity((end - start) * n);
    let mut matrices = Vec::new();
    let mut last = None;
    let mut millis = 0.0;
    for positions in &frames[start..end] {
        let normals =
            meshio::compute_normals(positions, &triangles, meshio::NormalWeighting::Angle);
        let scene = occlusion_gpu::Scene::single(positions.clone(), normals, triangles.clone())?;
        let t = Instant::now();
        let m = engine.compute(&scene, &sphere)?;
        millis += t.elapsed().as_secs_f64() * 1e3;
        ambient.extend(m.ambient());
        if request.matrix {
            matrices.extend(m.to_dense());
        }
        last = Some((positions, m));
    }
    let count = end - start;
    match (out_kind, &request.out) {
        (Some("npy"), Some(path)) => {
            let k = sphere.len();
            if request.matrix {
                let shape: Vec<usize> = if count > 1 {
                    vec![count, n, k]
                } else {
                    vec![n, k]
                };
                meshio::write_npy_f32(path, &shape, &matrices)?;
            } else {
                let shape: Vec<usize> = if count > 1 { vec![count, n] } else { vec![n] };
                meshio::write_npy_f32(path, &shape, &ambient)?;
            }
        }
        (Some("ply"), Some(path)) => {
            if let Some((positions, m)) = &last {
                let colours = match &request.environment {
                    Some(env) => {
                        let radiance = env.radiance_per_direction(
                            &sphere,
                            lightsphere::RadianceMethod::CellMean,
                        )?;
                        let weights = sphere.light_weights(&radiance)?;
                        let c = m.radiance(&weights)?;
                        display_colours(&c)
                    }
                    None => ambient
                        .iter()
                        .map(|a| Vec3::splat(if a.is_finite() { *a } else { 0.0 }))
                        .collect(),
                };
                write_ply(path, positions, m.normals(), &triangles, &colours, &ambient)?;
            }
        }
        _ => {}
    }
    Ok(VisibilitySummary {
        directions: sphere.len(),
        vertices: n,
        frames: count,
        millis,
        backend,
    })
}

type Frames = (Vec<Vec<Vec3>>, Vec<[u32; 3]>);

fn load_frames(input: &Path) -> Result<Frames, Error> {
    let ext = |e: &str| input.extension().is_some_and(|x| x.eq_ignore_ascii_case(e));
    if input.is_dir() || ext("npy") || ext("glb") || ext("gltf") {
        if let Ok((anim, _)) = meshio::load_animation(input, &meshio::AnimationOptions::default()) {
            if !anim.triangles.is_empty() {
                return Ok((anim.frames, anim.triangles));
            }
            return Err(invalid(
                input,
                "an .npy animation has no triangles; pass a mesh as the input instead".to_owned(),
            ));
        }
    }
    let (mesh, _) = meshio::load_mesh(input, &meshio::LoadOptions::default())?;
    Ok((vec![mesh.positions], mesh.triangles))
}

/// Map radiance to display colours: the 90th percentile of luminance to 0.8, gamma 2.2.
fn display_colours(c: &[Vec3]) -> Vec<Vec3> {
    let mut lum: Vec<f32> = c
        .iter()
        .map(|v| v.dot(Vec3::new(0.2126, 0.7152, 0.0722)))
        .filter(|l| l.is_finite() && *l > 0.0)
        .collect();
    let scale = if lum.is_empty() {
        1.0
    } else {
        let k = (lum.len() - 1) * 9 / 10;
        let (_, key, _) = lum.select_nth_unstable_by(k, f32::total_cmp);
        0.8 / *key
    };
    c.iter()
        .map(|v| {
            if v.is_finite() {
                (*v * scale).clamp(Vec3::ZERO, Vec3::ONE).powf(1.0 / 2.2)
            } else {
                Vec3::ZERO
            }
        })
        .collect()
}

/// Binary little-endian PLY with positions, normals, 8-bit colour and a float `ao`, written
/// atomically.
fn write_ply(
    path: &Path,
    positions: &[Vec3],
    normals: &[Vec3],
    triangles: &[[u32; 3]],
    colours: &[Vec3],
    ambient: &[f32],
) -> Result<(), Error> {
    meshio::write_atomic(path, |w| {
        write!(
            w,
            "ply\nformat binary_little_endian 1.0\ncomment cloth-vis visibility: ao = a_i (NaN: vertex used by no face)\n\
             element vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
             property float nx\nproperty float ny\nproperty float nz\n\
             property uchar red\nproperty uchar green\nproperty uchar blue\nproperty float ao\n\
             element face {}\nproperty list uchar uint vertex_indices\nend_header\n",
            positions.len(),
            triangles.len()
        )?;
        for i in 0..positions.len() {
            for v in positions[i]
                .to_array()
                .into_iter()
                .chain(normals[i].to_array())
            {
                w.write_all(&v.to_le_bytes())?;
            }
            let c = colours[i]
                .to_array()
                .map(|x| (x.clamp(0.0, 1.0) * 255.0 + 0.5) as u8);
            w.write_all(&c)?;
            w.write_all(&ambient[i].to_le_bytes())?;
        }
        for t in triangles {
            w.write_all(&[3u8])?;
            for v in t {
                w.write_all(&v.to_le_bytes())?;
            }
        }
        Ok(())
    })?;
    Ok(())
}
