//! `cargo xtask repro fins`: silhouette enhancement with BTF fins (thesis §5.7) on the
//! synthetic wool of `synth::fins`:
//!
//! 1. the 81 images of Table 5.3 at 128² (time), and their PCA (eq. 5.14 with the mean)
//!    against c: error in 8-bit sRGB units, PSNR, `.finpca` size, time — where the default
//!    c = 16 sits (the thesis: "around 16 additional textures");
//! 2. fin extraction per frame on the deforming drape (`synth:cloth`, 4,356 vertices,
//!    120 frames): median and worst milliseconds on one core, fins per frame;
//! 3. with an adapter, Figs. 5.23 and 5.24: the UV sphere and the draped dress of
//!    `../shared/data` (the drape's last frame when the data is absent), each without and
//!    with fins under the same light, side by side, and what the fins cost in the frame.
//!
//! Writes `target/repro/fins.md`, `fins-error.svg`, `fins-fig5.23.png`, `fins-fig5.24.png`.

use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

use btf::fin_pca::FinPca;
use btf::fins::{FinBuilder, FinMesh, FinParams, Viewer};
use btf::render::{Light, RenderParams};
use btf::{BtfPcaParams, Storage};
use cloth_vis::fins_stage::{FinLook, welded_triangles, wool_images};
use cloth_vis::object::WorldObject;
use figures::chart::{Axis, Series, chart_svg};
use glam::{Vec2, Vec3};

/// Component counts of the sweep (80 keeps every image).
const SWEEP_C: [usize; 7] = [1, 2, 4, 8, 16, 32, 80];

/// Runs the reproduction and writes its files under `out`.
///
/// # Errors
/// Generator, compression, file and GPU errors.
pub fn run(out: &Path) -> anyhow::Result<()> {
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# BTF fins (thesis §5.7)\n\n`cargo xtask repro fins`, {} rayon threads. Data: the \
         synthetic wool of `synth::fins` (default parameters, 128² × 2² samples, 400 strands), \
         81 images under the lights of Table 5.3 at the grazing view θ_V = 90°.\n",
        rayon::current_num_threads()
    );
    let start = Instant::now();
    let images = wool_images(&synth::fins::WoolFinParams::default())?;
    let _ = writeln!(
        md,
        "Rendering the 81 images: {:.2} s.\n\n## PCA against c (eq. 5.14 with the mean)\n\n\
         8-bit eigen-images, 16-bit mean (80: f32 both); error over all 81 images.\n\n\
         | c | RMS (8-bit sRGB) | max | PSNR dB | `.finpca` KB | compress s |\n|---|---|---|---|---|---|",
        start.elapsed().as_secs_f64()
    );
    let mut points = Vec::new();
    for c in SWEEP_C {
        let exact = c == 80;
        let params = BtfPcaParams {
            components: c,
            storage: if exact { Storage::F32 } else { Storage::U8 },
            mean_storage: if exact { Storage::F32 } else { Storage::U16 },
            ..Default::default()
        };
        let t = Instant::now();
        let fins = FinPca::from_images(&images, &params)?;
        let seconds = t.elapsed().as_secs_f64();
        let stats = fins.stats(&images)?;
        let _ = writeln!(
            md,
            "| {c} | {:.2} | {:.1} | {:.1} | {:.0} | {:.2} |",
            stats.rms_srgb8,
            stats.max_abs_srgb8,
            stats.psnr_db,
            fins.to_bytes().len() as f64 / 1e3,
            seconds
        );
        points.push((c as f64, stats.rms_srgb8.max(1e-3)));
    }
    let svg = chart_svg(
        "Fin BTF: reconstruction error against c",
        ["components c", "RMS error (8-bit sRGB)"],
        [Axis::Log, Axis::Log],
        &[Series {
            label: "synthetic wool 128²".into(),
            points,
        }],
    );
    atomic_out::write_bytes(&out.join("fins-error.svg"), svg.as_bytes())?;

    extraction(&mut md)?;
    match gpu_context::GpuContext::new(&Default::default()) {
        Ok(gpu) => pictures(&mut md, out, &gpu)?,
        Err(e) => {
            let _ = writeln!(md, "\nNo GPU adapter ({e}): Figs. 5.23/5.24 not drawn.");
        }
    }
    atomic_out::write_bytes(&out.join("fins.md"), md.as_bytes())?;
    println!("{md}");
    Ok(())
}

/// Fin extraction on every frame of the deforming drape.
fn extraction(md: &mut String) -> anyhow::Result<()> {
    let anim = synth::simulate_cloth(&synth::ClothParams::default())?;
    let welded = welded_triangles(&anim.frames[0], &anim.triangles);
    let mut builder = FinBuilder::new(&welded, anim.vertex_count())?;
    let mut mesh = FinMesh::default();
    let (centre, radius) = render::bounding_sphere(anim.frames[0].iter()).unwrap_or_default();
    let eye = centre + Vec3::new(0.55, 0.45, 1.0).normalize() * 3.0 * radius.max(1e-3);
    let params = FinParams {
        material_size: 0.04 * radius,
        height: 1.0,
        offset: 0.0,
    };
    let (mut times, mut counts) = (Vec::new(), Vec::new());
    for frame in &anim.frames {
        let normals =
            meshio::compute_normals(frame, &anim.triangles, meshio::NormalWeighting::Angle);
        let t = Instant::now();
        builder.build(frame, &normals, Viewer::Eye(eye), &params, &mut mesh);
        times.push(t.elapsed().as_secs_f64() * 1e3);
        counts.push(mesh.len());
    }
    let mut sorted = times.clone();
    sorted.sort_by(f64::total_cmp);
    let _ = writeln!(
        md,
        "\n## Fin extraction per frame (§5.7.3)\n\nThe drape of `synth:cloth` ({} vertices, \
         {} triangles, {} frames), silhouette for a fixed eye, fins built on the \
         position-welded topology: median **{:.3} ms**, worst {:.3} ms per frame on one core \
         (target ≤ 2 ms for 10k triangles); {}–{} fins per frame.",
        anim.vertex_count(),
        anim.triangles.len(),
        anim.frames.len(),
        sorted[sorted.len() / 2],
        sorted[sorted.len() - 1],
        counts.iter().min().unwrap_or(&0),
        counts.iter().max().unwrap_or(&0),
    );
    Ok(())
}

fn object(
    name: &str,
    positions: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    uvs: Vec<Vec2>,
) -> WorldObject {
    let normals = meshio::compute_normals(&positions, &triangles, meshio::NormalWeighting::Angle);
    WorldObject::textured(name, positions, normals, triangles, Some(uvs))
}

/// Figs. 5.23 and 5.24 with the woven BTF of `synth` (32², c = 16) on the surface.
fn pictures(md: &mut String, out: &Path, gpu: &gpu_context::GpuContext) -> anyhow::Result<()> {
    let pca = cloth_vis::btf_stage::synth_material(32, 16)?;
    let fins = FinPca::from_images(
        &wool_images(&synth::fins::WoolFinParams::default())?,
        &BtfPcaParams::default(),
    )?;
    let (p, t, uv) = cloth_vis::object::uv_sphere(48, 96);
    let sphere = object("sphere", p.clone(), t, uv);
    // Exact sphere normals (the positions), as `btf render synth:sphere` uses.
    let sphere = WorldObject {
        normals: p,
        ..sphere
    };
    let dress = match test_data::shared_file("meshes/garments/dress-victor-iso-draped.obj") {
        Some(path) => {
            let options = meshio::LoadOptions {
                recompute_normals: true,
                ..Default::default()
            };
            let (split, _) = meshio::load_mesh_split_seams(&path, &options)?;
            let m = split.mesh;
            let uvs = m
                .uvs
                .ok_or_else(|| anyhow::anyhow!("the dress has no UVs"))?;
            (
                object("dress", m.positions, m.triangles, uvs),
                Vec3::Z,
                "the draped dress",
            )
        }
        None => {
            let anim = synth::simulate_cloth(&synth::ClothParams::default())?;
            let last = anim.frames.len() - 1;
            let cloth = object("cloth", anim.frames[last].clone(), anim.triangles, anim.uvs);
            (cloth, Vec3::Y, "the synthetic drape (shared data absent)")
        }
    };
    let _ = writeln!(
        md,
        "\n## Figs. 5.23 and 5.24 (left without, right with fins)\n\nWoven BTF of `synth` \
         (32², c = 16) on the surface, fins of the wool at c = 16, fin size 4 % of the \
         bounding radius, height 1 material unit; one directional light; frames on `{}` \
         (median of 3, read-back included).\n\n\
         | picture | object | vertices | fins | extraction ms | lighting ms | frame ms without | with | fins' share |\n\
         |---|---|---|---|---|---|---|---|---|",
        gpu.adapter.get_info().name
    );
    let figures = [
        (
            "fins-fig5.23.png",
            &sphere,
            Vec3::Y,
            "the UV sphere",
            Vec3::new(0.2, 0.7, 0.7),
        ),
        (
            "fins-fig5.24.png",
            &dress.0,
            dress.1,
            dress.2,
            Vec3::new(0.5, -0.8, 0.7),
        ),
    ];
    for (file, object, up, what, light_dir) in figures {
        let (centre, radius) = render::bounding_sphere(object.positions.iter()).unwrap_or_default();
        // The camera direction (0.55, 0.45, 1) of `btf render`, turned onto the mesh's up.
        let direction = if up == Vec3::Z {
            Vec3::new(0.55, -1.0, 0.45)
        } else {
            Vec3::new(0.55, 0.45, 1.0)
        };
        let light_dir = if up == Vec3::Z {
            light_dir
        } else {
            Vec3::new(0.2, 0.7, 0.7)
        };
        let camera = cloth_vis::camera::frame_sphere(direction, up, centre, radius, 480, 480);
        let light = Light::Directional {
            dir_to_light_world: light_dir,
            radiance: Vec3::splat(1.3),
        };
        let mut params = RenderParams::default();
        params.uv_scale = Vec2::splat(4.0);
        let look = FinLook::for_radius(radius, None, None);
        let (without, with, cost) = cloth_vis::btf_stage::render_with_fins(
            gpu,
            &pca,
            &[object],
            &light,
            &camera,
            &params,
            &fins,
            &look,
        )?;
        let picture = cloth_vis::btf_stage::side_by_side(&without, &with);
        figures::strip::write_png(&out.join(file), &picture)?;
        let _ = writeln!(
            md,
            "| `{file}` | {what} | {} | {} | {:.2} | {:.2} | {:.1} | {:.1} | {:+.0} % |",
            object.positions.len(),
            cost.fins,
            cost.extract_ms,
            cost.prepare_ms,
            cost.frame_without_ms,
            cost.frame_ms,
            100.0 * (cost.frame_ms / cost.frame_without_ms.max(1e-9) - 1.0)
        );
    }
    Ok(())
}
