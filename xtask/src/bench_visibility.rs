//! `cargo xtask bench visibility [--quick] [--threads N]`: the `cpu` backend of occlusion-gpu
//! beside Mitsuba 3 (Embree through its `llvm_ad_rgb` variant) and Open3D (`RaycastingScene`,
//! Embree) on the same rays, the same triangles and the same number of threads, in one run
//! (issue #20 item 5).
//!
//! Cases: the bunny at k = 6 … 1026, the dragon and igea at k = 258, one frame of the synthetic
//! drape (with its ball) at k = 66 and 258 (`--quick`: the bunny at k = 66 and 258). Per case
//! the rays the engine casts — every receiver vertex pushed off its surface by
//! `DEFAULT_OFFSET_RELATIVE` × the diagonal along its normal, towards every direction with
//! n·l > 0 — and the triangle soup in the engine's centred coordinates are written as `.npy`
//! under `target/bench-visibility/`; `xtask/scripts/visibility_peers.py` traces them in a
//! virtual environment under `target/mitsuba-venv` (Mitsuba and Open3D are comparisons, not
//! dependencies). Ours: a fresh engine per run (BVH build + trace, as a deforming frame pays)
//! and, on the same engine, the trace alone (the BVH reused). Peers: scene build and trace
//! apart. Times are medians; the occluded-ray counts are compared as a cross-check. Writes
//! `target/repro/bench-visibility.md`. Open3D's wheel needs `libusb-1.0-0` (Debian); a peer that
//! cannot be imported is reported in its column, not fatal.

use std::fmt::Write as _;
use std::path::Path;
use std::process::Command;
use std::time::Instant;

use anyhow::{Context, bail};
use glam::Vec3;
use lightsphere::Lightsphere;
use occlusion_gpu::{RayCaster, Scene, SceneObject, VisibilityEngine, VisibilityParams};

pub(crate) struct Case {
    pub(crate) name: String,
    pub(crate) scene: Scene,
    level: u32,
}

struct Ours {
    rays: u64,
    occluded: u64,
    full_ms: f64,
    trace_ms: f64,
}

pub(crate) fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

pub(crate) fn mesh_case(name: &str, relative: &str, level: u32) -> anyhow::Result<Case> {
    let path = test_data::data_root().join(relative);
    let (mesh, _) = meshio::load_mesh(&path, &meshio::LoadOptions::default())
        .with_context(|| path.display().to_string())?;
    let sphere_k = Lightsphere::new(level)?.len();
    Ok(Case {
        name: format!("{name}-k{sphere_k}"),
        scene: Scene::single(mesh.positions, mesh.normals, mesh.triangles)?,
        level,
    })
}

pub(crate) fn drape_case(level: u32) -> anyhow::Result<Case> {
    let params = synth::ClothParams::default();
    let cloth = synth::simulate_cloth(&params)?;
    let frame = &cloth.frames[cloth.frames.len() / 2];
    let normals = meshio::compute_normals(frame, &cloth.triangles, meshio::NormalWeighting::Angle);
    let mut scene = Scene::new();
    scene.push(SceneObject::new(
        frame.clone(),
        normals,
        cloth.triangles.clone(),
    ))?;
    let (p, t) = synth::obstacle_mesh(&params.obstacle, 3);
    scene.push(SceneObject::new(p.clone(), vec![Vec3::Y; p.len()], t).occluder_only())?;
    Ok(Case {
        name: format!(
            "drape-f{}-k{}",
            cloth.frames.len() / 2,
            Lightsphere::new(level)?.len()
        ),
        scene,
        level,
    })
}

/// Write the case's rays and triangles for the peers; return the ray count.
fn export(case: &Case, dir: &Path) -> anyhow::Result<u64> {
    let sphere = Lightsphere::new(case.level)?;
    let caster = RayCaster::new(&case.scene)?;
    let offset = occlusion_gpu::DEFAULT_OFFSET_RELATIVE * caster.diagonal();
    let tris: Vec<f32> = caster
        .triangles()
        .flatten()
        .flat_map(|v| v.to_array())
        .collect();
    let (mut origins, mut dirs) = (Vec::new(), Vec::new());
    for (p, n) in caster.receivers() {
        if n == Vec3::ZERO {
            continue;
        }
        for l in sphere.directions() {
            if n.dot(*l) > 0.0 {
                origins.extend((p + n * offset).to_array());
                dirs.extend(l.to_array());
            }
        }
    }
    let rays = origins.len() / 3;
    let write = |suffix: &str, data: &[f32]| {
        meshio::write_npy_f32(
            &dir.join(format!("{}.{suffix}.npy", case.name)),
            &[data.len() / 3, 3],
            data,
        )
    };
    write("tris", &tris)?;
    write("origins", &origins)?;
    write("dirs", &dirs)?;
    Ok(rays as u64)
}

fn ours(case: &Case, repeats: usize) -> anyhow::Result<Ours> {
    let sphere = Lightsphere::new(case.level)?;
    let params = VisibilityParams::default();
    let (mut full, mut trace) = (Vec::new(), Vec::new());
    let mut result = None;
    for _ in 0..repeats + 1 {
        let mut engine = VisibilityEngine::cpu(params);
        let t = Instant::now();
        let m = engine.compute(&case.scene, &sphere)?;
        full.push(t.elapsed().as_secs_f64() * 1e3);
        // The same engine again: the BVH is reused, only the rays are traced.
        let t = Instant::now();
        let again = engine.compute(&case.scene, &sphere)?;
        trace.push(t.elapsed().as_secs_f64() * 1e3);
        if again.bits() != m.bits() {
            bail!("{}: the reused BVH changed M", case.name);
        }
        result = Some((engine.last_ray_count(), m.visible_count() as u64));
    }
    let (rays, visible) = result.expect("at least one run");
    // The first run warms caches and the thread pool: left out.
    Ok(Ours {
        rays,
        occluded: rays - visible,
        full_ms: median(full[1..].to_vec()),
        trace_ms: median(trace[1..].to_vec()),
    })
}

/// Run the benchmark.
pub fn run(root: &Path, out: &Path, quick: bool, threads: usize) -> anyhow::Result<()> {
    let dir = root.join("target/bench-visibility");
    std::fs::create_dir_all(&dir)?;
    let python = crate::python::venv(
        root,
        "mitsuba-venv",
        &[
            ("mitsuba", "mitsuba==3.*"),
            ("open3d", "open3d"),
            ("numpy", "numpy"),
        ],
    )?;
    let mut cases = Vec::new();
    if quick {
        for level in [2, 3] {
            cases.push(mesh_case("bunny", "meshes/bun_zipper.ply", level)?);
        }
    } else {
        for level in 0..=4 {
            cases.push(mesh_case("bunny", "meshes/bun_zipper.ply", level)?);
        }
        cases.push(mesh_case("dragon", "meshes/dragon_vrip_res2.ply", 3)?);
        cases.push(mesh_case("igea", "meshes/igea.ply", 3)?);
        cases.push(drape_case(2)?);
        cases.push(drape_case(3)?);
    }
    let repeats = if quick { 3 } else { 5 };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    let mut rows = Vec::new();
    for case in &cases {
        let exported = export(case, &dir)?;
        let o = pool.install(|| ours(case, repeats))?;
        if o.rays != exported {
            bail!(
                "{}: the engine cast {} rays, the export holds {exported}",
                case.name,
                o.rays
            );
        }
        println!(
            "{}: {} rays, ours {:.1} ms (trace {:.1} ms)",
            case.name, o.rays, o.full_ms, o.trace_ms
        );
        rows.push(o);
    }
    let output = Command::new(&python)
        .arg(root.join("xtask/scripts/visibility_peers.py"))
        .arg(&dir)
        .arg(threads.to_string())
        .arg(repeats.to_string())
        .args(cases.iter().map(|c| c.name.as_str()))
        .env("DRJIT_LIBLLVM_PATH", llvm_path().unwrap_or_default())
        .output()
        .context("cannot start the peers' script")?;
    if !output.status.success() {
        bail!(
            "the peers' script failed: {}",
            String::from_utf8_lossy(&output.stderr)
        );
    }
    let peers: Vec<serde_json::Value> = String::from_utf8_lossy(&output.stdout)
        .lines()
        .filter_map(|l| serde_json::from_str(l).ok())
        .collect();
    let mut md = String::new();
    writeln!(
        md,
        "# Visibility: occlusion-gpu's `cpu` backend beside Mitsuba 3 and Open3D\n"
    )?;
    writeln!(
        md,
        "Same rays (every receiver vertex towards every lightsphere direction with n·l > 0, origins \
         pushed 1e-4 × the diagonal along the normal), same triangles, {threads} threads, medians of \
         {repeats} runs. Ours: a fresh engine (BVH build + trace) and the trace alone (BVH reused). \
         Peers: scene build and trace. Ratio = our time ÷ the peer's (below 1: faster).\n"
    )?;
    writeln!(
        md,
        "| case | rays | ours build+trace ms | ours trace ms | Mitsuba 3 build / trace ms | Open3D build / trace ms | ours ÷ Mitsuba (total, trace) | ours ÷ Open3D (total, trace) | occluded: ours / Mitsuba / Open3D |"
    )?;
    writeln!(md, "|---|---|---|---|---|---|---|---|---|")?;
    for (case, o) in cases.iter().zip(&rows) {
        let peer = |name: &str| {
            peers
                .iter()
                .find(|p| p["case"] == case.name.as_str() && p["peer"] == name)
        };
        let cell = |name: &str| match peer(name) {
            Some(p) if p.get("error").is_none() => {
                let (b, t) = (
                    p["build_s"].as_f64().unwrap_or(f64::NAN) * 1e3,
                    p["trace_s"].as_f64().unwrap_or(f64::NAN) * 1e3,
                );
                (
                    format!("{b:.1} / {t:.1}"),
                    format!("{:.2}, {:.2}", o.full_ms / (b + t), o.trace_ms / t),
                    p["occluded"].to_string(),
                )
            }
            Some(p) => (
                "—".into(),
                format!("({})", p["error"].as_str().unwrap_or("error")),
                "—".into(),
            ),
            None => ("—".into(), "—".into(), "—".into()),
        };
        let (mi_t, mi_r, mi_o) = cell("mitsuba3");
        let (o3_t, o3_r, o3_o) = cell("open3d");
        writeln!(
            md,
            "| {} | {} | {:.1} | {:.1} | {mi_t} | {o3_t} | {mi_r} | {o3_r} | {} / {mi_o} / {o3_o} |",
            case.name, o.rays, o.full_ms, o.trace_ms, o.occluded
        )?;
    }
    atomic_out::write_bytes(&out.join("bench-visibility.md"), md.as_bytes())?;
    print!("{md}");
    Ok(())
}

/// Dr.Jit's LLVM backend needs libLLVM; Mesa's lavapipe installs one.
fn llvm_path() -> Option<String> {
    let dir = Path::new("/usr/lib/x86_64-linux-gnu");
    let mut found: Vec<_> = std::fs::read_dir(dir)
        .ok()?
        .flatten()
        .map(|e| e.path())
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with("libLLVM"))
        })
        .collect();
    found.sort();
    found.pop().map(|p| p.display().to_string())
}
