//! The self-shadowing effect's wiring against the engine's own ambient term: under a constant
//! environment L, c_i = (ρ/π) Σ_j M_ij L ω_j = ρ L a_i exactly, for the front rows and (for
//! two-sided objects) the back rows; an occluder above a sheet darkens its top, not its
//! underside.

mod common;

use common::{object, sheet};

use cloth_vis::scene::Scene;
use cloth_vis::shadowing::{light_objects, visibility};
use glam::Vec3;
use gpu_context::{GpuContext, GpuOptions};

#[test]
fn constant_sky_gives_albedo_times_radiance_times_ambient_on_both_sides() {
    let gpu = match GpuContext::new(&GpuOptions::default()) {
        Ok(g) => g,
        Err(e) => {
            test_data::skip::<()>(&format!("no GPU adapter: {e}"));
            return;
        }
    };
    let scene =
        Scene::from_toml("[visibility]\nbackend = \"cpu\"\n", ".".as_ref(), "test").unwrap();
    let mut objects = vec![
        object("floor", sheet(9, 2.0, 0.0), true),
        object("roof", sheet(3, 0.8, 0.3), false),
    ];
    let sphere = lightsphere::Lightsphere::new(3).unwrap();
    let l = Vec3::new(2.0, 1.0, 0.5);
    let radiance = vec![l; sphere.len()];
    let (vis, report) = visibility(&scene, &gpu, &objects, &sphere).unwrap();
    assert_eq!(report["backend"], "cpu");
    light_objects(&mut objects, &sphere, &radiance, Some(&vis)).unwrap();

    // Independent ambient terms from the engine, front and flipped.
    let ambient = |normals: Vec<Vec3>| {
        let mut occ = occlusion_gpu::Scene::new();
        occ.push(occlusion_gpu::SceneObject::new(
            objects[0].positions.clone(),
            normals,
            objects[0].triangles.clone(),
        ))
        .unwrap();
        occ.push(
            occlusion_gpu::SceneObject::new(
                objects[1].positions.clone(),
                objects[1].normals.clone(),
                objects[1].triangles.clone(),
            )
            .occluder_only(),
        )
        .unwrap();
        let mut engine =
            occlusion_gpu::VisibilityEngine::cpu(occlusion_gpu::VisibilityParams::default());
        engine.compute(&occ, &sphere).unwrap().ambient()
    };
    let top = ambient(objects[0].normals.clone());
    let bottom = ambient(objects[0].normals.iter().map(|n| -*n).collect());
    let rho_l = objects[0].albedo * l;
    let front = objects[0].front.as_ref().unwrap();
    let back = objects[0].back.as_ref().unwrap();
    for i in 0..front.len() {
        let tol = 1e-4 * rho_l.max_element();
        assert!(
            (front[i] - rho_l * top[i]).abs().max_element() < tol,
            "front {i}: {} vs {}",
            front[i],
            rho_l * top[i]
        );
        assert!(
            (back[i] - rho_l * bottom[i]).abs().max_element() < tol,
            "back {i}: {} vs {}",
            back[i],
            rho_l * bottom[i]
        );
    }
    // The centre of the floor lies under the roof: darker on top than at the open corner, and
    // its underside is open (a ≈ 1).
    let centre = 4 * 9 + 4;
    assert!(
        top[centre] < 0.8 * top[0],
        "centre {} corner {}",
        top[centre],
        top[0]
    );
    assert!(bottom[centre] > 0.95, "underside {}", bottom[centre]);
}

/// `[visibility] max_distance` below the roof's height leaves the floor as open as without the
/// roof (the cpu stage, no GPU needed); a non-positive distance or a GPU backend is refused.
#[test]
fn max_distance_below_the_roof_ignores_it() {
    let sphere = lightsphere::Lightsphere::new(2).unwrap();
    let ambient = |toml: &str, objects: &[cloth_vis::object::WorldObject]| {
        let scene = Scene::from_toml(toml, ".".as_ref(), "test").unwrap();
        let mut stage = cloth_vis::shadowing::VisibilityStage::new(&scene, None).unwrap();
        stage
            .compute(objects, &sphere)
            .unwrap()
            .0
            .matrix()
            .ambient()
    };
    let floor = object("floor", sheet(9, 2.0, 0.0), false);
    let roof = object("roof", sheet(3, 0.8, 0.3), false);
    let both = [floor.clone(), roof];
    let alone = ambient(
        "[visibility]\nbackend = \"cpu\"\n",
        std::slice::from_ref(&floor),
    );
    let bounded = ambient("[visibility]\nmax_distance = 0.25\n", &both);
    let unbounded = ambient("[visibility]\nbackend = \"cpu\"\n", &both);
    let n = alone.len();
    assert_eq!(bounded[..n], alone[..]);
    assert_ne!(
        unbounded[..n],
        alone[..],
        "the roof shades the floor without the bound"
    );
    for bad in [
        "[visibility]\nmax_distance = 0.0\n",
        "[visibility]\nmax_distance = -1.0\n",
        "[visibility]\nbackend = \"depth\"\nmax_distance = 1.0\n",
    ] {
        let toml = format!("{bad}[[object]]\nname = \"c\"\nsource = \"synth:cloth\"\n");
        let scene = Scene::from_toml(&toml, ".".as_ref(), "test").unwrap();
        let error = scene.validate().unwrap_err();
        assert!(
            error.to_string().contains("visibility.max_distance"),
            "{bad}: {error}"
        );
    }
}
