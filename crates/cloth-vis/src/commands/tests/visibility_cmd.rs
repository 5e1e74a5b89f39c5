//! `cloth-vis visibility` end to end on the cpu backend (no GPU needed): array shapes, NaN for
//! vertices used by no face, a PLY that our own loader reads back, and refusals before work.

use super::common::{cli_env, text};
use crate::commands::visibility::{VisibilityRequest, run_visibility};
use cloth_vis::Error;

/// A 5×5 grid facing +y, plus one vertex used by no face (index 25).
fn grid_obj(dir: &std::path::Path) -> std::path::PathBuf {
    let mut text = String::new();
    for i in 0..5 {
        for j in 0..5 {
            text.push_str(&format!("v {} 0 {}\n", i as f32 * 0.25, j as f32 * 0.25));
        }
    }
    text.push_str("v 9 9 9\n");
    for i in 0..4 {
        for j in 0..4 {
            let a = i * 5 + j + 1;
            text.push_str(&format!(
                "f {} {} {}\nf {} {} {}\n",
                a,
                a + 1,
                a + 6,
                a,
                a + 6,
                a + 5
            ));
        }
    }
    let path = dir.join("grid.obj");
    std::fs::write(&path, text).unwrap();
    path
}

fn request(input: std::path::PathBuf, out: Option<std::path::PathBuf>) -> VisibilityRequest {
    VisibilityRequest {
        level: 2,
        backend: Some(occlusion_gpu::Backend::Cpu),
        depth_resolution: 256,
        out,
        ..VisibilityRequest::new(input)
    }
}

#[test]
fn ambient_npy_keeps_vertex_order_with_nan_for_unused_vertices() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("a.npy");
    let summary = run_visibility(&request(grid_obj(dir.path()), Some(out.clone())), None).unwrap();
    assert_eq!(
        (
            summary.directions,
            summary.vertices,
            summary.unused,
            summary.frames
        ),
        (66, 26, 1, 1)
    );
    let line = summary.line();
    assert!(
        line.starts_with("visibility: 66 directions x 26 vertices in ")
            && line.ends_with("; 1 vertex without a normal (used by no triangle, or neither their triangles nor their neighbours give a direction): a_i = NaN (-1 in .glb)"),
        "{line}"
    );
    let array = meshio::read_npy_f32(&out).unwrap();
    assert_eq!(array.shape, vec![26]);
    // An open plane: every used vertex sees its whole upper hemisphere (a = Σ ω max(0, n·l)/π ≈ 1).
    for a in &array.data[..25] {
        assert!((a - 1.0).abs() < 0.05, "{a}");
    }
    assert!(array.data[25].is_nan());

    let mut with_matrix = request(grid_obj(dir.path()), Some(dir.path().join("m.npy")));
    with_matrix.matrix = true;
    run_visibility(&with_matrix, None).unwrap();
    let m = meshio::read_npy_f32(&dir.path().join("m.npy")).unwrap();
    assert_eq!(m.shape, vec![26, 66]);
    // Row sums weighted by ω reproduce a_i: check the first vertex.
    let sphere = lightsphere::Lightsphere::new(2).unwrap();
    let a0: f64 = m.data[..66]
        .iter()
        .zip(sphere.solid_angles())
        .map(|(v, w)| f64::from(*v) * w)
        .sum::<f64>()
        / std::f64::consts::PI;
    assert!((a0 as f32 - array.data[0]).abs() < 1e-5);
    // The sidecars carry l_j and ω_j: a_i from them alone, ω summing to 4π.
    let dirs = meshio::read_npy_f32(&dir.path().join("m.directions.npy")).unwrap();
    let w = meshio::read_npy_f32(&dir.path().join("m.weights.npy")).unwrap();
    assert_eq!(
        (dirs.shape.clone(), w.shape.clone()),
        (vec![66, 3], vec![66])
    );
    assert_eq!(dirs.data[..3], sphere.directions()[0].to_array());
    let total: f64 = w.data.iter().map(|v| f64::from(*v)).sum();
    assert!((total - 4.0 * std::f64::consts::PI).abs() < 1e-5, "{total}");
    let a0: f32 = m.data[..66]
        .iter()
        .zip(&w.data)
        .map(|(v, w)| v * w)
        .sum::<f32>()
        / std::f32::consts::PI;
    assert!((a0 - array.data[0]).abs() < 1e-5);
}

#[test]
fn ply_output_reads_back_with_the_same_counts() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("ao.ply");
    run_visibility(&request(grid_obj(dir.path()), Some(out.clone())), None).unwrap();
    let (mesh, report) = meshio::load_mesh(&out, &meshio::LoadOptions::default()).unwrap();
    assert_eq!((mesh.vertex_count(), mesh.triangle_count()), (26, 32));
    assert_eq!(report.unreferenced_vertices, vec![25]);
}

#[test]
fn bad_requests_are_refused_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let input = grid_obj(dir.path());
    let txt = dir.path().join("out.txt");
    let err = run_visibility(&request(input.clone(), Some(txt.clone())), None).unwrap_err();
    assert!(
        matches!(err, Error::Request { .. }) && err.to_string().contains("out.txt"),
        "{err}"
    );
    assert!(!txt.exists());
    let mut frames = request(input.clone(), None);
    frames.frames = Some((0, 2));
    let err = run_visibility(&frames, None).unwrap_err().to_string();
    assert!(err.contains("0..2") && err.contains("1 frames"), "{err}");
    let mut depth = request(input, None);
    depth.backend = Some(occlusion_gpu::Backend::Depth);
    let err = run_visibility(&depth, None).unwrap_err().to_string();
    assert!(err.contains("--backend cpu"), "{err}");
}

#[test]
fn an_output_that_is_the_input_is_refused_however_it_is_spelled() {
    // Issue #12: `visibility bunny.ply --out bunny.ply` silently overwrote the mesh.
    let dir = tempfile::tempdir().unwrap();
    let input = grid_obj(dir.path());
    let before = std::fs::read(&input).unwrap();
    std::fs::create_dir(dir.path().join("sub")).unwrap();
    let dotted = dir
        .path()
        .join("sub")
        .join("..")
        .join(input.file_name().unwrap());
    for out in [input.clone(), dotted] {
        let mut request = request(input.clone(), None);
        request.render = Some(out.with_extension("png"));
        request.out = Some(out.clone());
        let err = run_visibility(&request, None).unwrap_err().to_string();
        assert!(err.contains("is the input"), "{err}");
    }
    assert_eq!(
        std::fs::read(&input).unwrap(),
        before,
        "the input is untouched"
    );
}

#[test]
fn a_machine_without_vulkan_gets_an_error_not_a_panic() {
    // Issue #12, C7: with the Vulkan loader pointed at nothing, wgpu fell back to Mesa's GL
    // driver, which cannot run our shaders, and every GPU command panicked inside wgpu;
    // `--backend cpu --render` wrote its .npy first. Now the adapter chooser refuses adapters
    // that lack what the paths need (or finds none, where GL is absent too), exit code 1.
    let dir = tempfile::tempdir().unwrap();
    let input = grid_obj(dir.path());
    let npy = dir.path().join("a.npy");
    let png = dir.path().join("a.png");
    let no_vulkan = [
        ("VK_ICD_FILENAMES", "/nonexistent.json"),
        ("VK_DRIVER_FILES", "/nonexistent.json"),
        ("CLOTH_VIS_BACKEND", ""),
        ("WGPU_BACKEND", ""),
    ];
    let runs: [&[&str]; 2] = [
        &[
            "visibility",
            text(&input),
            "--backend",
            "depth",
            "--level",
            "1",
            "--out",
            text(&npy),
        ],
        &[
            "visibility",
            text(&input),
            "--backend",
            "cpu",
            "--level",
            "1",
            "--out",
            text(&npy),
            "--render",
            text(&png),
        ],
    ];
    for args in runs {
        let out = cli_env(args, &no_vulkan);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
        assert!(
            stderr.contains("apt-get install mesa-vulkan-drivers"),
            "the message says what to install: {stderr}"
        );
        assert!(!npy.exists() && !png.exists(), "nothing is written");
    }
}

/// Issue #18: point caches (`.pc2`, `.mdd`, `.npy`) are visibility inputs once `--topology`
/// gives their triangles; a_i per frame equals that of the same frames as an OBJ folder, bit
/// for bit. Without a topology the refusal names the flag.
#[test]
fn point_caches_with_a_topology_mesh_match_the_obj_folder() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = grid_obj(dir.path());
    let (rest, _) = meshio::load_mesh(&mesh, &meshio::LoadOptions::default()).unwrap();
    // Three frames: the grid folding up about its middle row.
    let frames: Vec<Vec<glam::Vec3>> = (0..3)
        .map(|f| {
            rest.positions
                .iter()
                .map(|p| {
                    let lift = if p.x > 0.6 {
                        (p.x - 0.5) * 0.4 * f as f32
                    } else {
                        0.0
                    };
                    *p + glam::Vec3::Y * lift
                })
                .collect()
        })
        .collect();
    let folder = dir.path().join("frames");
    std::fs::create_dir(&folder).unwrap();
    let faces: String = std::fs::read_to_string(&mesh)
        .unwrap()
        .lines()
        .filter(|l| l.starts_with("f "))
        .map(|l| format!("{l}\n"))
        .collect();
    for (f, frame) in frames.iter().enumerate() {
        let mut text: String = frame
            .iter()
            .map(|p| format!("v {} {} {}\n", p.x, p.y, p.z))
            .collect();
        text.push_str(&faces);
        std::fs::write(folder.join(format!("{}.obj", f + 1)), text).unwrap();
    }
    // The caches hold the positions the OBJ text round-trips to.
    let (obj_clip, _) =
        meshio::load_animation(&folder, &meshio::AnimationOptions::default()).unwrap();
    let pc2 = dir.path().join("clip.pc2");
    let mdd = dir.path().join("clip.mdd");
    meshio::write_pc2(&pc2, &obj_clip.frames, 0.0, 1.0).unwrap();
    meshio::write_mdd(&mdd, &obj_clip.frames, 30.0).unwrap();
    let run = |input: &std::path::Path, topology: Option<&std::path::Path>, name: &str| {
        let out = dir.path().join(name);
        let mut r = request(input.to_owned(), Some(out.clone()));
        r.topology = topology.map(std::path::Path::to_owned);
        run_visibility(&r, None).map(|_| meshio::read_npy_f32(&out).unwrap())
    };
    let reference = run(&folder, None, "obj.npy").unwrap();
    assert_eq!(reference.shape, vec![3, 26]);
    for (cache, name) in [(&pc2, "pc2.npy"), (&mdd, "mdd.npy")] {
        let got = run(cache, Some(&mesh), name).unwrap();
        assert_eq!(got.shape, reference.shape);
        let same = got
            .data
            .iter()
            .zip(&reference.data)
            .all(|(a, b)| a.to_bits() == b.to_bits());
        assert!(same, "{}", cache.display());
    }
    let message = run(&pc2, None, "none.npy").unwrap_err().to_string();
    assert!(message.contains("--topology"), "{message}");
}

#[test]
fn a_matrix_above_8_gb_is_refused_before_the_first_ray() {
    // 182² = 33,124 vertices × 65,538 directions (level 7) × 4 bytes = 8.7 GB > 8 GiB.
    let dir = tempfile::tempdir().unwrap();
    let side = 182;
    let mut text = String::new();
    for i in 0..side {
        for j in 0..side {
            text.push_str(&format!("v {i} 0 {j}\n"));
        }
    }
    for i in 0..side - 1 {
        for j in 0..side - 1 {
            let a = i * side + j + 1;
            text.push_str(&format!("f {a} {} {}\n", a + 1, a + side + 1));
        }
    }
    let input = dir.path().join("big.obj");
    std::fs::write(&input, text).unwrap();
    let out = dir.path().join("m.npy");
    let big = VisibilityRequest {
        level: 7,
        matrix: true,
        ..request(input, Some(out.clone()))
    };
    let message = run_visibility(&big, None).unwrap_err().to_string();
    assert!(
        message.contains("m.npy") && message.contains("8.7 GB") && message.contains("--force"),
        "{message}"
    );
    assert!(!out.exists());
}
