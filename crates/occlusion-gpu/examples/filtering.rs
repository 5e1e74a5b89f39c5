//! What vertex filtering (paper 000 §4.1) saves: prints markdown tables of rows computed and
//! visibility time with and without filtering, on a camera orbit around the Stanford bunny
//! (static) and on the synthetic cloth animation (deforming, fixed camera) at k = 66, beside
//! the seed's Table 1.
//!
//! ```text
//! cargo run --release -p occlusion-gpu --example filtering -- [BUNNY.ply] [ORBIT_FRAMES] [CLOTH_FRAMES]
//! ```
//! Defaults: `../shared/data/meshes/bun_zipper.ply`, 24 orbit frames, 30 cloth frames. The
//! `cpu` backend always runs; the `depth` backend and the GPU id pass run when an adapter
//! exists (a software adapter's times say nothing about a real GPU).

use std::time::{Duration, Instant};

use glam::Vec3;
use gpu_context::{GpuContext, GpuOptions};
use lightsphere::Lightsphere;
use occlusion_gpu::{
    Backend, Camera, FilterParams, FilteredVisibility, Scene, SceneObject, TriangleVisibility,
    VisibilityEngine, VisibilityParams,
};

/// Lightsphere level of both tables: k = 66, the seed's Table 1 row compared.
const LEVEL: u32 = 2;
/// Id-pass resolution (the seed rendered at 1280 × 960; the bunny fills about half of it).
const VIEW: u32 = 512;

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1000.0
}

fn bounds(scene: &Scene) -> (Vec3, f32) {
    let points = scene.objects().iter().flat_map(|o| o.positions.iter());
    let (lo, hi) = points.fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| {
        (lo.min(*p), hi.max(*p))
    });
    (0.5 * (lo + hi), 0.5 * (hi - lo).length())
}

struct Engines<'a> {
    ctx: Option<&'a GpuContext>,
}

impl Engines<'_> {
    fn backends(&self) -> Vec<Backend> {
        let mut backends = vec![Backend::Cpu];
        if self.ctx.is_some() {
            backends.push(Backend::Depth);
        }
        backends
    }

    fn engine(&self, backend: Backend) -> VisibilityEngine {
        match (backend, self.ctx) {
            (Backend::Cpu, _) | (_, None) => VisibilityEngine::cpu(VisibilityParams::default()),
            (backend, Some(ctx)) => {
                VisibilityEngine::with_gpu(&ctx.device, &ctx.queue, backend, Default::default())
            }
        }
    }

    fn visibility(&self) -> TriangleVisibility {
        match self.ctx {
            Some(ctx) => TriangleVisibility::gpu(&ctx.device, &ctx.queue),
            None => TriangleVisibility::Cpu,
        }
    }
}

fn bunny_orbit(engines: &Engines, scene: &Scene, frames: usize) -> anyhow_free::Result {
    let sphere = Lightsphere::new(LEVEL)?;
    let (center, radius) = bounds(scene);
    let n = scene.receiver_count();
    println!(
        "\n## Bunny orbit: {n} vertices, {} triangles, k = {}, {frames} frames, id pass {VIEW}²\n",
        scene.triangle_count(),
        sphere.len()
    );
    println!("Without filtering a static mesh computes all N rows once (frame 0).\n");
    println!(
        "| backend | mode | rows frame 0 | rows total | ms frame 0 | ms total | seed Table 1 bunny 35k, k = 66 |"
    );
    println!("|---|---|---:|---:|---:|---:|---|");
    let mut per_frame = Vec::new();
    for backend in engines.backends() {
        let mut engine = engines.engine(backend);
        engine.compute(scene, &sphere)?; // warm-up (pipelines, caches)
        let start = Instant::now();
        engine.compute(scene, &sphere)?;
        let full = start.elapsed();
        println!(
            "| {} | full | {n} | {n} | {:.1} | {:.1} | time1 3606 ms |",
            backend.name(),
            ms(full),
            ms(full)
        );
        let mut driver = FilteredVisibility::new(
            engines.engine(backend),
            engines.visibility(),
            FilterParams::default(),
        )?;
        let (mut rows_total, mut time_total, mut first) = (0, Duration::ZERO, (0, Duration::ZERO));
        for f in 0..frames {
            let angle = std::f32::consts::TAU * f as f32 / frames as f32;
            let eye = center + 2.5 * radius * Vec3::new(angle.cos(), 0.3, angle.sin());
            let camera = Camera::look_at(eye, center, Vec3::Y, 0.7, VIEW, VIEW)?;
            let start = Instant::now();
            let stats = driver.frame(scene, &sphere, &camera, false)?;
            let time = start.elapsed();
            if f == 0 {
                first = (stats.rows_computed, time);
            }
            rows_total += stats.rows_computed;
            time_total += time;
            if backend == Backend::Cpu {
                per_frame.push((f, stats));
            }
        }
        println!(
            "| {} | filtered | {} | {rows_total} | {:.1} | {:.1} | time2 2666 ms |",
            backend.name(),
            first.0,
            ms(first.1),
            ms(time_total)
        );
    }
    println!("\nPer frame (cpu backend, filtered):\n");
    println!("| frame | visible tris | new tris | unseen tris | rows | id pass ms | rows ms |");
    println!("|---:|---:|---:|---:|---:|---:|---:|");
    for (f, s) in per_frame {
        println!(
            "| {f} | {} | {} | {} | {} | {:.2} | {:.2} |",
            s.triangles_visible.map_or("-".into(), |v| v.to_string()),
            s.triangles_new,
            s.triangles_unseen,
            s.rows_computed,
            ms(s.visibility_time),
            ms(s.compute_time)
        );
    }
    Ok(())
}

fn cloth(engines: &Engines, frames: usize) -> anyhow_free::Result {
    let params = synth::ClothParams {
        frames,
        ..Default::default()
    };
    let start = Instant::now();
    let animation = synth::simulate_cloth(&params)?;
    eprintln!("cloth simulated in {:.1} s", start.elapsed().as_secs_f64());
    let scenes: Vec<Scene> = animation
        .frames
        .iter()
        .map(|p| {
            let normals =
                meshio::compute_normals(p, &animation.triangles, meshio::NormalWeighting::Area);
            let mut scene = Scene::new();
            scene.push(SceneObject::new(
                p.clone(),
                normals,
                animation.triangles.clone(),
            ))?;
            Ok(scene)
        })
        .collect::<Result<_, occlusion_gpu::OcclusionError>>()?;
    let sphere = Lightsphere::new(LEVEL)?;
    let n = animation.vertex_count();
    // Fixed camera from the side, as a viewer of a draped cloth would stand.
    let camera = Camera::look_at(
        Vec3::new(3.0, 1.2, 1.0),
        Vec3::new(0.0, 0.4, 0.0),
        Vec3::Y,
        0.8,
        VIEW,
        VIEW,
    )?;
    println!(
        "\n## Cloth animation (deforming): {n} vertices, {} triangles, k = {}, {frames} frames, fixed camera\n",
        animation.triangles.len(),
        sphere.len()
    );
    println!(
        "| backend | mode | mean rows/frame | mean ms/frame | of which id pass ms | seed Table 1 trousers (3219 v, k = 66) |"
    );
    println!("|---|---|---:|---:|---:|---|");
    for backend in engines.backends() {
        let mut engine = engines.engine(backend);
        engine.compute(&scenes[0], &sphere)?;
        let start = Instant::now();
        for scene in &scenes {
            engine.compute(scene, &sphere)?;
        }
        let full = start.elapsed() / frames as u32;
        println!(
            "| {} | full | {n} | {:.1} | - | time1 330 ms |",
            backend.name(),
            ms(full)
        );
        let mut driver = FilteredVisibility::new(
            engines.engine(backend),
            engines.visibility(),
            FilterParams::default(),
        )?;
        driver.frame(&scenes[0], &sphere, &camera, true)?; // warm-up
        let (mut rows, mut ids) = (0, Duration::ZERO);
        let start = Instant::now();
        for scene in &scenes {
            let stats = driver.frame(scene, &sphere, &camera, true)?;
            rows += stats.rows_computed;
            ids += stats.visibility_time;
        }
        let filtered = start.elapsed() / frames as u32;
        println!(
            "| {} | filtered | {} | {:.1} | {:.1} | time2 222 ms |",
            backend.name(),
            rows / frames,
            ms(filtered),
            ms(ids / frames as u32)
        );
    }
    Ok(())
}

/// Boxed errors without an `anyhow` dependency.
mod anyhow_free {
    pub type Result<T = ()> = std::result::Result<T, Box<dyn std::error::Error>>;
}

fn main() -> anyhow_free::Result {
    let mut args = std::env::args().skip(1);
    let bunny = args
        .next()
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| test_data::data_root().join("meshes/bun_zipper.ply"));
    let orbit_frames: usize = args.next().map_or(Ok(24), |a| a.parse())?;
    let cloth_frames: usize = args.next().map_or(Ok(30), |a| a.parse())?;
    let ctx = GpuContext::new(&GpuOptions::default()).ok();
    match &ctx {
        Some(ctx) => println!("Adapter: {}", ctx.summary()),
        None => println!("No GPU adapter: cpu backend and CPU id rasteriser only."),
    }
    println!(
        "Machine: {} CPU threads.",
        std::thread::available_parallelism().map_or(1, |n| n.get())
    );
    let engines = Engines { ctx: ctx.as_ref() };
    if bunny.is_file() {
        let (mesh, _) = meshio::load_mesh(&bunny, &meshio::LoadOptions::default())?;
        let scene = Scene::single(mesh.positions, mesh.normals, mesh.triangles)?;
        bunny_orbit(&engines, &scene, orbit_frames.max(1))?;
    } else {
        println!("\n(bunny skipped: {} not found)", bunny.display());
    }
    cloth(&engines, cloth_frames.max(1))?;
    Ok(())
}
