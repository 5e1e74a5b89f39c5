//! Every WGSL shader in `shaders/` parses and validates with naga (the compiler wgpu uses), so a
//! broken shader fails here on any machine, GPU or not.

use std::path::PathBuf;

fn shader_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shaders")
}

#[test]
fn every_shader_parses_and_validates() {
    let mut checked = 0;
    let mut entries: Vec<_> = std::fs::read_dir(shader_dir())
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .collect();
    entries.sort();
    for path in entries
        .into_iter()
        .filter(|p| p.extension().is_some_and(|e| e == "wgsl"))
    {
        let source = std::fs::read_to_string(&path).unwrap();
        let module = naga::front::wgsl::parse_str(&source)
            .unwrap_or_else(|e| panic!("{}: {}", path.display(), e.emit_to_string(&source)));
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::empty(),
        )
        .validate(&module)
        .unwrap_or_else(|e| panic!("{}: {}", path.display(), e.emit_to_string(&source)));
        checked += 1;
    }
    assert!(
        checked >= 1,
        "no shaders found in {}",
        shader_dir().display()
    );
}

#[test]
fn the_renderer_embeds_the_shader_file() {
    let on_disk = std::fs::read_to_string(shader_dir().join("mesh.wgsl")).unwrap();
    assert_eq!(cloth_vis::render::MESH_SHADER, on_disk);
}
