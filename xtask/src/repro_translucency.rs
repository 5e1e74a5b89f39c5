//! `cargo xtask repro translucency [--quick]`: seed 004's Table 1 rebuilt (crate
//! `translucency`; SEED-NOTES §5.3):
//!
//! - (a) per-pass times of the per-frame pipeline — cube map, SH projection, light distance
//!   map with its peeled layer, blur — and of the frame that evaluates eq. 12 (with the Gouraud
//!   meshes and the read-back), medians over the frames, for the bunny (69,451 triangles, the
//!   paper's model) and the dragon of `../shared/data`, static and under the sine deformer of
//!   Fig. 12 (its CPU work — positions, normals, E_t — timed apart), beside the paper's fps
//!   (GeForce 6800, 512² viewport, 64² cube map, 512² shadow map);
//! - (b) TR 164's claim that 128² and 256² cube maps "did not significantly change" E_lm: the
//!   relative change of E_lm against 256² on the bunny;
//! - (c) the ringing of SH9 under a delta light, and what each window leaves.
//!
//! Writes `target/repro/translucency.md` (atomically). Without an adapter only (c) runs.

use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

use glam::{DVec3, Vec3};
use render::{Background, Camera, DrawMesh, FrameFormat, Renderer};
use translucency::gpu::{PassTimes, PipelineParams, TranslucencyPass, TranslucentMesh};
use translucency::model::{self, Light};
use translucency::{Material, Window, sh};

/// The paper's models and fps (TR 162–167).
const MODELS: [(&str, &str, f64); 2] = [
    ("bunny", "meshes/bun_zipper.ply", 65.2),
    ("dragon", "meshes/dragon_vrip_res2.ply", 83.6),
];

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Runs the reproduction into `out`.
pub fn run(out: &Path, quick: bool) -> anyhow::Result<()> {
    let mut md = String::new();
    writeln!(
        md,
        "# Translucency by spherical harmonics (seed 004, Table 1)\n"
    )?;
    match gpu_context::GpuContext::new(&Default::default()) {
        Ok(gpu) => {
            writeln!(md, "Adapter: {}.\n", gpu.summary())?;
            table_1(&mut md, &gpu, quick)?;
            cube_sizes(&mut md, &gpu)?;
        }
        Err(e) => writeln!(md, "No GPU adapter ({e}): (a) and (b) skipped.\n")?,
    }
    ringing(&mut md)?;
    atomic_out::write_bytes(&out.join("translucency.md"), md.as_bytes())?;
    print!("{md}");
    Ok(())
}

struct Loaded {
    positions: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
}

fn load(relative: &str) -> anyhow::Result<Loaded> {
    let path = test_data::data_root().join(relative);
    let (mesh, _) = meshio::load_mesh(&path, &meshio::LoadOptions::default())?;
    Ok(Loaded {
        positions: mesh.positions,
        triangles: mesh.triangles,
    })
}

/// One model's frames: pass medians, frame median, CPU deformer median.
fn frames(
    gpu: &gpu_context::GpuContext,
    mesh: &Loaded,
    deform: bool,
    count: usize,
) -> anyhow::Result<(PassTimes, f64, f64)> {
    let format = FrameFormat::for_context(gpu);
    let mut renderer = Renderer::new(&gpu.device, format);
    let mut pass = TranslucencyPass::new(
        &gpu.device,
        &renderer.pass_context(),
        PipelineParams::default(),
    )?;
    let (lo, hi) = mesh
        .positions
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(*p), hi.max(*p))
        });
    let (centre, radius) = ((lo + hi) / 2.0, (hi - lo).length() / 2.0);
    let camera = Camera::framing(
        centre,
        radius,
        centre,
        Vec3::new(0.0, 0.15, 1.0),
        Vec3::Y,
        35.0,
        512,
        512,
    );
    let light = Light::Point((centre + radius * Vec3::new(-0.8, 1.2, -2.5)).as_dvec3());
    let material = Material::preset("skin1")?;
    let desc = cloth_vis::scene::SineDeformDesc {
        amplitude: 0.05,
        waves: 1.0,
        frames: count,
    };
    let (mut passes, mut totals, mut cpu) = (Vec::new(), Vec::new(), Vec::new());
    for f in 0..count + 1 {
        let t = Instant::now();
        let positions = if deform {
            cloth_vis::deform::sine_frame(&mesh.positions, &desc, f)
        } else {
            mesh.positions.clone()
        };
        let normals =
            meshio::compute_normals(&positions, &mesh.triangles, meshio::NormalWeighting::Angle);
        let p64: Vec<DVec3> = positions.iter().map(|p| p.as_dvec3()).collect();
        let power = [(light_position(&light) - centre.as_dvec3()).length_squared(); 3];
        let e_t =
            model::transmitted_irradiance(&p64, &normals, &light, power, material.eta, |_| 1.0);
        let rd = material.diffuse_reflectance();
        let direct: Vec<Vec3> = e_t
            .iter()
            .map(|e| {
                Vec3::new(
                    e[0] * rd[0] as f32,
                    e[1] * rd[1] as f32,
                    e[2] * rd[2] as f32,
                ) / std::f32::consts::PI
            })
            .collect();
        let cpu_ms = t.elapsed().as_secs_f64() * 1e3;
        let mesh_in = TranslucentMesh {
            positions: &p64,
            normals: &normals,
            triangles: &mesh.triangles,
            irradiance: &e_t,
        };
        let times = pass.prepare(
            &gpu.device,
            &gpu.queue,
            &mesh_in,
            light,
            &material,
            camera.eye.as_dvec3(),
            true,
        )?;
        let t = Instant::now();
        renderer.gouraud.set_meshes(
            &gpu.device,
            &gpu.queue,
            &[DrawMesh {
                positions: &positions,
                triangles: &mesh.triangles,
                front: &direct,
                back: &direct,
            }],
        )?;
        renderer.render(
            &gpu.device,
            &gpu.queue,
            &camera,
            Background::Color([0.0; 3]),
            &[&pass],
        )?;
        let frame_ms = t.elapsed().as_secs_f64() * 1e3;
        // The first frame warms caches and allocates: left out.
        if f > 0 {
            passes.push(times);
            totals.push(times.total + frame_ms);
            cpu.push(cpu_ms);
        }
        let _ = frame_ms;
    }
    let pick = |get: fn(&PassTimes) -> f64| median(passes.iter().map(get).collect());
    let medians = PassTimes {
        upload: pick(|t| t.upload),
        cube_map: pick(|t| t.cube_map),
        sh_projection: pick(|t| t.sh_projection),
        light_map: pick(|t| t.light_map),
        blur: pick(|t| t.blur),
        total: pick(|t| t.total),
    };
    Ok((medians, median(totals), median(cpu)))
}

fn light_position(light: &Light) -> DVec3 {
    match *light {
        Light::Point(p) => p,
        Light::Directional(d) => d,
    }
}

fn table_1(md: &mut String, gpu: &gpu_context::GpuContext, quick: bool) -> anyhow::Result<()> {
    let count = if quick { 4 } else { 20 };
    writeln!(
        md,
        "## (a) Table 1: per-pass times (median of {count} frames, ms)\n"
    )?;
    writeln!(
        md,
        "Each pass submitted and waited for (so the sum is slower than one submission). Frame = \
         the shared frame with the Gouraud mesh, eq. 12 added, 4× MSAA resolve and the read-back \
         of the 512² HDR image. CPU = deformer, normals, E_t per vertex. Skin1, a point light \
         behind the model.\n"
    )?;
    writeln!(
        md,
        "| model | triangles | deformed | upload | cube map | SH | light map + peel | blur | passes + frame | CPU | fps (ours) | fps (paper, GeForce 6800) |"
    )?;
    writeln!(md, "|---|---|---|---|---|---|---|---|---|---|---|---|")?;
    for (name, path, paper) in MODELS {
        let mesh = load(path)?;
        for deform in [false, true] {
            let (t, total, cpu) = frames(gpu, &mesh, deform, count)?;
            writeln!(
                md,
                "| {name} | {} | {} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {paper} |",
                mesh.triangles.len(),
                if deform { "sine" } else { "no" },
                t.upload,
                t.cube_map,
                t.sh_projection,
                t.light_map,
                t.blur,
                total,
                cpu,
                1e3 / (total + if deform { cpu } else { 0.0 }),
            )?;
        }
    }
    writeln!(md)?;
    Ok(())
}

fn cube_sizes(md: &mut String, gpu: &gpu_context::GpuContext) -> anyhow::Result<()> {
    writeln!(
        md,
        "## (b) Cube-map size (TR 164: 128² and 256² \"did not significantly change\" E_lm)\n"
    )?;
    let mesh = load(MODELS[0].1)?;
    let normals = meshio::compute_normals(
        &mesh.positions,
        &mesh.triangles,
        meshio::NormalWeighting::Angle,
    );
    let p64: Vec<DVec3> = mesh.positions.iter().map(|p| p.as_dvec3()).collect();
    let light = Light::Point(DVec3::new(-0.1, 0.25, -0.25));
    let material = Material::preset("skin1")?;
    let e_t =
        model::transmitted_irradiance(&p64, &normals, &light, [1.0; 3], material.eta, |_| 1.0);
    let renderer = Renderer::new(&gpu.device, FrameFormat::single_sample(&gpu.device));
    let mut results = Vec::new();
    for size in [32, 64, 128, 256] {
        let mut pass = TranslucencyPass::new(
            &gpu.device,
            &renderer.pass_context(),
            PipelineParams {
                cube_size: size,
                light_map_size: 64,
                ..Default::default()
            },
        )?;
        let m = TranslucentMesh {
            positions: &p64,
            normals: &normals,
            triangles: &mesh.triangles,
            irradiance: &e_t,
        };
        let times = pass.prepare(
            &gpu.device,
            &gpu.queue,
            &m,
            light,
            &material,
            DVec3::new(0.0, 0.1, 0.5),
            true,
        )?;
        results.push((
            size,
            pass.read_coefficients(&gpu.device, &gpu.queue)?,
            times,
        ));
    }
    let reference = results.last().expect("four sizes").1;
    writeln!(
        md,
        "| cube face | relative change of E_lm against 256² | max change of B over the sphere | cube map ms | SH ms |"
    )?;
    writeln!(md, "|---|---|---|---|---|")?;
    for (size, e, t) in &results {
        let (mut num, mut den) = (0.0, 0.0);
        for k in 0..9 {
            for c in 0..3 {
                num += (e.coeffs[k][c] - reference.coeffs[k][c]).powi(2);
                den += reference.coeffs[k][c].powi(2);
            }
        }
        let mut worst = 0.0f64;
        let mut peak = 0.0f64;
        for i in 0..2000 {
            let y = 1.0 - 2.0 * (f64::from(i) + 0.5) / 2000.0;
            let r = (1.0 - y * y).sqrt();
            let phi = 2.399_963 * f64::from(i);
            let d = DVec3::new(r * phi.cos(), y, r * phi.sin());
            let (a, b) = (
                e.irradiance_clamped(d)[1],
                reference.irradiance_clamped(d)[1],
            );
            worst = worst.max((a - b).abs());
            peak = peak.max(b);
        }
        writeln!(
            md,
            "| {size}² | {:.2e} | {:.2} % of its peak | {:.1} | {:.1} |",
            (num / den).sqrt(),
            100.0 * worst / peak,
            t.cube_map,
            t.sh_projection
        )?;
    }
    writeln!(md)?;
    Ok(())
}

fn ringing(md: &mut String) -> anyhow::Result<()> {
    writeln!(
        md,
        "## (c) Ringing of SH9 under a delta light (B's minimum over the sphere; exact: 0)\n"
    )?;
    writeln!(md, "| window | h1 | h2 | min B | B(r = l) (exact 1) |")?;
    writeln!(md, "|---|---|---|---|---|")?;
    for (name, w) in [
        ("none", Window::None),
        ("Lanczos 3", Window::Lanczos { width: 3.0 }),
        ("Lanczos 4", Window::Lanczos { width: 4.0 }),
        ("Gaussian 8", Window::Gaussian { width: 8.0 }),
        ("Gaussian 5", Window::Gaussian { width: 5.0 }),
        ("Gaussian 3", Window::Gaussian { width: 3.0 }),
    ] {
        let h = w.factors();
        let top = translucency::Sh9::delta(DVec3::Z, [1.0; 3])
            .windowed(w)
            .irradiance(DVec3::Z)[0];
        writeln!(
            md,
            "| {name} | {:.3} | {:.3} | {:+.4} | {:.3} |",
            h[1],
            h[2],
            sh::delta_response_minimum(w),
            top
        )?;
    }
    writeln!(md)?;
    Ok(())
}
