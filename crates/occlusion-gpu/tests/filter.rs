//! Vertex filtering (paper 000 §4.1): rows computed with filtering are bit-identical to a full
//! computation for every vertex of every visible triangle; the filter computes each vertex at
//! most once on a static orbit and exactly the visible triangles' vertices per deforming frame.

mod common;

use common::*;
use glam::Vec3;
use lightsphere::Lightsphere;
#[cfg(feature = "gpu")]
use occlusion_gpu::{Backend, DepthParams, TriangleIdRenderer};
use occlusion_gpu::{
    Camera, FilterParams, FilterThreshold, FilteredVisibility, OcclusionError, Scene, SceneObject,
    TriangleSet, TriangleVisibility, VertexFilter, VisibilityEngine, VisibilityMatrix,
    VisibilityParams, triangle_rows, visible_triangles_cpu,
};

const SIZE: u32 = 96;

/// The shared GPU-or-skip harness (fails under CI, visible skip otherwise).
#[cfg(feature = "gpu")]
use gpu_context::testing::gpu_or_skip as gpu;

fn cpu_engine() -> VisibilityEngine {
    VisibilityEngine::cpu(VisibilityParams::default())
}

fn bounds(scene: &Scene) -> (Vec3, f32) {
    let points: Vec<Vec3> = scene
        .objects()
        .iter()
        .flat_map(|o| {
            o.positions
                .iter()
                .map(|p| o.world_from_object.transform_point3(*p))
        })
        .collect();
    let lo = points.iter().fold(Vec3::INFINITY, |a, p| a.min(*p));
    let hi = points.iter().fold(Vec3::NEG_INFINITY, |a, p| a.max(*p));
    (0.5 * (lo + hi), 0.5 * (hi - lo).length())
}

/// Frame `f` of an orbit of `frames` around the scene at 2.5 radii, slightly from above.
fn orbit(scene: &Scene, f: usize, frames: usize) -> Camera {
    let (center, radius) = bounds(scene);
    let angle = std::f32::consts::TAU * f as f32 / frames as f32;
    let eye = center + 2.5 * radius * Vec3::new(angle.cos(), 0.5, angle.sin());
    Camera::look_at(eye, center, Vec3::Y, 0.8, SIZE, SIZE).unwrap()
}

/// Every vertex row of every visible triangle equals the full matrix bit for bit, as do its
/// ambient term and radiance.
#[track_caller]
fn assert_visible_rows_identical(
    scene: &Scene,
    visible: &TriangleSet,
    filtered: &VisibilityMatrix,
    full: &VisibilityMatrix,
) {
    let rows = triangle_rows(scene, visible).unwrap();
    let w = full.words_per_row();
    let (a_f, a_full) = (filtered.ambient(), full.ambient());
    let radiance: Vec<Vec3> = (0..full.directions_len())
        .map(|j| Vec3::new(1.0 + j as f32, 0.5, 2.0 / (1.0 + j as f32)))
        .collect();
    let (c_f, c_full) = (
        filtered.radiance(&radiance).unwrap(),
        full.radiance(&radiance).unwrap(),
    );
    for &r in &rows {
        let r = r as usize;
        assert_eq!(
            filtered.bits()[r * w..(r + 1) * w],
            full.bits()[r * w..(r + 1) * w],
            "row {r}"
        );
        assert_eq!(a_f[r].to_bits(), a_full[r].to_bits(), "ambient of row {r}");
        assert_eq!(
            c_f[r].to_array().map(f32::to_bits),
            c_full[r].to_array().map(f32::to_bits),
            "radiance of row {r}"
        );
    }
}

/// Runs a static orbit with filtering; checks identity per frame and returns the total rows.
fn static_orbit(
    scene: &Scene,
    engine: VisibilityEngine,
    full_engine: &mut VisibilityEngine,
    mut visibility_check: TriangleVisibility,
    visibility: TriangleVisibility,
    frames: usize,
) -> usize {
    let sphere = Lightsphere::new(2).unwrap();
    let full = full_engine.compute(scene, &sphere).unwrap();
    let mut driver = FilteredVisibility::new(engine, visibility, FilterParams::default()).unwrap();
    let mut total = 0;
    for f in 0..frames {
        let camera = orbit(scene, f, frames);
        let stats = driver.frame(scene, &sphere, &camera, false).unwrap();
        total += stats.rows_computed;
        let visible = match driver.last_visible() {
            Some(v) => v.clone(),
            None => visibility_check.visible(scene, &camera).unwrap(),
        };
        assert!(visible.count() > 0, "frame {f} sees the mesh");
        assert_visible_rows_identical(scene, &visible, driver.matrix().unwrap(), &full);
        eprintln!(
            "frame {f}: {} rows, {:?} visible, {} new, {} unseen",
            stats.rows_computed,
            stats.triangles_visible,
            stats.triangles_new,
            stats.triangles_unseen
        );
    }
    assert_eq!(
        total,
        driver.computed_rows(),
        "each row computed at most once"
    );
    assert!(total <= scene.receiver_count());
    total
}

#[test]
fn compute_rows_equals_full_rows_and_leaves_others() {
    let scene = sphere_over_plane();
    let sphere = Lightsphere::new(2).unwrap();
    let mut engine = cpu_engine();
    let full = engine.compute(&scene, &sphere).unwrap();
    // A different scene (the ball lowered into the plane) gives different "old" rows.
    let mut moved = scene.clone();
    moved.object_mut(1).unwrap().world_from_object = glam::Mat4::from_translation(-0.4 * Vec3::Y);
    let old = engine.compute(&moved, &sphere).unwrap();
    let mut matrix = old.clone();
    let rows: Vec<u32> = (0..scene.receiver_count() as u32).step_by(7).collect();
    engine.compute_rows(&scene, &mut matrix, &rows).unwrap();
    let w = full.words_per_row();
    for r in 0..scene.receiver_count() {
        let expected = if rows.contains(&(r as u32)) {
            &full
        } else {
            &old
        };
        assert_eq!(
            matrix.bits()[r * w..(r + 1) * w],
            expected.bits()[r * w..(r + 1) * w]
        );
        assert_eq!(matrix.normals()[r], expected.normals()[r], "normal {r}");
    }
    assert_ne!(matrix, old, "the moved ball changed some listed rows");
}

#[test]
fn compute_rows_rejects_bad_indices() {
    let scene = sphere_over_plane();
    let sphere = Lightsphere::new(0).unwrap();
    let mut engine = cpu_engine();
    let mut matrix = engine.compute(&scene, &sphere).unwrap();
    let n = matrix.rows() as u32;
    let before = matrix.clone();
    assert!(matches!(
        engine.compute_rows(&scene, &mut matrix, &[0, n]),
        Err(OcclusionError::RowOutOfRange { row, .. }) if row == n
    ));
    assert_eq!(matrix, before, "nothing written on error");
    let mut small = Scene::new();
    small.push(grid(2, 1.0).object()).unwrap();
    assert!(matches!(
        engine.compute_rows(&small, &mut matrix, &[0]),
        Err(OcclusionError::RowCountMismatch { .. })
    ));
    engine.compute_rows(&scene, &mut matrix, &[]).unwrap();
    assert_eq!(matrix, before);
}

#[test]
fn static_orbit_is_identical_and_computes_each_row_once_cpu() {
    let scene = sphere_over_plane();
    let mut full_engine = cpu_engine();
    let total = static_orbit(
        &scene,
        cpu_engine(),
        &mut full_engine,
        TriangleVisibility::Cpu,
        TriangleVisibility::Cpu,
        12,
    );
    eprintln!(
        "sphere over plane: {total} of {} rows",
        scene.receiver_count()
    );
    assert!(total > 0);
}

#[test]
fn bunny_orbit_is_identical_cpu_backend() {
    let Some(scene) = shared_scene("meshes/bun_zipper_res4.ply") else {
        return;
    };
    let mut full_engine = cpu_engine();
    let total = static_orbit(
        &scene,
        cpu_engine(),
        &mut full_engine,
        TriangleVisibility::Cpu,
        TriangleVisibility::Cpu,
        8,
    );
    eprintln!("bunny res4: {total} of {} rows", scene.receiver_count());
}

#[test]
#[cfg(feature = "gpu")]
fn bunny_orbit_is_identical_depth_backend_gpu_ids() {
    let Some(ctx) = gpu() else { return };
    let Some(scene) = shared_scene("meshes/bun_zipper_res4.ply") else {
        return;
    };
    let params =
        VisibilityParams::default().with_depth(DepthParams::default().with_resolution(512));
    let depth = || VisibilityEngine::with_gpu(&ctx.device, &ctx.queue, Backend::Depth, params);
    let ids = || TriangleVisibility::gpu(&ctx.device, &ctx.queue);
    let mut full_engine = depth();
    static_orbit(&scene, depth(), &mut full_engine, ids(), ids(), 6);
    // And the cpu backend with the GPU id pass.
    let mut full_engine = cpu_engine();
    static_orbit(&scene, cpu_engine(), &mut full_engine, ids(), ids(), 6);
}

#[test]
#[cfg(feature = "gpu")]
fn gpu_ids_agree_with_cpu_rasteriser() {
    let Some(ctx) = gpu() else { return };
    let mut renderer = TriangleIdRenderer::new(&ctx.device, &ctx.queue);
    let scenes: Vec<Scene> = [
        Some(sphere_over_plane()),
        shared_scene("meshes/bun_zipper_res4.ply"),
    ]
    .into_iter()
    .flatten()
    .collect();
    for scene in &scenes {
        for f in 0..4 {
            let camera = orbit(scene, f, 4);
            let gpu = renderer.visible_triangles(scene, &camera).unwrap();
            let cpu = visible_triangles_cpu(scene, &camera).unwrap();
            let differ = (0..gpu.len())
                .filter(|&t| gpu.contains(t) != cpu.contains(t))
                .count();
            eprintln!(
                "frame {f}: gpu {} cpu {} differ {differ}",
                gpu.count(),
                cpu.count()
            );
            // Only triangles touching pixel centres with an edge (fill rule) may differ.
            assert!(differ as f64 <= 0.03 * gpu.count() as f64 + 2.0);
        }
    }
}

/// The synthetic cloth as a scene per frame, with area-weighted normals.
fn cloth_scenes(grid: usize, frames: usize) -> Vec<Scene> {
    let params = synth::ClothParams {
        grid,
        frames,
        ..Default::default()
    };
    let animation = synth::simulate_cloth(&params).unwrap();
    animation
        .frames
        .iter()
        .map(|positions| {
            let normals = meshio::compute_normals(
                positions,
                &animation.triangles,
                meshio::NormalWeighting::Area,
            );
            let mut scene = Scene::new();
            scene
                .push(SceneObject::new(
                    positions.clone(),
                    normals,
                    animation.triangles.clone(),
                ))
                .unwrap();
            scene
        })
        .collect()
}

#[test]
fn deforming_cloth_computes_exactly_the_visible_vertices() {
    let scenes = cloth_scenes(20, 24);
    let sphere = Lightsphere::new(1).unwrap();
    // Fixed camera from the +x side: it sees one side of the drape.
    let camera = Camera::look_at(
        Vec3::new(3.0, 0.8, 0.0),
        Vec3::new(0.0, 0.4, 0.0),
        Vec3::Y,
        0.9,
        SIZE,
        SIZE,
    )
    .unwrap();
    let mut driver = FilteredVisibility::new(
        cpu_engine(),
        TriangleVisibility::Cpu,
        FilterParams::default(),
    )
    .unwrap();
    let mut full_engine = cpu_engine();
    for (f, scene) in scenes.iter().enumerate() {
        let stats = driver.frame(scene, &sphere, &camera, true).unwrap();
        let visible = driver
            .last_visible()
            .expect("a deforming frame always filters")
            .clone();
        let expected = triangle_rows(scene, &visible).unwrap().len();
        assert_eq!(stats.rows_computed, expected, "frame {f}");
        assert!(
            stats.rows_computed > 0 && stats.rows_computed < stats.rows_total,
            "frame {f}: {stats:?}"
        );
        if f % 6 == 5 {
            let full = full_engine.compute(scene, &sphere).unwrap();
            assert_visible_rows_identical(scene, &visible, driver.matrix().unwrap(), &full);
        }
    }
}

#[test]
fn threshold_moves_all_of_u_to_t_and_stops_filtering() {
    let mut filter = VertexFilter::new(
        10,
        FilterParams::default().with_threshold(FilterThreshold::Count(4)),
    )
    .unwrap();
    let t = filter
        .update(|| TriangleSet::from_indices(10, &[0, 1, 2]))
        .unwrap();
    assert_eq!(t.iter().collect::<Vec<_>>(), [0, 1, 2]);
    // Seen triangles are not "new" again.
    let t = filter
        .update(|| TriangleSet::from_indices(10, &[1, 2, 3, 4, 5, 6]))
        .unwrap();
    assert_eq!(t.iter().collect::<Vec<_>>(), [3, 4, 5, 6]);
    assert_eq!(filter.unseen().count(), 3);
    assert!(filter.is_active());
    // |U| = 3 < 4: all of U becomes T without a visibility pass, and filtering stops.
    let t = filter
        .update(|| panic!("no visibility pass below the threshold"))
        .unwrap();
    assert_eq!(t.iter().collect::<Vec<_>>(), [7, 8, 9]);
    assert!(!filter.is_active());
    assert_eq!(filter.unseen().count(), 0);
    let t = filter.update(|| panic!("filter is off")).unwrap();
    assert_eq!(t.count(), 0);
    // Reset (deforming mesh) re-initialises U and switches filtering back on.
    filter.reset();
    assert!(filter.is_active());
    assert_eq!(filter.unseen().count(), 10);
    let t = filter
        .update(|| TriangleSet::from_indices(10, &[9]))
        .unwrap();
    assert_eq!(t.iter().collect::<Vec<_>>(), [9]);
    // Wrong size and invalid fraction are errors.
    assert!(matches!(
        filter.update(|| Ok(TriangleSet::empty(3))),
        Err(OcclusionError::SizeMismatch { .. })
    ));
    for bad in [-0.1, 1.5, f64::NAN] {
        let params = FilterParams::default().with_threshold(FilterThreshold::Fraction(bad));
        assert!(VertexFilter::new(10, params).is_err());
    }
}

#[test]
fn fraction_threshold_on_an_orbit_finishes_all_rows() {
    // With a threshold of 60% of the triangles, the second frame already switches off and
    // computes every remaining vertex: the whole matrix then equals the full one.
    let scene = sphere_over_plane();
    let sphere = Lightsphere::new(1).unwrap();
    let params = FilterParams::default().with_threshold(FilterThreshold::Fraction(0.6));
    let mut driver =
        FilteredVisibility::new(cpu_engine(), TriangleVisibility::Cpu, params).unwrap();
    let mut active = Vec::new();
    for f in 0..3 {
        let stats = driver
            .frame(&scene, &sphere, &orbit(&scene, f, 8), false)
            .unwrap();
        active.push(stats.filter_active);
    }
    assert_eq!(active, [true, false, false]);
    let full = cpu_engine().compute(&scene, &sphere).unwrap();
    let m = driver.matrix().unwrap();
    assert_eq!(m.bits(), full.bits());
    assert_eq!(driver.computed_rows(), scene.receiver_count());
}

mod hard_cases {
    use super::*;

    #[test]
    fn camera_seeing_nothing_computes_nothing() {
        let scene = sphere_over_plane();
        let sphere = Lightsphere::new(1).unwrap();
        let camera = Camera::look_at(
            Vec3::new(0.0, 0.0, 10.0),
            Vec3::new(0.0, 0.0, 20.0),
            Vec3::Y,
            0.8,
            SIZE,
            SIZE,
        )
        .unwrap();
        let mut driver = FilteredVisibility::new(
            cpu_engine(),
            TriangleVisibility::Cpu,
            FilterParams::default(),
        )
        .unwrap();
        let stats = driver.frame(&scene, &sphere, &camera, false).unwrap();
        assert_eq!(stats.triangles_visible, Some(0));
        assert_eq!(stats.rows_computed, 0);
        assert!(
            driver
                .matrix()
                .unwrap()
                .ambient()
                .iter()
                .all(|a| a.is_nan()),
            "nothing computed"
        );
        #[cfg(feature = "gpu")]
        if let Some(ctx) = gpu() {
            let mut renderer = TriangleIdRenderer::new(&ctx.device, &ctx.queue);
            assert_eq!(
                renderer.visible_triangles(&scene, &camera).unwrap().count(),
                0
            );
        }
    }

    #[test]
    fn camera_inside_a_closed_mesh_sees_the_inside() {
        let ball = uv_sphere(Vec3::ZERO, 1.0, 12, 24);
        let scene = Scene::single(
            ball.positions.clone(),
            ball.normals.clone(),
            ball.triangles.clone(),
        )
        .unwrap();
        let sphere = Lightsphere::new(1).unwrap();
        let camera = Camera::look_at(Vec3::ZERO, Vec3::X, Vec3::Y, 1.2, SIZE, SIZE).unwrap();
        let visible = visible_triangles_cpu(&scene, &camera).unwrap();
        assert!(visible.count() > 0 && visible.count() < scene.triangle_count());
        let mut driver = FilteredVisibility::new(
            cpu_engine(),
            TriangleVisibility::Cpu,
            FilterParams::default(),
        )
        .unwrap();
        let stats = driver.frame(&scene, &sphere, &camera, false).unwrap();
        assert_eq!(
            stats.rows_computed,
            triangle_rows(&scene, &visible).unwrap().len()
        );
        let full = cpu_engine().compute(&scene, &sphere).unwrap();
        assert_visible_rows_identical(&scene, &visible, driver.matrix().unwrap(), &full);
        #[cfg(feature = "gpu")]
        if let Some(ctx) = gpu() {
            let mut renderer = TriangleIdRenderer::new(&ctx.device, &ctx.queue);
            let gpu = renderer.visible_triangles(&scene, &camera).unwrap();
            assert!(gpu.count() > 0 && gpu.count() < scene.triangle_count());
        }
    }

    #[test]
    fn zero_triangles_see_nothing() {
        let scene = Scene::single(vec![Vec3::ZERO, Vec3::X], vec![Vec3::Y; 2], vec![]).unwrap();
        let camera = Camera::look_at(
            Vec3::new(0.0, 2.0, 2.0),
            Vec3::ZERO,
            Vec3::Y,
            0.8,
            SIZE,
            SIZE,
        )
        .unwrap();
        assert_eq!(visible_triangles_cpu(&scene, &camera).unwrap().len(), 0);
        let mut driver = FilteredVisibility::new(
            cpu_engine(),
            TriangleVisibility::Cpu,
            FilterParams::default(),
        )
        .unwrap();
        let stats = driver
            .frame(&scene, &Lightsphere::new(0).unwrap(), &camera, true)
            .unwrap();
        assert_eq!(stats.rows_computed, 0);
        #[cfg(feature = "gpu")]
        if let Some(ctx) = gpu() {
            let mut renderer = TriangleIdRenderer::new(&ctx.device, &ctx.queue);
            assert_eq!(
                renderer.visible_triangles(&scene, &camera).unwrap().len(),
                0
            );
        }
    }

    #[test]
    fn sub_pixel_triangle_is_neither_visible_nor_computed() {
        // A 2×2 quad at the origin plus a separate triangle 1e-4 wide (far below a pixel of
        // a 96² view of the quad) placed between pixel centres.
        let mut positions = grid(1, 2.0).positions;
        let base = positions.len() as u32;
        positions.extend([
            Vec3::new(0.3, 0.5, 0.3),
            Vec3::new(0.3001, 0.5, 0.3),
            Vec3::new(0.3, 0.5, 0.3001),
        ]);
        let mut triangles = grid(1, 2.0).triangles;
        triangles.push([base, base + 1, base + 2]);
        let scene = Scene::single(positions, vec![Vec3::Y; 7], triangles).unwrap();
        let camera = Camera::look_at(
            Vec3::new(0.0, 3.0, 0.01),
            Vec3::ZERO,
            Vec3::Y,
            0.9,
            SIZE,
            SIZE,
        )
        .unwrap();
        let visible = visible_triangles_cpu(&scene, &camera).unwrap();
        assert!(
            visible.contains(0) && visible.contains(1),
            "the quad is visible"
        );
        assert!(
            !visible.contains(2),
            "the tiny triangle covers no pixel centre"
        );
        let mut driver = FilteredVisibility::new(
            cpu_engine(),
            TriangleVisibility::Cpu,
            FilterParams::default(),
        )
        .unwrap();
        let sphere = Lightsphere::new(1).unwrap();
        let stats = driver.frame(&scene, &sphere, &camera, false).unwrap();
        assert_eq!(stats.rows_computed, 4, "only the quad's vertices");
        let ambient = driver.matrix().unwrap().ambient();
        assert!(
            ambient[4..].iter().all(|a| a.is_nan()),
            "tiny triangle's vertices not computed"
        );
        #[cfg(feature = "gpu")]
        if let Some(ctx) = gpu() {
            let mut renderer = TriangleIdRenderer::new(&ctx.device, &ctx.queue);
            let gpu = renderer.visible_triangles(&scene, &camera).unwrap();
            assert!(gpu.contains(0) && gpu.contains(1) && !gpu.contains(2));
        }
    }

    #[test]
    fn invalid_cameras_are_errors() {
        assert!(Camera::new(glam::Mat4::IDENTITY, 0, 4).is_err());
        assert!(Camera::new(glam::Mat4::from_cols_array(&[f32::NAN; 16]), 4, 4).is_err());
        assert!(Camera::look_at(Vec3::ONE, Vec3::ONE, Vec3::Y, 0.8, 4, 4).is_err());
        assert!(Camera::look_at(Vec3::ZERO, Vec3::X, Vec3::Y, 4.0, 4, 4).is_err());
    }
}
