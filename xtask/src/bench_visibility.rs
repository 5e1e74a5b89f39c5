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
//! dependencies), served one build and trace per request so that each round runs ours and then
//! each peer within seconds. Ours: a fresh engine per run (BVH build + trace, as a deforming
//! frame pays) and, on the same engine, the trace alone (the BVH reused). Peers: a fresh scene
//! build and a trace per round (measured once per case before, which left Open3D's lazy build
//! anywhere from 5 to 374 ms within one run). Times are medians over the rounds, and each ratio
//! is the median of the rounds' own ratios: this machine's speed drifts by up to a quarter
//! within minutes (the bunny's trace at k = 258 took 0.25–0.37 s in one session, the code
//! unchanged), and before the rounds alternated our runs and the peers' came minutes apart (the
//! ratio moved from 0.72 to 0.83 between two days). The occluded-ray counts are compared as a
//! cross-check. Writes `target/repro/bench-visibility.md`. Open3D's wheel needs `libusb-1.0-0`
//! (Debian); a peer that cannot be imported is reported in its column, not fatal.

use std::fmt::Write as _;
use std::io::{BufRead, BufReader, Write as _};
use std::path::Path;
use std::process::{Child, ChildStdin, ChildStdout, Command, Stdio};
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

/// One of our runs: a fresh engine (BVH build + trace), then the same engine again (the BVH
/// reused, the trace alone).
struct OurRun {
    rays: u64,
    occluded: u64,
    full_ms: f64,
    trace_ms: f64,
}

/// What one peer measured on one case: a fresh build and a trace per round, and the round's
/// total (build + trace, or as the peer timed it in one piece: Open3D's creation and first
/// query).
#[derive(Default)]
struct PeerRuns {
    build_ms: Vec<f64>,
    trace_ms: Vec<f64>,
    total_ms: Vec<f64>,
    occluded: u64,
    error: Option<String>,
}

/// The peers' script (`xtask/scripts/visibility_peers.py`), serving one build and trace per
/// request.
struct PeerServer {
    child: Child,
    stdin: ChildStdin,
    stdout: BufReader<ChildStdout>,
}

impl PeerServer {
    fn start(python: &Path, root: &Path, dir: &Path, threads: usize) -> anyhow::Result<Self> {
        let mut child = Command::new(python)
            .arg(root.join("xtask/scripts/visibility_peers.py"))
            .arg(dir)
            .arg(threads.to_string())
            .env("DRJIT_LIBLLVM_PATH", llvm_path().unwrap_or_default())
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .context("cannot start the peers' script")?;
        let stdin = child
            .stdin
            .take()
            .context("the peers' script has no stdin")?;
        let stdout = BufReader::new(
            child
                .stdout
                .take()
                .context("the peers' script has no stdout")?,
        );
        Ok(Self {
            child,
            stdin,
            stdout,
        })
    }

    /// One round of `peer` on `case`: a fresh build and a trace.
    fn ask(&mut self, case: &str, peer: &str) -> anyhow::Result<serde_json::Value> {
        writeln!(self.stdin, "{case} {peer}").context("the peers' script stopped reading")?;
        self.stdin.flush()?;
        let mut line = String::new();
        if self.stdout.read_line(&mut line)? == 0 {
            bail!("the peers' script exited while tracing {case} with {peer}");
        }
        serde_json::from_str(&line)
            .with_context(|| format!("the peers' script answered {line:?} for {case} / {peer}"))
    }

    /// Records one round of `peer` on `case` in `runs`.
    fn round(&mut self, case: &str, peer: &str, runs: &mut PeerRuns) -> anyhow::Result<()> {
        if runs.error.is_some() {
            return Ok(());
        }
        let reply = self.ask(case, peer)?;
        if let Some(e) = reply.get("error") {
            runs.error = Some(e.as_str().unwrap_or("error").to_owned());
            return Ok(());
        }
        let seconds = |key: &str| {
            reply[key]
                .as_f64()
                .with_context(|| format!("no {key} in the peer's answer {reply}"))
        };
        let (build, trace) = (seconds("build_s")? * 1e3, seconds("trace_s")? * 1e3);
        let total = reply["total_s"].as_f64().map_or(build + trace, |t| t * 1e3);
        runs.build_ms.push(build);
        runs.trace_ms.push(trace);
        runs.total_ms.push(total);
        runs.occluded = reply["occluded"].as_u64().unwrap_or(0);
        Ok(())
    }
}

impl Drop for PeerServer {
    fn drop(&mut self) {
        // Closing stdin ends the script's loop; a script stuck elsewhere is killed.
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
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

fn our_run(case: &Case) -> anyhow::Result<OurRun> {
    let sphere = Lightsphere::new(case.level)?;
    let mut engine = VisibilityEngine::cpu(VisibilityParams::default());
    let t = Instant::now();
    let m = engine.compute(&case.scene, &sphere)?;
    let full_ms = t.elapsed().as_secs_f64() * 1e3;
    // The same engine again: the BVH is reused, only the rays are traced.
    let t = Instant::now();
    let again = engine.compute(&case.scene, &sphere)?;
    let trace_ms = t.elapsed().as_secs_f64() * 1e3;
    if again.bits() != m.bits() {
        bail!("{}: the reused BVH changed M", case.name);
    }
    let rays = engine.last_ray_count();
    Ok(OurRun {
        rays,
        occluded: rays - m.visible_count() as u64,
        full_ms,
        trace_ms,
    })
}

/// The median of our time ÷ the peer's over the rounds (both measured within seconds of
/// each other): (build + trace, trace alone).
fn ratios(ours: &[OurRun], peer: &PeerRuns) -> (f64, f64) {
    let total = ours
        .iter()
        .zip(&peer.total_ms)
        .map(|(o, t)| o.full_ms / t)
        .collect();
    let trace = ours
        .iter()
        .zip(&peer.trace_ms)
        .map(|(o, t)| o.trace_ms / t)
        .collect();
    (median(total), median(trace))
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
    let mut server = PeerServer::start(&python, root, &dir, threads)?;
    let peer_names = ["mitsuba3", "open3d"];
    let mut rows = Vec::new();
    for case in &cases {
        let exported = export(case, &dir)?;
        let (mut ours, mut peers) = (Vec::new(), peer_names.map(|_| PeerRuns::default()));
        // Round 0 warms caches, the thread pool and the peers' kernels: left out.
        for round in 0..=repeats {
            let o = pool.install(|| our_run(case))?;
            if o.rays != exported {
                bail!(
                    "{}: the engine cast {} rays, the export holds {exported}",
                    case.name,
                    o.rays
                );
            }
            for (name, runs) in peer_names.iter().zip(&mut peers) {
                server.round(&case.name, name, runs)?;
                if round == 0 {
                    runs.build_ms.clear();
                    runs.trace_ms.clear();
                    runs.total_ms.clear();
                }
            }
            if round > 0 {
                ours.push(o);
            }
        }
        let (full, trace) = (
            median(ours.iter().map(|o| o.full_ms).collect()),
            median(ours.iter().map(|o| o.trace_ms).collect()),
        );
        println!(
            "{}: {} rays, ours {full:.1} ms (trace {trace:.1} ms)",
            case.name, ours[0].rays
        );
        rows.push((ours, peers, full, trace));
    }
    drop(server);
    let mut md = String::new();
    writeln!(
        md,
        "# Visibility: occlusion-gpu's `cpu` backend beside Mitsuba 3 and Open3D\n"
    )?;
    writeln!(
        md,
        "Same rays (every receiver vertex towards every lightsphere direction with n·l > 0, origins \
         pushed 1e-4 × the diagonal along the normal), same triangles, {threads} threads, {repeats} \
         rounds after a warm-up round, each round one run of ours and then one build and trace of each peer, \
         seconds apart. Ours: a fresh engine (BVH build + trace) and the trace alone (BVH reused). \
         Peers: a fresh scene build and a trace per round. Times are medians over the rounds; a ratio is our \
         time ÷ the peer's in each round, its median over the rounds (below 1: faster).\n"
    )?;
    writeln!(
        md,
        "| case | rays | ours build+trace ms | ours trace ms | Mitsuba 3 build / trace ms | Open3D build / trace ms | ours ÷ Mitsuba (total, trace) | ours ÷ Open3D (total, trace) | occluded: ours / Mitsuba / Open3D |"
    )?;
    writeln!(md, "|---|---|---|---|---|---|---|---|---|")?;
    for (case, (ours, peers, full, trace)) in cases.iter().zip(&rows) {
        let cell = |runs: &PeerRuns| match &runs.error {
            None if !runs.trace_ms.is_empty() => {
                let (total, traced) = ratios(ours, runs);
                (
                    format!(
                        "{:.1} / {:.1}",
                        median(runs.build_ms.clone()),
                        median(runs.trace_ms.clone())
                    ),
                    format!("{total:.2}, {traced:.2}"),
                    runs.occluded.to_string(),
                )
            }
            Some(e) => ("—".into(), format!("({e})"), "—".into()),
            None => ("—".into(), "—".into(), "—".into()),
        };
        let (mi_t, mi_r, mi_o) = cell(&peers[0]);
        let (o3_t, o3_r, o3_o) = cell(&peers[1]);
        writeln!(
            md,
            "| {} | {} | {full:.1} | {trace:.1} | {mi_t} | {o3_t} | {mi_r} | {o3_r} | {} / {mi_o} / {o3_o} |",
            case.name, ours[0].rays, ours[0].occluded
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
