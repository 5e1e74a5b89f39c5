//! The output side of `cloth-vis visibility`: `.glb` with `COLOR_0` and `_AO`, environment
//! rotation by rotated look-ups, and `--render` PNG/EXR. The rendering tests need a GPU adapter
//! (lavapipe is fine) and skip through `test_data::skip` without one.

use std::path::{Path, PathBuf};

use crate::commands::visibility::{GLB_UNUSED_AO, VisibilityRequest, run_visibility};
use cloth_vis::camera::resolve;
use cloth_vis::lighting::{
    environment_rotation as env_rotation, rotated_lookup_radiance as light_radiance,
    shadowed_radiance as vertex_radiance,
};
use cloth_vis::scene::CameraDesc;
use glam::Vec3;
use gpu_context::{GpuContext, GpuOptions};
use lightsphere::{Environment, Lightsphere, RadianceMethod};
use render::bounding_sphere;

/// An L-shaped fold: a floor (y = 0, facing +y) and a wall (x = 0, facing +x), 5×5 vertices
/// each, sharing no vertex, so that a_i ranges from ~0.5 near the fold to ~1 far from it; plus
/// one vertex used by no face (the last).
fn fold_obj(dir: &Path) -> PathBuf {
    let mut text = String::new();
    for i in 0..5 {
        for j in 0..5 {
            let (u, v) = (i as f32 * 0.25, j as f32 * 0.25);
            text.push_str(&format!("v {} 0 {}\n", u + 0.02, v));
        }
    }
    for i in 0..5 {
        for j in 0..5 {
            let (u, v) = (i as f32 * 0.25, j as f32 * 0.25);
            text.push_str(&format!("v 0 {} {}\n", u + 0.02, v));
        }
    }
    text.push_str("v 9 9 9\n");
    for (base, flip) in [(0, false), (25, true)] {
        for i in 0..4 {
            for j in 0..4 {
                let a = base + i * 5 + j + 1;
                let (t1, t2) = if flip {
                    ([a, a + 5, a + 6], [a, a + 6, a + 1])
                } else {
                    ([a, a + 1, a + 6], [a, a + 6, a + 5])
                };
                text.push_str(&format!(
                    "f {} {} {}\nf {} {} {}\n",
                    t1[0], t1[1], t1[2], t2[0], t2[1], t2[2]
                ));
            }
        }
    }
    let path = dir.join("fold.obj");
    std::fs::write(&path, text).unwrap();
    path
}

const VERTICES: usize = 51;
const UNUSED: usize = 50;

fn request(input: PathBuf) -> VisibilityRequest {
    VisibilityRequest {
        level: 2,
        backend: Some(occlusion_gpu::Backend::Cpu),
        ..VisibilityRequest::new(input)
    }
}

/// A small procedural sky (width divisible by 4, so quarter turns map texels onto texels).
fn sky() -> Environment {
    let s = synth::sky(&synth::SkyParams {
        width: 256,
        height: 128,
        sun_to_sky_ratio: 50.0,
        sun_angular_radius_deg: 4.0,
        ..synth::SkyParams::default()
    })
    .unwrap();
    Environment::from_latlong(s.width, s.height, s.texels).unwrap()
}

/// The attributes of a GLB's first primitive: `name → (accessor type, f32 values)`, read
/// straight from the container (cloth-vis does not depend on the `gltf` crate).
fn glb_attribute(path: &Path, name: &str) -> Vec<f32> {
    let bytes = std::fs::read(path).unwrap();
    let word = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
    let json_len = word(12);
    let root: serde_json::Value = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
    let bin = &bytes[20 + json_len + 8..];
    let accessor = &root["accessors"][root["meshes"][0]["primitives"][0]["attributes"][name]
        .as_u64()
        .unwrap() as usize];
    assert_eq!(accessor["componentType"], 5126, "{name} is float");
    let view = &root["bufferViews"][accessor["bufferView"].as_u64().unwrap() as usize];
    let offset = view["byteOffset"].as_u64().unwrap() as usize;
    let len = view["byteLength"].as_u64().unwrap() as usize;
    bin[offset..offset + len]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
        .collect()
}

#[test]
fn glb_holds_the_mesh_colour_and_the_ambient_term_of_the_npy() {
    let dir = tempfile::tempdir().unwrap();
    let input = fold_obj(dir.path());
    let npy = dir.path().join("a.npy");
    let glb = dir.path().join("a.glb");
    run_visibility(
        &VisibilityRequest {
            out: Some(npy.clone()),
            ..request(input.clone())
        },
        None,
    )
    .unwrap();
    run_visibility(
        &VisibilityRequest {
            out: Some(glb.clone()),
            ..request(input.clone())
        },
        None,
    )
    .unwrap();

    let (original, _) = meshio::load_mesh(&input, &meshio::LoadOptions::default()).unwrap();
    let (loaded, report) = meshio::load_mesh(&glb, &meshio::LoadOptions::default()).unwrap();
    assert_eq!(loaded.positions, original.positions);
    assert_eq!(loaded.triangles, original.triangles);
    assert_eq!(report.unreferenced_vertices, vec![UNUSED as u32]);

    let ambient = meshio::read_npy_f32(&npy).unwrap().data;
    let ao = glb_attribute(&glb, "_AO");
    assert_eq!(ao.len(), VERTICES);
    for (i, (a, g)) in ambient.iter().zip(&ao).enumerate() {
        if i == UNUSED {
            assert!(a.is_nan());
            assert_eq!(*g, GLB_UNUSED_AO);
        } else {
            assert_eq!(a, g, "vertex {i}");
        }
    }
    // The fold occludes: a_i really varies, so the comparison above is not vacuous.
    let used = &ambient[..UNUSED];
    let lo = used.iter().copied().fold(f32::INFINITY, f32::min);
    let hi = used.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    assert!(lo < 0.75 && hi > 0.9, "a_i in [{lo}, {hi}]");

    // Without an environment COLOR_0 is the grey a_i, linear, scaled so that the 90th
    // percentile is 0.8: proportional to a_i where it is not clamped.
    let colour = glb_attribute(&glb, "COLOR_0");
    let scale = colour[0] / ambient[0];
    for i in 0..UNUSED {
        let c = &colour[3 * i..3 * i + 3];
        assert!(c[0] == c[1] && c[1] == c[2], "grey");
        let expected = (ambient[i] * scale).min(1.0);
        assert!(
            (c[0] - expected).abs() < 1e-5,
            "vertex {i}: {} vs {expected}",
            c[0]
        );
    }
    assert_eq!(&colour[3 * UNUSED..], &[0.0; 3]);
}

#[test]
fn multi_frame_glb_and_bad_render_requests_are_refused_before_work() {
    let dir = tempfile::tempdir().unwrap();
    let input = fold_obj(dir.path());
    let err = run_visibility(
        &VisibilityRequest {
            out: Some(dir.path().join("m.glb")),
            matrix: true,
            ..request(input.clone())
        },
        None,
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("--matrix") && err.contains("m.glb"), "{err}");
    let err = run_visibility(
        &VisibilityRequest {
            render: Some(dir.path().join("r.jpg")),
            ..request(input.clone())
        },
        None,
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("--render") && err.contains(".exr"), "{err}");
    let err = run_visibility(
        &VisibilityRequest {
            render: Some(dir.path().join("r.png")),
            ..request(input.clone())
        },
        None,
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.contains("--render needs a GPU adapter") && err.contains("r.png"),
        "{err}"
    );
    let err = run_visibility(
        &VisibilityRequest {
            env_rotation_deg: 45.0,
            ..request(input)
        },
        None,
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.contains("--env-rotation") && err.contains("--sky"),
        "{err}"
    );
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        1,
        "only the input"
    );
}

/// For each direction j the index π(j) with l_π(j) = R⁻¹·l_j, checked to f64 rounding.
fn quarter_turn_permutation(sphere: &Lightsphere, deg: f32) -> Vec<usize> {
    let lookup = sphere.rotated(env_rotation(deg).inverse());
    let mut seen = vec![false; sphere.len()];
    lookup
        .directions_f64()
        .iter()
        .map(|&d| {
            let j = sphere.nearest_f64(d);
            let error = (d - sphere.directions_f64()[j]).length();
            assert!(error < 1e-12, "{deg}°: look-up {d} is {error} from l_{j}");
            assert!(!seen[j], "{deg}°: l_{j} hit twice");
            seen[j] = true;
            j
        })
        .collect()
}

#[test]
fn quarter_turns_about_y_permute_the_octahedral_directions() {
    let env = sky();
    for level in [1, 3] {
        let sphere = Lightsphere::new(level).unwrap();
        let unrotated = light_radiance(&env, &sphere, 0.0).unwrap();
        for deg in [90.0, 180.0, 270.0, -90.0, 450.0] {
            let permutation = quarter_turn_permutation(&sphere, deg);
            if deg == 180.0 {
                // Not the identity: the test would pass vacuously otherwise.
                assert!(permutation.iter().enumerate().any(|(j, p)| j != *p));
            }
            let rotated = light_radiance(&env, &sphere, deg).unwrap();
            for (j, p) in permutation.iter().enumerate() {
                let (a, b) = (rotated[j], unrotated[*p]);
                // The same texel sub-samples fall into the same (permuted) cells; only the
                // order of the f64 sums differs.
                assert!(
                    (a - b).abs().max_element() <= 1e-5 * b.abs().max_element().max(1e-3),
                    "level {level}, {deg}°, I_{j} = {a} but I_{p} = {b}"
                );
            }
        }
    }
}

#[test]
fn rotated_lookups_equal_a_rotated_environment() {
    let env = sky();
    let sphere = Lightsphere::new(3).unwrap();
    let deg = 37.0;
    let lookups = light_radiance(&env, &sphere, deg).unwrap();
    let rotated_env = env.clone().with_rotation(env_rotation(deg));
    let reference = rotated_env
        .radiance_per_direction(&sphere, RadianceMethod::CellMean)
        .unwrap();
    let unrotated = light_radiance(&env, &sphere, 0.0).unwrap();
    let power = sphere.power(&reference).unwrap()[1];
    let mut moved = 0.0f64;
    for (j, ((a, b), u)) in lookups.iter().zip(&reference).zip(&unrotated).enumerate() {
        let w = sphere.solid_angles()[j];
        // Same cell integrals up to the rounding of the rotated sample directions.
        assert!(
            f64::from((*a - *b).abs().max_element()) * w <= 1e-6 * power,
            "I_{j}: {a} vs {b}"
        );
        moved += f64::from((*u - *b).abs().y) * w;
    }
    assert!(moved > 0.05 * power, "the rotation must change I");

    // And the vertex radiance c_i built from it (M reused) matches too.
    let (mesh, _) = meshio::load_mesh(
        &fold_obj(tempfile::tempdir().unwrap().path()),
        &meshio::LoadOptions::default(),
    )
    .unwrap();
    let scene = occlusion_gpu::Scene::single(mesh.positions, mesh.normals, mesh.triangles).unwrap();
    let m = occlusion_gpu::VisibilityEngine::cpu(Default::default())
        .compute(&scene, &sphere)
        .unwrap();
    let c = vertex_radiance(&m, &sphere, &lookups).unwrap();
    let c_ref = vertex_radiance(&m, &sphere, &reference).unwrap();
    for i in 0..UNUSED {
        assert!(
            (c[i] - c_ref[i]).abs().max_element() <= 1e-5 * c_ref[i].max_element(),
            "c_{i}: {} vs {}",
            c[i],
            c_ref[i]
        );
    }
    assert!(c[UNUSED].is_nan());
}

/// A GPU context, or `None` after the project's skip policy (fails under CI). Lavapipe wants
/// `XDG_RUNTIME_DIR` set (e.g. `/tmp`) in the test's environment.
fn gpu() -> Option<GpuContext> {
    match GpuContext::new(&GpuOptions::default()) {
        Ok(g) => Some(g),
        Err(e) => test_data::skip(&format!("no GPU adapter: {e}")),
    }
}

fn read_exr(path: &Path) -> (usize, usize, Vec<[f32; 4]>) {
    let image = exr::prelude::read_first_rgba_layer_from_file(
        path,
        |resolution, _| {
            (
                resolution.width(),
                vec![[0.0f32; 4]; resolution.width() * resolution.height()],
            )
        },
        |(width, pixels), position, (r, g, b, a): (f32, f32, f32, f32)| {
            pixels[position.y() * *width + position.x()] = [r, g, b, a];
        },
    )
    .unwrap();
    let size = image.layer_data.size;
    (
        size.width(),
        size.height(),
        image.layer_data.channel_data.pixels.1,
    )
}

/// Pixel of a world point seen by the camera `run_visibility` frames for these positions.
fn vertex_pixels(positions: &[Vec3], used: &[usize], size: [u32; 2]) -> Vec<(usize, usize)> {
    let points: Vec<Vec3> = used.iter().map(|&i| positions[i]).collect();
    let (centre, radius) = bounding_sphere(&points).unwrap();
    let desc = CameraDesc {
        width: size[0],
        height: size[1],
        ..CameraDesc::default()
    };
    let camera = resolve(&desc, centre, radius);
    used.iter()
        .map(|&i| {
            let ndc = camera
                .clip_from_world()
                .unwrap()
                .project_point3(positions[i]);
            let x = ((ndc.x + 1.0) * 0.5 * size[0] as f32) as usize;
            let y = ((1.0 - ndc.y) * 0.5 * size[1] as f32) as usize;
            (x, y)
        })
        .collect()
}

/// Interior vertices of the fold (not on the outline, so the pixel around them is covered).
fn interior_vertices() -> Vec<usize> {
    let mut out = Vec::new();
    for base in [0, 25] {
        for i in 1..4 {
            for j in 1..4 {
                out.push(base + i * 5 + j);
            }
        }
    }
    out
}

#[test]
fn exr_holds_the_linear_vertex_radiance_and_rotation_matches_a_rotated_environment() {
    let Some(gpu) = gpu() else { return };
    let dir = tempfile::tempdir().unwrap();
    let input = fold_obj(dir.path());
    let size = [160u32, 120];
    let env = sky();
    let deg = 30.0;
    let exr_rotated = dir.path().join("rotated.exr");
    run_visibility(
        &VisibilityRequest {
            environment: Some(env.clone()),
            env_rotation_deg: deg,
            render: Some(exr_rotated.clone()),
            render_size: size,
            ..request(input.clone())
        },
        Some(&gpu),
    )
    .unwrap();
    let (w, h, pixels) = read_exr(&exr_rotated);
    assert_eq!((w, h), (160, 120));
    assert!(pixels.iter().flatten().all(|v| v.is_finite()));

    // c_i computed independently from the public pieces.
    let (mesh, _) = meshio::load_mesh(&input, &meshio::LoadOptions::default()).unwrap();
    let sphere = Lightsphere::new(2).unwrap();
    let scene = occlusion_gpu::Scene::single(
        mesh.positions.clone(),
        mesh.normals.clone(),
        mesh.triangles.clone(),
    )
    .unwrap();
    let m = occlusion_gpu::VisibilityEngine::cpu(Default::default())
        .compute(&scene, &sphere)
        .unwrap();
    let c = vertex_radiance(&m, &sphere, &light_radiance(&env, &sphere, deg).unwrap()).unwrap();
    let used: Vec<usize> = (0..UNUSED).collect();
    let all = vertex_pixels(&mesh.positions, &used, size);
    let mut worst = 0.0f32;
    for i in interior_vertices() {
        let (x, y) = all[i];
        let p = Vec3::from_slice(&pixels[y * w + x][..3]);
        worst = worst.max(((p - c[i]).abs() / c[i].abs().max(Vec3::splat(1e-6))).max_element());
    }
    // Gouraud interpolation equals c_i at the vertex; the pixel centre is up to ½ px away.
    assert!(
        worst < 0.02,
        "worst relative pixel error at vertices {worst}"
    );

    // The same render with the environment itself rotated: mesh and backdrop agree.
    let exr_reference = dir.path().join("reference.exr");
    run_visibility(
        &VisibilityRequest {
            environment: Some(env.clone().with_rotation(env_rotation(deg))),
            render: Some(exr_reference.clone()),
            render_size: size,
            ..request(input.clone())
        },
        Some(&gpu),
    )
    .unwrap();
    let (_, _, reference) = read_exr(&exr_reference);
    let diff: f64 = pixels
        .iter()
        .zip(&reference)
        .map(|(a, b)| f64::from((a[1] - b[1]).abs()))
        .sum();
    let total: f64 = reference.iter().map(|p| f64::from(p[1].abs())).sum();
    assert!(
        diff <= 1e-4 * total,
        "mean relative difference {}",
        diff / total
    );
    // While an unrotated environment gives a different image (the check is not vacuous).
    let exr_unrotated = dir.path().join("unrotated.exr");
    run_visibility(
        &VisibilityRequest {
            environment: Some(env),
            render: Some(exr_unrotated.clone()),
            render_size: size,
            ..request(input)
        },
        Some(&gpu),
    )
    .unwrap();
    let (_, _, unrotated) = read_exr(&exr_unrotated);
    let diff: f64 = pixels
        .iter()
        .zip(&unrotated)
        .map(|(a, b)| f64::from((a[1] - b[1]).abs()))
        .sum();
    assert!(
        diff > 0.01 * total,
        "rotation changed nothing: {}",
        diff / total
    );
}

#[test]
fn png_has_the_requested_size_and_brightens_with_exposure() {
    let Some(gpu) = gpu() else { return };
    let dir = tempfile::tempdir().unwrap();
    let input = fold_obj(dir.path());
    let mut means = Vec::new();
    for (name, ev) in [
        ("dark.png", Some(-1.0)),
        ("bright.png", Some(1.0)),
        ("auto.png", None),
    ] {
        let path = dir.path().join(name);
        run_visibility(
            &VisibilityRequest {
                render: Some(path.clone()),
                render_size: [96, 64],
                exposure_ev: ev,
                ..request(input.clone())
            },
            Some(&gpu),
        )
        .unwrap();
        let image = image::open(&path).unwrap().to_rgb8();
        assert_eq!(image.dimensions(), (96, 64), "{name}");
        let mean: f64 = image.pixels().map(|p| f64::from(p[1])).sum::<f64>() / f64::from(96 * 64);
        means.push(mean);
    }
    // Without an environment the background is black and the mesh grey a_i ≤ 1: at EV −1
    // (×½) and +1 (×2), with gamma 2.2, the brighter image is clearly brighter.
    assert!(means[1] > means[0] * 1.3, "means {means:?}");
    assert!(means[0] > 1.0, "the mesh is visible: {means:?}");
}

#[test]
fn a_z_up_copy_with_up_axis_z_gets_the_colours_of_the_y_up_original() {
    use crate::commands::up_axis::UpAxis;
    let dir = tempfile::tempdir().unwrap();
    let input = fold_obj(dir.path());
    // The same fold authored Z-up.
    let z_up = super::common::z_up_copy(&input);
    let colours = |input: &Path, up_axis: UpAxis, name: &str| {
        let glb = dir.path().join(name);
        let request = VisibilityRequest {
            environment: Some(sky()),
            out: Some(glb.clone()),
            up_axis,
            ..request(input.to_owned())
        };
        run_visibility(&request, None).unwrap();
        (glb_attribute(&glb, "COLOR_0"), glb_attribute(&glb, "_AO"))
    };
    let (reference, ao) = colours(&input, UpAxis::PosY, "y.glb");
    let (turned, turned_ao) = colours(&z_up, UpAxis::PosZ, "z.glb");
    let (lying, _) = colours(&z_up, UpAxis::PosY, "lying.glb");
    // a_i does not depend on the up axis; the sky's colours follow it to rounding.
    for (a, b) in ao.iter().zip(&turned_ao) {
        assert!((a - b).abs() < 1e-5, "a_i {a} vs {b}");
    }
    let max_diff = |a: &[f32], b: &[f32]| {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0f32, f32::max)
    };
    assert!(
        max_diff(&reference, &turned) < 1e-4,
        "{}",
        max_diff(&reference, &turned)
    );
    // Without --up-axis the sun lights the lying copy from the side: the test is not vacuous.
    assert!(
        max_diff(&reference, &lying) > 0.05,
        "{}",
        max_diff(&reference, &lying)
    );
}
