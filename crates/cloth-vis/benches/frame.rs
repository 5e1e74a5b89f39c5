//! The shared frame on the demo's cloth (issue: "render"): per animation frame, the visibility
//! matrix on the cpu backend (level 3, 258 directions, cloth + ball + ground) and the frame
//! itself (768², MSAA where offered); and a 12-panel strip with the renderer built once
//! against one built per panel, as the facade did before (a shader compile and two pipelines
//! per panel); and the display image tone-mapped on the CPU after an HDR read-back against
//! the GPU tone-map pass. On a software adapter (lavapipe) the render times prove nothing about a GPU;
//! the strip ratio still shows what per-panel compilation cost.
//!
//! `cargo bench -p cloth-vis --bench frame`

use std::path::Path;

use cloth_vis::object::WorldObject;
use cloth_vis::scene::CameraDesc;
use criterion::{Criterion, criterion_group, criterion_main};
use glam::Vec3;
use render::{Background, DrawMesh, FrameFormat, Renderer};

fn object(
    name: &str,
    positions: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    two_sided: bool,
) -> WorldObject {
    let normals = meshio::compute_normals(&positions, &triangles, meshio::NormalWeighting::Angle);
    WorldObject {
        name: name.to_owned(),
        positions,
        normals,
        triangles,
        uvs: None,
        albedo: Vec3::splat(0.6),
        two_sided,
        front: None,
        back: None,
        animation: None,
    }
}

fn bench(c: &mut Criterion) {
    let Ok(gpu) = gpu_context::GpuContext::new(&Default::default()) else {
        eprintln!("no GPU adapter: the frame benchmarks need one (lavapipe is enough)");
        return;
    };
    let scene = cloth_vis::demo_scene().unwrap();
    let anim = synth::simulate_cloth(&synth::ClothParams::default()).unwrap();
    let (ball_p, ball_t) = synth::obstacle_mesh(&anim.obstacle, 4);
    let (gp, gt, _) = render::ground::ground_grid(Vec3::new(0.0, 0.0, 0.0), 0.0, 3.0, 64);
    let sphere = lightsphere::Lightsphere::new(3).unwrap();
    let sky = synth::sky(&synth::SkyParams::default()).unwrap();
    let env = lightsphere::Environment::from_latlong(sky.width, sky.height, sky.texels).unwrap();
    let radiance = env
        .radiance_per_direction(&sphere, lightsphere::RadianceMethod::CellMean)
        .unwrap();

    let mut group = c.benchmark_group("animation_frame_demo_cloth");
    group.sample_size(10);
    let mut frame = 0usize;
    let pose = |f: usize| {
        vec![
            object(
                "cloth",
                anim.frames[f].clone(),
                anim.triangles.clone(),
                true,
            ),
            object("ball", ball_p.clone(), ball_t.clone(), false),
            object("ground", gp.clone(), gt.clone(), false),
        ]
    };
    group.bench_function("visibility_cpu_level3", |b| {
        b.iter(|| {
            frame = (frame + 1) % anim.frames.len();
            let objects = pose(frame);
            cloth_vis::shadowing::visibility(&scene, &gpu, &objects, &sphere).unwrap()
        })
    });
    let mut objects = pose(anim.frames.len() - 1);
    let (vis, _) = cloth_vis::shadowing::visibility(&scene, &gpu, &objects, &sphere).unwrap();
    cloth_vis::shadowing::light_objects(&mut objects, &sphere, &radiance, Some(&vis)).unwrap();
    let mut renderer = Renderer::new(&gpu.device, FrameFormat::for_context(&gpu));
    renderer.backdrop.set_environment(
        &gpu.device,
        Some(render::Backdrop {
            width: env.width(),
            height: env.height(),
            texels: env.texels(),
            world_from_env: env.world_from_env(),
        }),
    );
    let all: Vec<Vec3> = objects[..2]
        .iter()
        .flat_map(|o| o.positions.clone())
        .collect();
    let (centre, radius) = render::bounding_sphere(&all).unwrap();
    let camera = cloth_vis::camera::resolve(&scene.camera, centre, radius);
    group.bench_function("render_768_update_in_place", |b| {
        b.iter(|| {
            let meshes: Vec<DrawMesh<'_>> = objects
                .iter()
                .map(|o| DrawMesh {
                    positions: &o.positions,
                    triangles: &o.triangles,
                    front: o.front.as_deref().unwrap(),
                    back: o.back.as_deref().unwrap(),
                })
                .collect();
            renderer
                .gouraud
                .set_meshes(&gpu.device, &gpu.queue, &meshes)
                .unwrap();
            renderer
                .render(
                    &gpu.device,
                    &gpu.queue,
                    &camera,
                    Background::Environment,
                    &[],
                )
                .unwrap()
        })
    });
    // The display image two ways: the HDR frame read back (16 B/pixel) and tone-mapped on the
    // CPU, or tone-mapped by the frame's last GPU pass and read back as 8-bit (4 B/pixel) —
    // what a viewer's per-frame cost depends on.
    let display = render::tone::Display::default();
    group.bench_function("display_768_cpu_tone_map_after_hdr_read_back", |b| {
        b.iter(|| {
            let hdr = renderer
                .render(
                    &gpu.device,
                    &gpu.queue,
                    &camera,
                    Background::Environment,
                    &[],
                )
                .unwrap();
            render::output::to_rgba8(&hdr, &display, Background::Environment)
        })
    });
    group.bench_function("display_768_gpu_tone_map_pass", |b| {
        b.iter(|| {
            renderer
                .render_display(
                    &gpu.device,
                    &gpu.queue,
                    &camera,
                    Background::Environment,
                    &[],
                    &display,
                )
                .unwrap()
        })
    });
    group.finish();

    // 12 panels of 256², the cloth animation.
    let mut group = c.benchmark_group("strip_12_panels");
    group.sample_size(10);
    let options = figures::strip::StripOptions {
        count: 12,
        panel_size: [256, 256],
        albedo: None,
    };
    group.bench_function("renderer_built_once", |b| {
        b.iter(|| {
            figures::strip::render_strip(
                &gpu.device,
                &gpu.queue,
                &anim.frames,
                &anim.triangles,
                &options,
                Path::new("bench"),
            )
            .unwrap()
        })
    });
    let strip_camera = cloth_vis::camera::resolve(
        &CameraDesc {
            width: 256,
            height: 256,
            ..CameraDesc::default()
        },
        centre,
        radius,
    );
    let grey = vec![Vec3::splat(0.5); anim.frames[0].len()];
    group.bench_function("renderer_built_per_panel_as_before", |b| {
        b.iter(|| {
            for k in 0..12 {
                let f = k * (anim.frames.len() - 1) / 11;
                // What the facade's render() did per call: compile, build, draw, read back.
                let mut r = Renderer::new(&gpu.device, FrameFormat::single_sample(&gpu.device));
                r.gouraud
                    .set_meshes(
                        &gpu.device,
                        &gpu.queue,
                        &[DrawMesh {
                            positions: &anim.frames[f],
                            triangles: &anim.triangles,
                            front: &grey,
                            back: &grey,
                        }],
                    )
                    .unwrap();
                r.render(
                    &gpu.device,
                    &gpu.queue,
                    &strip_camera,
                    Background::Color([0.0; 3]),
                    &[],
                )
                .unwrap();
            }
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
