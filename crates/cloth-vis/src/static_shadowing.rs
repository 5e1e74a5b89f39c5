//! The `static-shadowing` stage: per-vertex visibility maps (thesis §4.3, crate `hemicube`) of
//! every object, and the environment radiance they let through, L_o = ρ Σ_p V_p ΔF_p L(dir_p).
//!
//! All objects occlude each other; a two-sided object gets a second set of maps for its back
//! side (normals flipped), as the `self-shadowing` stage gives it a second set of rows. The
//! builder and pipelines are made once per run; a deforming object rebuilds its maps every frame
//! (the seed's limitation, T 6389–6392: the maps are static).

use std::sync::Arc;

use glam::Vec3;
use gpu_context::GpuContext;
use hemicube::{BuildParams, EnvLookup, GpuBuilder, PixelLayout};
use occlusion_gpu::{RayCaster, SceneObject};
use serde_json::json;

use crate::Error;
use crate::object::WorldObject;
use crate::scene::{Scene, StaticBuilderDesc};
use crate::shadowing::scaled_rows;

/// Maps and lighting for a run: layout and (for the GPU) the atlas pipeline made once.
pub struct StaticShadowingStage {
    layout: Arc<PixelLayout>,
    gpu_builder: Option<GpuBuilder>,
    lookup: EnvLookup,
}

impl StaticShadowingStage {
    /// The stage of `scene`'s `[static_shadowing]` table (validated by [`Scene::validate`]).
    ///
    /// # Errors
    /// [`Error::Scene`] for a table that does not validate or that asks for the GPU builder
    /// without an adapter; hemicube and GPU errors.
    pub fn new(scene: &Scene, gpu: Option<&GpuContext>) -> Result<Self, Error> {
        let table = &scene.static_shadowing;
        let invalid = |key: &str| Error::Scene {
            origin: scene.origin.clone(),
            message: format!("static_shadowing.{key} is invalid"),
        };
        let model = table.model().ok_or_else(|| invalid("model"))?;
        let lookup = table.lookup().ok_or_else(|| invalid("lookup"))?;
        let layout = Arc::new(PixelLayout::new(model, hemicube::FormFactorRule::Exact)?);
        let gpu_builder = match (table.builder, gpu) {
            (StaticBuilderDesc::Cpu, _) | (StaticBuilderDesc::Auto, None) => None,
            (StaticBuilderDesc::Auto, Some(g))
                if g.summary().is_software
                    || !model.is_planar()
                    || !GpuBuilder::is_supported(g) =>
            {
                None
            }
            (_, Some(g)) => Some(GpuBuilder::new(g, layout.clone())?),
            (StaticBuilderDesc::Gpu, None) => {
                return Err(Error::Scene {
                    origin: scene.origin.clone(),
                    message: "static_shadowing.builder: \"gpu\" needs a GPU adapter and none \
                              was found; use \"cpu\""
                        .to_owned(),
                });
            }
        };
        Ok(Self {
            layout,
            gpu_builder,
            lookup,
        })
    }

    /// Builds the maps of every object as posed and sets its front (and back) radiance.
    /// Returns what the run report records.
    ///
    /// # Errors
    /// Scene, builder and GPU errors.
    pub fn light(
        &self,
        gpu: Option<&GpuContext>,
        objects: &mut [WorldObject],
        env: &lightsphere::Environment,
    ) -> Result<serde_json::Value, Error> {
        let mut scene = occlusion_gpu::Scene::new();
        let mut rows = Vec::with_capacity(objects.len());
        let mut first = 0usize;
        for object in objects.iter() {
            scene.push(SceneObject::new(
                object.positions.clone(),
                object.normals.clone(),
                object.triangles.clone(),
            ))?;
            let n = object.positions.len();
            let back = if object.two_sided {
                let flipped: Vec<Vec3> = object.normals.iter().map(|n| -*n).collect();
                scene.push(SceneObject::new(
                    object.positions.clone(),
                    flipped,
                    object.triangles.clone(),
                ))?;
                Some(first + n..first + 2 * n)
            } else {
                None
            };
            rows.push((first..first + n, back.clone()));
            first += if back.is_some() { 2 * n } else { n };
        }
        let caster = RayCaster::new(&scene)?;
        let t = std::time::Instant::now();
        let params = BuildParams::default();
        let (maps, stats) = match (&self.gpu_builder, gpu) {
            (Some(builder), Some(gpu)) => builder.build_with_caster(gpu, &caster, &params)?,
            _ => hemicube::build_with_caster(&caster, self.layout.clone(), &params),
        };
        let build_ms = t.elapsed().as_secs_f64() * 1e3;
        let t = std::time::Instant::now();
        let c = hemicube::lighting::environment_radiance(&maps, env, Vec3::ONE, self.lookup);
        let light_ms = t.elapsed().as_secs_f64() * 1e3;
        for (object, (front, back)) in objects.iter_mut().zip(&rows) {
            let f = scaled_rows(&c, front, object.albedo);
            object.back = Some(
                back.as_ref()
                    .map_or_else(|| f.clone(), |b| scaled_rows(&c, b, object.albedo)),
            );
            object.front = Some(f);
        }
        Ok(json!({
            "model": self.layout.model().label(),
            "builder": if self.gpu_builder.is_some() { "gpu" } else { "cpu" },
            "maps": maps.len(),
            "bytes_per_vertex": maps.bytes_per_vertex(),
            "samples": stats.samples,
            "build_ms": build_ms,
            "light_ms": light_ms,
            "lookup": format!("{:?}", self.lookup),
        }))
    }
}
