//! Helpers shared by the facade's tests.
#![allow(dead_code)]

use std::path::Path;

use cloth_vis::Scene;
use cloth_vis::object::WorldObject;
use glam::Vec3;
use gpu_context::{GpuContext, GpuOptions};

/// A scene from TOML text with paths relative to `base`.
#[track_caller]
pub fn scene(text: &str, base: &Path) -> Scene {
    match Scene::from_toml(text, base, "test scene") {
        Ok(s) => s,
        Err(e) => panic!("test scene does not parse: {e}"),
    }
}

/// A GPU context, or `None` after the project's skip policy (fails under CI).
pub fn gpu_available() -> bool {
    match GpuContext::new(&GpuOptions::default()) {
        Ok(_) => true,
        Err(e) => test_data::skip::<()>(&format!("no GPU adapter: {e}")).is_some(),
    }
}

/// Small procedural settings so end-to-end runs stay quick in tests.
pub const SMALL_SYNTH: &str = r#"
[synth]
cloth_grid = 24
cloth_frames = 40
seed = 3
sky_width = 256
"#;

/// Runs the `cloth-vis` binary with `args`.
pub fn cli(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_cloth-vis"))
        .args(args)
        .output()
        .unwrap()
}

/// A path as a command-line argument.
pub fn text(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// An n×n grid in the xz plane at height y, facing +y (counter-clockwise seen from above).
pub fn sheet(n: usize, size: f32, y: f32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut positions = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let s = size / (n - 1) as f32;
            positions.push(Vec3::new(
                i as f32 * s - size / 2.0,
                y,
                j as f32 * s - size / 2.0,
            ));
        }
    }
    let mut triangles = Vec::new();
    for i in 0..n - 1 {
        for j in 0..n - 1 {
            let a = (i * n + j) as u32;
            let (b, c, d) = (a + 1, a + n as u32, a + n as u32 + 1);
            triangles.push([a, b, d]);
            triangles.push([a, d, c]);
        }
    }
    (positions, triangles)
}

pub fn object(
    name: &str,
    (positions, triangles): (Vec<Vec3>, Vec<[u32; 3]>),
    two_sided: bool,
) -> WorldObject {
    let normals = meshio::compute_normals(&positions, &triangles, meshio::NormalWeighting::Angle);
    WorldObject {
        name: name.to_owned(),
        positions,
        normals,
        triangles,
        uvs: None,
        albedo: Vec3::new(0.5, 0.25, 1.0),
        two_sided,
        front: None,
        back: None,
        animation: None,
    }
}

/// An OBJ sheet facing +z in an n × n grid with UVs: triangles left of x = 0.5 under
/// `usemtl left`, the rest under `usemtl right`.
pub fn two_part_sheet(n: usize) -> String {
    let mut obj = String::new();
    for r in 0..=n {
        for c in 0..=n {
            let (x, y) = (c as f32 / n as f32, r as f32 / n as f32);
            obj.push_str(&format!("v {x} {y} 0\nvt {x} {y}\n"));
        }
    }
    for (material, cols) in [("left", 0..n / 2), ("right", n / 2..n)] {
        obj.push_str(&format!("usemtl {material}\n"));
        for r in 0..n {
            for c in cols.clone() {
                let i = r * (n + 1) + c + 1;
                let j = i + n + 1;
                obj.push_str(&format!(
                    "f {i}/{i} {}/{} {}/{} {j}/{j}\n",
                    i + 1,
                    i + 1,
                    j + 1,
                    j + 1
                ));
            }
        }
    }
    obj
}
