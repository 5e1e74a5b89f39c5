//! The `self-shadowing` effect: the visibility matrix M of every vertex towards every light
//! direction (occlusion-gpu, paper 000 §3), and per-vertex radiance with it:
//! c_i = (ρ/π) Σ_j M_ij I_j ω_j, where M_ij = n_i·l_j if vertex i sees direction j, else 0.
//!
//! Two-sided objects (cloth) get a second set of rows computed with flipped normals, so the
//! underside is lit by what it sees, not by what the top side sees.

use glam::Vec3;
use gpu_context::GpuContext;
use occlusion_gpu::{
    Backend, CpuParams, DepthParams, SceneObject, VisibilityEngine, VisibilityMatrix,
    VisibilityParams,
};
use serde_json::json;

use crate::Error;
use crate::object::WorldObject;
use crate::scene::{Scene, VisibilityBackendDesc};

/// M for every object (and for the flipped side of two-sided ones), with the row ranges.
#[derive(Debug)]
pub struct Visibility {
    matrix: VisibilityMatrix,
    /// Per object: rows of the front side, and of the back side when two-sided.
    rows: Vec<(std::ops::Range<usize>, Option<std::ops::Range<usize>>)>,
}

impl Visibility {
    /// The matrix: one row per receiver vertex (front rows, then back rows of two-sided
    /// objects, in object order), one column per light direction.
    pub fn matrix(&self) -> &VisibilityMatrix {
        &self.matrix
    }

    /// The rows of object `index`'s front side, and of its back side when two-sided.
    pub fn rows(
        &self,
        index: usize,
    ) -> Option<&(std::ops::Range<usize>, Option<std::ops::Range<usize>>)> {
        self.rows.get(index)
    }
}

/// The visibility stage of a run: the engine of the scene's backend, built once and reused
/// for every frame of a sequence (GPU backends keep their pipelines and buffers).
pub struct VisibilityStage {
    engine: VisibilityEngine,
    backend: Backend,
    depth_resolution: u32,
}

impl VisibilityStage {
    /// The engine for `[visibility]` of `scene`: `auto` is the depth backend on a hardware
    /// adapter and the exact CPU ray caster on a software one or without one.
    ///
    /// # Errors
    /// [`Error::Scene`] when the scene asks for a GPU backend and `gpu` is `None`.
    pub fn new(scene: &Scene, gpu: Option<&GpuContext>) -> Result<Self, Error> {
        let bounded = scene.visibility.max_distance.is_some();
        let backend = match (scene.visibility.backend, gpu) {
            (VisibilityBackendDesc::Cpu, _) => Backend::Cpu,
            // Only the exact ray caster bounds its rays.
            (VisibilityBackendDesc::Auto, _) if bounded => Backend::Cpu,
            (VisibilityBackendDesc::Depth, _) => Backend::Depth,
            (VisibilityBackendDesc::Query, _) => Backend::Query,
            (VisibilityBackendDesc::Rays, _) => Backend::Rays,
            (VisibilityBackendDesc::Auto, Some(g)) if !g.summary().is_software => Backend::Depth,
            (VisibilityBackendDesc::Auto, _) => Backend::Cpu,
        };
        let depth_resolution = scene.visibility.depth_resolution;
        let params = VisibilityParams::default()
            .with_depth(DepthParams::default().with_resolution(depth_resolution))
            .with_cpu(
                CpuParams::default()
                    .with_max_distance(scene.visibility.max_distance.unwrap_or(f32::INFINITY)),
            );
        let engine = match (backend, gpu) {
            (Backend::Cpu, _) => VisibilityEngine::cpu(params),
            (other, Some(g)) => VisibilityEngine::with_gpu(&g.device, &g.queue, other, params),
            (other, None) => {
                return Err(Error::Scene {
                    origin: scene.origin.clone(),
                    message: format!(
                        "visibility backend {} needs a GPU adapter and none was found; use \
                         the cpu backend (--backend cpu, or backend = \"cpu\" in [visibility])",
                        other.name()
                    ),
                });
            }
        };
        Ok(Self {
            engine,
            backend,
            depth_resolution,
        })
    }

    /// The backend that runs.
    pub fn backend(&self) -> Backend {
        self.backend
    }

    /// Reports progress inside each later [`VisibilityStage::compute`]: (cells done, cells),
    /// a cell being one (vertex row, direction) ([`occlusion_gpu::ProgressFn`]); `None` stops.
    pub fn set_progress(&mut self, progress: Option<occlusion_gpu::ProgressFn>) {
        self.engine.set_progress(progress);
    }

    /// M for all objects as posed, each object occluding all others; two-sided objects get a
    /// second set of rows with flipped normals. Returns M and what the run report records.
    ///
    /// # Errors
    /// [`Error::Visibility`] when the engine rejects the scene or the GPU fails.
    pub fn compute(
        &mut self,
        objects: &[WorldObject],
        sphere: &lightsphere::Lightsphere,
    ) -> Result<(Visibility, serde_json::Value), Error> {
        let (occ, indices) = occlusion_scene(objects)?;
        let matrix = self.engine.compute(&occ, sphere)?;
        let rows = indices
            .iter()
            .map(|(front, back)| {
                let f = occ.receiver_rows(*front).unwrap_or(0..0);
                (f, back.and_then(|b| occ.receiver_rows(b)))
            })
            .collect();
        let total = matrix.rows() * matrix.directions_len();
        let report = json!({
            "backend": self.backend.name(),
            "rows": matrix.rows(),
            "directions": matrix.directions_len(),
            "visible_share": matrix.visible_count() as f64 / total.max(1) as f64,
            "rays": self.engine.last_ray_count(),
            "depth_resolution": self.depth_resolution,
            "bvh": bvh_report(self.engine.last_bvh()),
        });
        Ok((Visibility { matrix, rows }, report))
    }

    /// Refine `visibility` (computed by [`VisibilityStage::compute`] for `objects` as they are
    /// posed now, at a [`lightsphere::Lightsphere::new`] level) to the finer nested level
    /// `sphere`, tracing only the new directions (paper 000 §4.2's idle-time refinement).
    ///
    /// # Errors
    /// [`Error::Visibility`] when `sphere` does not extend the matrix's directions or the
    /// objects changed their vertex counts.
    pub fn refine(
        &mut self,
        objects: &[WorldObject],
        visibility: &mut Visibility,
        sphere: &lightsphere::Lightsphere,
    ) -> Result<(), Error> {
        let (occ, _) = occlusion_scene(objects)?;
        self.engine.refine(&occ, &mut visibility.matrix, sphere)?;
        Ok(())
    }
}

/// The receivers and occluders of `objects`: each object's rows, and a second set with
/// flipped normals for a two-sided object. Returns the scene and each object's (front, back)
/// indices in it.
#[allow(clippy::type_complexity)]
fn occlusion_scene(
    objects: &[WorldObject],
) -> Result<(occlusion_gpu::Scene, Vec<(usize, Option<usize>)>), Error> {
    let mut occ = occlusion_gpu::Scene::new();
    let mut indices = Vec::with_capacity(objects.len());
    for object in objects {
        let front = occ.push(SceneObject::new(
            object.positions.clone(),
            object.normals.clone(),
            object.triangles.clone(),
        ))?;
        let back = if object.two_sided {
            let flipped: Vec<Vec3> = object.normals.iter().map(|n| -*n).collect();
            let copy =
                SceneObject::new(object.positions.clone(), flipped, object.triangles.clone());
            Some(occ.push(copy)?)
        } else {
            None
        };
        indices.push((front, back));
    }
    Ok((occ, indices))
}

/// Compute M for all objects once ([`VisibilityStage`] built and used for one frame).
///
/// # Errors
/// As [`VisibilityStage::new`] and [`VisibilityStage::compute`].
pub fn visibility(
    scene: &Scene,
    gpu: &GpuContext,
    objects: &[WorldObject],
    sphere: &lightsphere::Lightsphere,
) -> Result<(Visibility, serde_json::Value), Error> {
    VisibilityStage::new(scene, Some(gpu))?.compute(objects, sphere)
}

/// The radiance of rows `range` times an object's albedo; black where the radiance is not finite
/// (vertices used by no triangle).
pub(crate) fn scaled_rows(c: &[Vec3], range: &std::ops::Range<usize>, albedo: Vec3) -> Vec<Vec3> {
    c[range.clone()]
        .iter()
        .map(|v| {
            if v.is_finite() {
                *v * albedo
            } else {
                Vec3::ZERO
            }
        })
        .collect()
}

/// Light every object: with M when `visibility` is given, else with M_ij = max(0, n_i·l_j).
/// Returns the number of vertices lit.
///
/// # Errors
/// [`Error::Visibility`] or [`Error::Light`] if the radiance and the directions disagree
/// (an internal bug).
pub fn light_objects(
    objects: &mut [WorldObject],
    sphere: &lightsphere::Lightsphere,
    radiance: &[Vec3],
    visibility: Option<&Visibility>,
) -> Result<usize, Error> {
    let mut vertices = 0;
    match visibility {
        Some(vis) => {
            // c = ρ · (1/π) Σ_j M_ij I_j ω_j.
            let c = crate::lighting::shadowed_radiance(&vis.matrix, sphere, radiance)?;
            for (object, (front, back)) in objects.iter_mut().zip(&vis.rows) {
                let f = scaled_rows(&c, front, object.albedo);
                let b = back
                    .as_ref()
                    .map_or_else(|| f.clone(), |b| scaled_rows(&c, b, object.albedo));
                vertices += f.len();
                object.front = Some(f);
                object.back = Some(b);
            }
        }
        None => {
            for object in objects.iter_mut() {
                let light = |normals: &[Vec3]| {
                    crate::lighting::lambertian_radiance(
                        normals,
                        sphere.directions(),
                        sphere.solid_angles(),
                        radiance,
                        object.albedo,
                    )
                };
                let front = light(&object.normals);
                let back = if object.two_sided {
                    let flipped: Vec<Vec3> = object.normals.iter().map(|n| -*n).collect();
                    light(&flipped)
                } else {
                    front.clone()
                };
                vertices += front.len();
                object.front = Some(front);
                object.back = Some(back);
            }
        }
    }
    Ok(vertices)
}

/// The `cpu` backend's BVH work of a frame for the run report: how the tree was obtained
/// (reused, refitted with its SAH cost ratio, built) and its milliseconds.
fn bvh_report(stats: occlusion_gpu::BvhStats) -> serde_json::Value {
    use occlusion_gpu::BvhUpdate;
    let (update, sah_ratio) = match stats.update {
        BvhUpdate::None => ("none", None),
        BvhUpdate::Reused => ("reused", None),
        BvhUpdate::Refitted { sah_ratio } => ("refitted", Some(sah_ratio)),
        BvhUpdate::Built => ("built", None),
    };
    json!({ "update": update, "sah_ratio": sah_ratio, "ms": stats.millis })
}
