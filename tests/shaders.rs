//! Every WGSL file in the workspace (each lives beside the crate that uses it) parses and
//! validates with naga (the compiler wgpu uses), so a broken shader fails here on any machine,
//! GPU or not. Passes of the shared frame (crate `render`) use the view binding of
//! `crates/render/src/view.wgsl` without declaring it: they are validated with it prepended,
//! exactly as their crates compile them; a file that names a sibling in a `// requires:
//! FILE.wgsl` line gets that sibling prepended as well (translucency's shared `common.wgsl`).

use std::path::{Path, PathBuf};

fn workspace() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn wgsl_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        let name = entry.file_name();
        if path.is_dir() {
            if name != "target" && name != ".git" {
                wgsl_files(&path, out);
            }
        } else if path.extension().is_some_and(|e| e == "wgsl") {
            out.push(path);
        }
    }
}

#[test]
fn every_shader_in_the_workspace_parses_and_validates() {
    let view = std::fs::read_to_string(workspace().join("crates/render/src/view.wgsl")).unwrap();
    let mut files = Vec::new();
    for dir in ["crates", "shaders", "xtask"] {
        wgsl_files(&workspace().join(dir), &mut files);
    }
    files.sort();
    let mut checked = Vec::new();
    for path in &files {
        let own = std::fs::read_to_string(path).unwrap();
        // A frame pass reads `view.` and leaves its declaration to view.wgsl.
        let needs_view = own.contains("view.") && !own.contains("var<uniform> view");
        let mut prelude = String::new();
        for line in own.lines() {
            if let Some(name) = line.trim().strip_prefix("// requires: ") {
                let sibling = path.with_file_name(name.trim());
                prelude.push_str(&std::fs::read_to_string(&sibling).unwrap_or_else(|e| {
                    panic!("{}: requires {}: {e}", path.display(), sibling.display())
                }));
                prelude.push('\n');
            }
        }
        let source = if needs_view {
            format!("{view}\n{prelude}{own}")
        } else {
            format!("{prelude}{own}")
        };
        let module = naga::front::wgsl::parse_str(&source)
            .unwrap_or_else(|e| panic!("{}: {}", path.display(), e.emit_to_string(&source)));
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::all(),
        )
        .validate(&module)
        .unwrap_or_else(|e| panic!("{}: {}", path.display(), e.emit_to_string(&source)));
        checked.push(path.strip_prefix(workspace()).unwrap_or(path).to_owned());
    }
    // view, gouraud, backdrop (render); btf_render (btf); cpca_decode (anim-pca); four
    // occlusion kernels and triangle_ids (occlusion-gpu): none may be skipped.
    assert!(
        checked.len() >= 10,
        "only {} WGSL files found: {checked:?}",
        checked.len()
    );
    eprintln!("validated {} WGSL files: {checked:?}", checked.len());
}

#[test]
fn crates_embed_the_files_on_disk() {
    let read = |p: &str| std::fs::read_to_string(workspace().join(p)).unwrap();
    assert_eq!(render::VIEW_SHADER, read("crates/render/src/view.wgsl"));
    assert_eq!(
        render::GOURAUD_SHADER,
        read("crates/render/src/gouraud.wgsl")
    );
    assert_eq!(
        render::BACKDROP_SHADER,
        read("crates/render/src/backdrop.wgsl")
    );
}
