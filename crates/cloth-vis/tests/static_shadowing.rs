//! The static-shadowing effect's wiring against the hemicube crate: under a constant
//! environment L every vertex gets ρ L Σ_p V_p ΔF_p, front and (two-sided) back; an occluder
//! above a sheet darkens its top, not its underside.

mod common;

use common::{object, sheet};

use std::sync::Arc;

use cloth_vis::static_shadowing::StaticShadowingStage;

#[test]
fn constant_sky_gives_albedo_times_radiance_times_open_fraction_on_both_sides() {
    let text = "effects = [\"static-shadowing\"]\n[[object]]\nname = \"a\"\nsource = \"synth:cloth\"\n\
                [environment]\nsource = \"synth:sky\"\n[static_shadowing]\nres = 16\nbuilder = \"cpu\"\nlookup = \"exact\"\n";
    let scene = common::scene(text, ".".as_ref());
    let stage = StaticShadowingStage::new(&scene, None).unwrap();
    let l = 2.0f32;
    let env = lightsphere::Environment::from_latlong(64, 32, vec![[l; 3]; 64 * 32]).unwrap();
    // The lower sheet is two-sided and normals face +y (the winding above); the upper sheet
    // covers its centre.
    let mut objects = vec![
        object("low", sheet(9, 2.0, 0.0), true),
        object("high", sheet(3, 0.5, 0.3), true),
    ];
    stage.light(None, &mut objects, &env).unwrap();
    // The reference: the hemicube maps of the same scene, front then back rows.
    let mut occ = occlusion_gpu::Scene::new();
    for o in &objects {
        occ.push(occlusion_gpu::SceneObject::new(
            o.positions.clone(),
            o.normals.clone(),
            o.triangles.clone(),
        ))
        .unwrap();
        let flipped = o.normals.iter().map(|n| -*n).collect();
        occ.push(occlusion_gpu::SceneObject::new(
            o.positions.clone(),
            flipped,
            o.triangles.clone(),
        ))
        .unwrap();
    }
    let layout = Arc::new(
        hemicube::PixelLayout::new(
            hemicube::Model::Hemicube { res: 16 },
            hemicube::FormFactorRule::Exact,
        )
        .unwrap(),
    );
    let (maps, _) =
        hemicube::build_with_rays(&occ, layout, &hemicube::BuildParams::default()).unwrap();
    let open = maps.open_fraction();
    let low = &objects[0];
    let (front, back) = (low.front.as_ref().unwrap(), low.back.as_ref().unwrap());
    let n = low.positions.len();
    for i in 0..n {
        let f = low.albedo * l * open[i];
        let b = low.albedo * l * open[n + i];
        assert!(
            (front[i] - f).abs().max_element() < 1e-5,
            "front {i}: {} vs {f}",
            front[i]
        );
        assert!(
            (back[i] - b).abs().max_element() < 1e-5,
            "back {i}: {} vs {b}",
            back[i]
        );
    }
    // The centre of the lower sheet: shadowed on top by the upper sheet, open underneath.
    let centre = 4 * 9 + 4;
    let normal_up = low.normals[centre].y > 0.0;
    let (top, under) = if normal_up {
        (front[centre], back[centre])
    } else {
        (back[centre], front[centre])
    };
    assert!(top.x < 0.9 * under.x, "top {top} under {under}");
}
