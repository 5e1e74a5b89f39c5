//! Prints what the loader found in a file: `cargo run -p meshio --example inspect -- PATH`.
//!
//! Folders, `.npy`, `.glb` and `.gltf` are loaded as animations, everything else as a mesh.
//! Errors are printed as the loader phrases them (exit code 1).

use std::path::PathBuf;

fn main() {
    let Some(path) = std::env::args().nth(1).map(PathBuf::from) else {
        eprintln!("usage: inspect PATH");
        std::process::exit(2);
    };
    let as_animation = path.is_dir()
        || path
            .extension()
            .is_some_and(|e| e == "npy" || e == "glb" || e == "gltf");
    let result = if as_animation {
        meshio::load_animation(&path, &meshio::AnimationOptions::default()).map(|(a, r)| {
            println!(
                "animation: {} frames × {} vertices, {} triangles, {} fps",
                a.frame_count(),
                a.vertex_count(),
                a.triangles.len(),
                a.frame_rate
            );
            println!("bounding box over all frames: {:?}", a.bounding_box());
            r
        })
    } else {
        meshio::load_mesh(&path, &meshio::LoadOptions::default()).map(|(m, r)| {
            println!(
                "mesh: {} vertices, {} triangles, uvs: {}",
                m.vertex_count(),
                m.triangle_count(),
                m.uvs.is_some()
            );
            println!("bounding box: {:?}", m.bounding_box());
            r
        })
    };
    match result {
        Ok(report) => {
            println!("format: {:?}", report.format);
            println!(
                "faces as written: {}, polygons triangulated: {}",
                report.file_face_count, report.polygons_triangulated
            );
            println!(
                "unreferenced vertices: {}",
                report.unreferenced_vertices.len()
            );
            let repeated = report
                .degenerate_triangles
                .iter()
                .filter(|d| d.kind == meshio::DegenerateKind::RepeatedIndex)
                .count();
            println!(
                "degenerate triangles: {} ({repeated} repeated index)",
                report.degenerate_triangles.len()
            );
            println!("duplicate positions: {}", report.duplicate_positions);
            println!(
                "repeated triangles: {}, back-to-back pairs: {}",
                report.repeated_triangles.repeated, report.repeated_triangles.back_to_back
            );
            println!(
                "normals computed: {}, file normals: {:?}, uvs: {:?}",
                report.normals_computed, report.file_normals, report.uvs
            );
            println!("skipped keywords: {:?}", report.skipped_keywords);
            println!("skipped properties: {:?}", report.skipped_properties);
            if let Some(clip) = &report.clip {
                println!("clip: {clip:?}");
            }
            for note in &report.notes {
                println!("note: {note}");
            }
        }
        Err(error) => {
            eprintln!("error: {error}");
            std::process::exit(1);
        }
    }
}
