//! The two pictures of the shadows report, each a pair drawn through the shared frame with the
//! same camera and exposure: Fig. 5.9 (a coarse sphere's terminator by the stencil alone, and
//! through eq. 5.6 at α = 15°) and Fig. 4.3 (the bunny's shadow from the full caster and from
//! its 1 % level, the display mesh whole in both).

use std::path::Path;

use glam::{DVec3, Vec3};
use gpu_context::{GpuContext, HdrImage};
use render::tone::{Display, ToneCurve};
use render::{Background, Camera, DepthConvention, DrawMesh, FrameFormat, Renderer, output};
use shadows::boundary::BoundaryMode;
use shadows::frame::{FrameLight, Receiver, SmoothBoundary, StencilShadows};
use shadows::volume::{CasterTopology, ShadowVolume, Sides, VolumeParams};
use shadows::{BoundaryTexture, Counting, Light};

/// One object of a picture: drawn, receiving, and casting with `caster` triangles.
pub struct Object {
    pub positions: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
    pub caster: Option<Vec<[u32; 3]>>,
    pub offset: f64,
}

fn normals(o: &Object) -> Vec<Vec3> {
    meshio::compute_normals(&o.positions, &o.triangles, meshio::NormalWeighting::Angle)
}

/// Renders `objects` (albedo 0.8, ambient 0.08) under `light` (irradiance 1 at the target).
fn panel(
    gpu: &GpuContext,
    objects: &[Object],
    light: Light,
    boundary: Option<SmoothBoundary>,
    camera: &Camera,
) -> anyhow::Result<HdrImage> {
    let format = FrameFormat::for_context(gpu).with_depth(DepthConvention::ReversedInfinite);
    let mut renderer = Renderer::new(&gpu.device, format);
    let normals: Vec<Vec<Vec3>> = objects.iter().map(normals).collect();
    let ambient: Vec<Vec<Vec3>> = objects
        .iter()
        .map(|o| vec![Vec3::splat(0.8 * 0.08); o.positions.len()])
        .collect();
    let albedo: Vec<Vec<Vec3>> = objects
        .iter()
        .map(|o| vec![Vec3::splat(0.8); o.positions.len()])
        .collect();
    let draws: Vec<DrawMesh> = objects
        .iter()
        .zip(&ambient)
        .map(|(o, a)| DrawMesh {
            positions: &o.positions,
            triangles: &o.triangles,
            front: a,
            back: a,
        })
        .collect();
    renderer
        .gouraud
        .set_meshes(&gpu.device, &gpu.queue, &draws)?;
    let mut effect = StencilShadows::new(
        &gpu.device,
        &renderer.pass_context(),
        &BoundaryTexture::step(shadows::boundary::TEXTURE_TEXELS),
        Counting::ZFail,
    )?;
    let receivers: Vec<Receiver> = objects
        .iter()
        .zip(&normals)
        .zip(&albedo)
        .map(|((o, n), a)| Receiver {
            positions: &o.positions,
            normals: n,
            albedo: a,
            triangles: &o.triangles,
            casts: o.caster.is_some(),
        })
        .collect();
    effect.set_receivers(&gpu.device, &receivers)?;
    let mut volume = ShadowVolume::new();
    let mut part = ShadowVolume::new();
    for o in objects {
        if let Some(tris) = &o.caster {
            let topology = CasterTopology::new(o.positions.len(), tris)?;
            let sides = if topology.border_edge_count() > 0 {
                Sides::Two
            } else {
                Sides::One
            };
            let params = VolumeParams {
                sides,
                offset: o.offset,
                ..Default::default()
            };
            part.build(&topology, &o.positions, &light, &params)?;
            volume.append(&part);
        }
    }
    let intensity = match light {
        Light::Point(p) => (p - camera.target.as_dvec3()).length_squared() as f32,
        Light::Directional(_) => 1.0,
    };
    effect.set_lights(
        &gpu.device,
        &gpu.queue,
        &[FrameLight {
            light,
            intensity: Vec3::splat(intensity),
            volume: &volume,
            boundary,
        }],
    )?;
    Ok(renderer.render(
        &gpu.device,
        &gpu.queue,
        camera,
        Background::Color([0.0; 3]),
        &[&effect],
    )?)
}

/// Two panels side by side, tone-mapped with the left panel's automatic exposure.
fn pair(path: &Path, left: &HdrImage, right: &HdrImage) -> anyhow::Result<()> {
    let display = Display {
        exposure_ev: output::auto_exposure(left),
        curve: ToneCurve::AcesFitted,
    };
    let (w, h) = (left.width(), left.height());
    let mut out = image::RgbaImage::new(2 * w, h);
    for (k, img) in [left, right].iter().enumerate() {
        let rgba = output::to_rgba8(img, &display, Background::Color([0.0; 3]));
        let panel =
            image::RgbaImage::from_raw(w, h, rgba).ok_or_else(|| anyhow::anyhow!("panel size"))?;
        image::imageops::replace(&mut out, &panel, i64::from(w) * k as i64, 0);
    }
    figures::strip::write_png(path, &out)?;
    Ok(())
}

fn ground(centre: Vec3, half: f32) -> Object {
    let c = centre;
    Object {
        positions: vec![
            c + Vec3::new(-half, 0.0, -half),
            c + Vec3::new(half, 0.0, -half),
            c + Vec3::new(half, 0.0, half),
            c + Vec3::new(-half, 0.0, half),
        ],
        triangles: vec![[0, 2, 1], [0, 3, 2]],
        caster: None,
        offset: 0.0,
    }
}

/// Fig. 5.9: a 320-triangle sphere on the ground, the sun low from the side; left the stencil
/// alone (its terminator follows the silhouette edges), right through eq. 5.6 at α = 15°.
pub fn fig_5_9(gpu: &GpuContext, path: &Path) -> anyhow::Result<()> {
    let (p, t) = synth::obstacle_mesh(
        &synth::Obstacle::Sphere {
            centre: Vec3::new(0.0, 1.0, 0.0),
            radius: 1.0,
        },
        2,
    );
    let objects = [
        Object {
            positions: p,
            triangles: t.clone(),
            caster: Some(t),
            offset: 0.0,
        },
        ground(Vec3::ZERO, 4.0),
    ];
    let light = Light::Directional(DVec3::new(1.0, 0.6, 0.3).normalize());
    let camera = Camera::look_at(
        Vec3::new(-0.6, 2.2, 4.2),
        Vec3::new(0.0, 0.8, 0.0),
        Vec3::Y,
        40.0,
        512,
        512,
    );
    let smooth = SmoothBoundary {
        alpha_deg: 15.0,
        mode: BoundaryMode::Cosine,
    };
    let left = panel(gpu, &objects, light, None, &camera)?;
    let right = panel(gpu, &objects, light, Some(smooth), &camera)?;
    pair(path, &left, &right)
}

/// Fig. 4.3: the bunny over the ground under a point light; left the full caster, right its
/// 1 % level (694 triangles) — the display mesh whole in both, eq. 5.6 at α = 15° on both.
pub fn fig_4_3(
    gpu: &GpuContext,
    path: &Path,
    bunny: (&[Vec3], &[[u32; 3]]),
    coarse: (&[[u32; 3]], f64),
) -> anyhow::Result<()> {
    let (positions, triangles) = bunny;
    let floor = positions.iter().map(|p| p.y).fold(f32::INFINITY, f32::min);
    let centre = Vec3::new(-0.02, floor, 0.0);
    let light = Light::Point(DVec3::new(0.1, 0.3, 0.15));
    let camera = Camera::look_at(
        Vec3::new(0.05, 0.25, 0.32),
        centre + Vec3::new(-0.04, 0.05, -0.02),
        Vec3::Y,
        40.0,
        512,
        512,
    );
    let smooth = Some(SmoothBoundary {
        alpha_deg: 15.0,
        mode: BoundaryMode::Cosine,
    });
    let with = |caster: Vec<[u32; 3]>, offset| {
        [
            Object {
                positions: positions.to_vec(),
                triangles: triangles.to_vec(),
                caster: Some(caster),
                offset,
            },
            ground(centre, 0.3),
        ]
    };
    let left = panel(gpu, &with(triangles.to_vec(), 0.0), light, smooth, &camera)?;
    let right = panel(
        gpu,
        &with(coarse.0.to_vec(), coarse.1),
        light,
        smooth,
        &camera,
    )?;
    pair(path, &left, &right)
}
