//! The `translucency` stage: seed 004's subsurface term added to the translucent objects in the
//! shared frame (crate `translucency`; SEED-NOTES §5).
//!
//! Per frame the translucent objects (merged: one accumulation point for all of them, TR 86)
//! hand their positions, normals and transmitted irradiance E_t to the pass, which renders the
//! cube map, reduces it to SH, renders the light distance map with its peeled layer and blurs
//! it; the frame then adds eq. 12 per pixel.
//!
//! * A **point or directional light** gives E_t = F_t(η, n·l) E max(0, n·l) (unshadowed) and
//!   also draws its own direct term ρ/π E max(0, n·l) into the objects' vertex radiance — the
//!   paper's "direct lighting" beside "subsurface scattering" (Figs. 10–11). The direct term
//!   is per vertex, so a vertex whose faces fold or crease away from the light darkens the
//!   triangles around it (a few on the decimated `bun_zipper_res3.ply`; see the
//!   `translucency` crate's docs).
//! * **`environment = true`** takes the scene's lighting (self-shadowed when `self-shadowing`
//!   runs): E_t = (π/ρ) c_i · (1 − R0)·20/21, the vertex radiance turned back into irradiance
//!   and scaled by Schlick's transmittance averaged over the cosine-weighted hemisphere; the
//!   thickness is measured along the environment's dominant direction (its luminance's band-1
//!   SH vector).
//!
//! A translucent object's albedo becomes its material's dipole reflectance R_d, so direct and
//! scattered light come from one material.

use glam::{DVec3, Vec3};
use gpu_context::GpuContext;
use render::Renderer;
use serde_json::json;
use translucency::gpu::{PipelineParams, TranslucencyPass, TranslucentMesh};
use translucency::model::{self, Light};
use translucency::{Material, Sh9};

use crate::Error;
use crate::object::WorldObject;
use crate::scene::Scene;

/// Where the translucent objects' light comes from.
#[derive(Clone, Copy, Debug)]
enum Source {
    /// A point or directional light of RGB power (intensity or irradiance).
    Light(Light, [f64; 3]),
    /// The scene's lighting; the light map along `direction` (towards the light).
    Environment(DVec3),
}

/// The stage: the pass (pipelines built once), the material and the light.
pub struct TranslucencyStage {
    pass: TranslucencyPass,
    material: Material,
    source: Source,
    objects: Vec<usize>,
    /// Per translucent object, the radiance before and after the last frame's direct term:
    /// a static object's radiance is not recomputed every frame, and must not gain the term
    /// twice.
    written: Vec<Option<Written>>,
    setup: serde_json::Value,
}

/// An object's (front, back) radiance before and after the light's direct term was added.
type Radiance = (Option<Vec<Vec3>>, Option<Vec<Vec3>>);
struct Written {
    before: Radiance,
    after: Radiance,
}

/// The direction towards the environment's dominant light: the band-1 SH vector of its
/// luminance (coefficients 1, 2, 3 ↔ y, z, x); +Y for a map without one.
pub fn dominant_direction(env: &lightsphere::Environment) -> DVec3 {
    let sh = Sh9::project_latlong(env);
    let lum = |k: usize| {
        let c = sh.coeffs[k];
        0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
    };
    DVec3::new(lum(3), lum(1), lum(2))
        .try_normalize()
        .unwrap_or(DVec3::Y)
}

impl TranslucencyStage {
    /// Build the pass against `renderer`'s frame; set the translucent objects' albedo to R_d.
    ///
    /// # Errors
    /// [`Error::Scene`] for a material or light the pass refuses, or no translucent object.
    pub fn new(
        scene: &Scene,
        gpu: &GpuContext,
        renderer: &Renderer,
        objects: &mut [WorldObject],
        environment: Option<&lightsphere::Environment>,
    ) -> Result<Self, Error> {
        let start = std::time::Instant::now();
        let desc = &scene.translucency;
        let invalid =
            |key: &str, e: translucency::TranslucencyError| scene.invalid(key, e.to_string());
        let material = desc.material().map_err(|e| invalid("translucency", e))?;
        let albedo = Vec3::from_array(material.diffuse_reflectance().map(|v| v as f32));
        let indices: Vec<usize> = objects
            .iter()
            .enumerate()
            .filter(|(_, o)| desc.covers(&o.name) && !o.triangles.is_empty())
            .map(|(i, _)| i)
            .collect();
        if indices.is_empty() {
            return Err(scene.invalid(
                "translucency.objects",
                "no object with triangles is translucent".to_owned(),
            ));
        }
        for &i in &indices {
            objects[i].albedo = albedo;
        }
        let l = &desc.light;
        let source = match (l.position, l.direction) {
            (Some(p), _) => {
                let p = DVec3::from_array(p);
                // Default: an irradiance of 1 at the translucent objects' centre.
                let (lo, hi) = indices
                    .iter()
                    .flat_map(|&i| objects[i].positions.iter())
                    .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), v| {
                        (lo.min(v.as_dvec3()), hi.max(v.as_dvec3()))
                    });
                let d2 = (p - (lo + hi) / 2.0).length_squared() as f32;
                Source::Light(
                    Light::Point(p),
                    l.intensity.unwrap_or([d2; 3]).map(f64::from),
                )
            }
            (None, Some(d)) => Source::Light(
                Light::Directional(DVec3::from_array(d).normalize()),
                l.irradiance.unwrap_or([1.0; 3]).map(f64::from),
            ),
            (None, None) => {
                let env = environment.ok_or_else(|| {
                    scene.invalid(
                        "translucency.light.environment",
                        "the scene has no environment".to_owned(),
                    )
                })?;
                Source::Environment(dominant_direction(env))
            }
        };
        let params = PipelineParams {
            cube_size: desc.cube_size,
            light_map_size: desc.light_map_size,
            window: desc.sh_window(),
            peel: desc.peel,
            intensity: desc.intensity,
        };
        let pass = TranslucencyPass::new(&gpu.device, &renderer.pass_context(), params)
            .map_err(|e| invalid("translucency", e))?;
        let setup = json!({
            "objects": indices.iter().map(|&i| objects[i].name.clone()).collect::<Vec<_>>(),
            "sigma_a_per_mm": material.sigma_a,
            "sigma_s_per_mm": material.sigma_s_prime,
            "eta": material.eta,
            "mm_per_unit": material.mm_per_unit,
            "sigma_tr_per_mm": material.sigma_tr(),
            "albedo_rd": albedo.to_array(),
            "light": match source {
                Source::Light(Light::Point(p), _) => json!({ "point": p.to_array() }),
                Source::Light(Light::Directional(d), _) => json!({ "directional": d.to_array() }),
                Source::Environment(d) => json!({ "environment_dominant_direction": d.to_array() }),
            },
            "cube_size": desc.cube_size,
            "light_map_size": desc.light_map_size,
            "window": desc.window,
            "peel": desc.peel,
            "setup_ms": start.elapsed().as_secs_f64() * 1e3,
        });
        Ok(Self {
            pass,
            material,
            source,
            written: indices.iter().map(|_| None).collect(),
            objects: indices,
            setup,
        })
    }

    /// This frame's passes (after the lighting stage): E_t per vertex, the light's direct term
    /// into the objects' radiance, then the pass's offscreen work, each pass timed.
    ///
    /// # Errors
    /// [`Error::Scene`] when the pass refuses the mesh; GPU errors.
    pub fn prepare(
        &mut self,
        scene: &Scene,
        gpu: &GpuContext,
        objects: &mut [WorldObject],
        eye: Vec3,
    ) -> Result<serde_json::Value, Error> {
        let eta = self.material.eta;
        let mut positions = Vec::new();
        let mut normals = Vec::new();
        let mut triangles = Vec::new();
        let mut irradiance = Vec::new();
        for (k, &i) in self.objects.iter().enumerate() {
            let o = &mut objects[i];
            let base = positions.len() as u32;
            let p: Vec<DVec3> = o.positions.iter().map(|v| v.as_dvec3()).collect();
            let e_t = match self.source {
                Source::Light(light, power) => {
                    // Unchanged since the last frame: start again from what was there before.
                    if let Some(w) = &self.written[k]
                        && (o.front.clone(), o.back.clone()) == w.after
                    {
                        (o.front, o.back) = w.before.clone();
                    }
                    let before = (o.front.clone(), o.back.clone());
                    add_direct_term(o, &light, power);
                    self.written[k] = Some(Written {
                        before,
                        after: (o.front.clone(), o.back.clone()),
                    });
                    model::transmitted_irradiance(&p, &o.normals, &light, power, eta, |_| 1.0)
                }
                Source::Environment(_) => {
                    let r0 = ((eta - 1.0) / (eta + 1.0)).powi(2);
                    let mean_ft = (1.0 - r0) * 20.0 / 21.0;
                    let rho = o.albedo.as_dvec3().max(DVec3::splat(1e-6));
                    match &o.front {
                        Some(front) => front
                            .iter()
                            .map(|c| {
                                let e = c.as_dvec3() * std::f64::consts::PI / rho * mean_ft;
                                e.as_vec3().to_array()
                            })
                            .collect(),
                        None => vec![[0.0; 3]; p.len()],
                    }
                }
            };
            positions.extend(p);
            normals.extend(o.normals.iter().copied());
            triangles.extend(o.triangles.iter().map(|t| t.map(|v| v + base)));
            irradiance.extend(e_t);
        }
        let light = match self.source {
            Source::Light(light, _) => light,
            Source::Environment(d) => Light::Directional(d),
        };
        let mesh = TranslucentMesh {
            positions: &positions,
            normals: &normals,
            triangles: &triangles,
            irradiance: &irradiance,
        };
        let times = self
            .pass
            .prepare(
                &gpu.device,
                &gpu.queue,
                &mesh,
                light,
                &self.material,
                eye.as_dvec3(),
                true,
            )
            .map_err(|e| scene.invalid("translucency", e.to_string()))?;
        let mut params = self.setup.clone();
        if let serde_json::Value::Object(map) = &mut params {
            map.insert("vertices".into(), json!(positions.len()));
            map.insert("triangles".into(), json!(triangles.len()));
            map.insert(
                "pass_ms".into(),
                json!({
                    "upload": times.upload,
                    "cube_map": times.cube_map,
                    "sh_projection": times.sh_projection,
                    "light_map": times.light_map,
                    "blur": times.blur,
                }),
            );
        }
        Ok(params)
    }

    /// The pass to hand to the frame.
    pub fn pass(&self) -> &TranslucencyPass {
        &self.pass
    }

    /// The position of its light when that is a point light.
    pub fn point_light(&self) -> Option<DVec3> {
        match self.source {
            Source::Light(Light::Point(p), _) => Some(p),
            _ => None,
        }
    }

    /// Move its point light to `position` (a viewer's light control); a directional light or
    /// the environment is left as it is.
    pub fn set_point_light(&mut self, position: DVec3) {
        if let Source::Light(Light::Point(p), _) = &mut self.source {
            *p = position;
        }
    }
}

/// Add a light's Lambertian term ρ/π E max(0, ±n·l) to an object's front (and back) vertex
/// radiance, starting from black when no other effect lit it.
fn add_direct_term(o: &mut WorldObject, light: &Light, power: [f64; 3]) {
    let n = o.positions.len();
    let rho = o.albedo / std::f32::consts::PI;
    let front = o.front.get_or_insert_with(|| vec![Vec3::ZERO; n]);
    let mut back_add = vec![Vec3::ZERO; n];
    for i in 0..n {
        let x = o.positions[i].as_dvec3();
        let l = light.towards(x);
        let falloff = match *light {
            Light::Point(p) => 1.0 / (p - x).length_squared().max(f64::MIN_POSITIVE),
            Light::Directional(_) => 1.0,
        };
        let e = Vec3::from_array(power.map(|v| (v * falloff) as f32));
        let cos = o.normals[i].as_dvec3().dot(l) as f32;
        front[i] += rho * e * cos.max(0.0);
        back_add[i] = rho * e * (-cos).max(0.0);
    }
    let back = o.back.get_or_insert_with(|| vec![Vec3::ZERO; n]);
    for (b, a) in back.iter_mut().zip(back_add) {
        *b += a;
    }
}
