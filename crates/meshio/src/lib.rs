//! Validated loading of static meshes (PLY, OBJ, glTF) and mesh animations (glTF skinning and
//! morph targets, folders of numbered OBJ frames, `.npy` arrays), and `.npy` and glTF binary
//! (`.glb`) output.
//!
//! Every other cloth-vis crate reads its geometry through this one. The seeds fix what that
//! geometry is: the ambient-occlusion method starts from "a triangle mesh with vertex normals"
//! (thesis §4.4.3; paper 000 Table 1 times the Stanford bunny, "35k" vertices), and the
//! animation-compression chapter uses "animations of polygonal meshes \[where\] the number of
//! faces and their connectivity does not change over time" (thesis §3.3, Tab. 3.3: chicken,
//! 3030 V / 5664 T). Hence the two result types: [`Mesh`] (positions, unit normals, optional
//! UVs, triangles) and [`Animation`] (one triangle list, one position array per frame, normals
//! computed per frame with [`compute_normals`]).
//!
//! Loading validates instead of trusting: header counts are checked against the file length
//! before allocating, NaN/inf coordinates and out-of-range indices are errors naming the file,
//! element and value ([`MeshIoError`]), and untidy but usable data (degenerate triangles,
//! unreferenced or duplicated vertices, unknown OBJ keywords) is described in a [`LoadReport`]
//! and changed only when [`LoadOptions`] asks. By default per-vertex outputs line up with the
//! file: vertex `i` of the mesh is vertex `i` of the file.
//!
//! | input | [`load_mesh`] | [`load_animation`] |
//! |---|---|---|
//! | `.ply` (ASCII, binary LE/BE; faces or `tristrips`) | ✓ | one frame |
//! | `.obj` | ✓ | one frame |
//! | folder of numbered `.obj` frames | | ✓ (numeric order, parallel parse) |
//! | `.gltf` / `.glb` (also `KHR_mesh_quantization`, `EXT_`/`KHR_meshopt_compression`: gltfpack) | rest pose of the scene | skinning + morph targets sampled at a frame rate |
//! | `.npy` `[F, V, 3]` f32/f64 | | ✓ (triangles from [`AnimationOptions::topology`]) |
//! | `.pc2`, `.mdd` point caches | | ✓ (triangles from [`AnimationOptions::topology`]) |
//!
//! An OBJ whose UVs differ between the corners of a vertex (UV seams) loads with the UVs dropped
//! by [`load_mesh`] (vertex i stays vertex i) or kept by [`load_mesh_split_seams`] (seam
//! vertices split, a map back to the file's vertices).
//!
//! Output: [`write_npy_f32`]; [`write_pc2`], [`write_mdd`]; [`write_glb`] (a [`GlbMesh`] with normals, linear float
//! `COLOR_0` and custom scalar attributes such as `_AO`); [`write_glb_animation`] (frames as
//! morph targets driven by a `STEP` weights clip, read back by [`load_animation`]);
//! [`write_gltf_with`] (the user's own glTF with baked attributes added, everything else kept);
//! [`write_vat_with`] (vertex-animation textures for engine shaders). All writers
//! validate first and write atomically (through [`atomic_out`], whose errors arrive as
//! [`MeshIoError::Io`]).
//!
//! # Examples
//! ```
//! use meshio::{LoadOptions, load_mesh};
//! let dir = tempfile::tempdir().unwrap();
//! let path = dir.path().join("quad.obj");
//! // A quad (fan-triangulated) and one vertex that no face uses.
//! std::fs::write(&path, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 5 5 5\nf 1 2 3 4\n").unwrap();
//! let (mesh, report) = load_mesh(&path, &LoadOptions::default()).unwrap();
//! assert_eq!(mesh.triangles, vec![[0, 1, 2], [0, 2, 3]]);
//! assert_eq!(report.unreferenced_vertices, vec![4]); // reported, kept in place
//! assert_eq!(mesh.normals[0], glam::Vec3::Z); // computed: the file has none
//!
//! let cleaned = LoadOptions { remove_unreferenced: true, ..LoadOptions::default() };
//! let (mesh, report) = load_mesh(&path, &cleaned).unwrap();
//! assert_eq!(mesh.vertex_count(), 4);
//! assert_eq!(report.vertex_remap.unwrap()[4], None);
//! ```

mod error;
mod gltf;
mod materials;
mod normals;
mod npy;
mod obj;
mod options;
mod ply;
mod pointcache;
mod report;
mod text;
mod types;
mod validate;
mod vat;

use std::path::Path;

pub use error::MeshIoError;
pub use gltf::{
    BakeValues, ColourChannel, DoubleSided, GLTF_DECODE_FLOOR, GLTF_DECODE_PER_INPUT_BYTE, GlbClip,
    GlbMesh, GltfBake, GltfBakeReport, MAX_GLB_ANIMATION_FRAMES, MAX_VIEWLESS_ELEMENTS,
    NORMAL_UNIT_TOLERANCE, text_gltf_buffer, write_glb, write_glb_animation,
    write_glb_animation_with, write_gltf_with,
};
pub use materials::{FaceMaterials, load_face_materials};
pub use normals::{CANCELLED_RELATIVE, NormalScratch, compute_normals, compute_normals_into};
pub use npy::{NpyArray, read_npy_f32, write_npy_f32, write_npy_frames};
pub use obj::{SeamSplit, load_mesh_split_seams};
pub use options::{
    AnimationOptions, ClipSelector, DEFAULT_FRAME_RATE, DEFAULT_MAX_FRAMES, LoadOptions,
    MAX_SAMPLED_BYTES, NormalWeighting,
};
pub use pointcache::{write_mdd, write_pc2};
pub use report::{
    AttributeStatus, ClipInfo, DegenerateKind, DegenerateTriangle, LoadReport, SourceFormat,
};
pub use types::{Animation, Mesh};
pub use validate::{
    RepeatedTriangles, ZERO_AREA_RELATIVE, count_duplicate_positions, count_repeated_triangles,
    find_degenerate_triangles, find_unreferenced_vertices,
};
pub use vat::{
    VAT_MAX_HEIGHT, VAT_MAX_WIDTH, VatClip, VatReport, vat_companions, vat_layout, write_vat_with,
};

/// Lower-case extension of `path` (empty when there is none).
fn extension(path: &Path) -> String {
    path.extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default()
}

/// Loads a static triangle mesh from a `.ply`, `.obj`, `.gltf` or `.glb` file (chosen by the
/// extension, case-insensitive).
///
/// Polygons are fan-triangulated, PLY strips decoded; glTF scenes are merged in their rest
/// pose. Normals come from the file when it has consistent per-vertex normals (and
/// `recompute_normals` is off), otherwise they are computed ([`compute_normals`]).
///
/// # Errors
/// [`MeshIoError`] naming the file, the element and the value: unreadable file, unsupported
/// extension, malformed header or number (with line number), header counts larger than the
/// file, truncated data, NaN/inf coordinates, out-of-range indices, faces with fewer than three
/// corners, an empty mesh, an invalid glTF document.
pub fn load_mesh(path: &Path, options: &LoadOptions) -> Result<(Mesh, LoadReport), MeshIoError> {
    match extension(path).as_str() {
        "ply" => ply::load_ply(path, options),
        "obj" => obj::load_obj(path, options),
        "gltf" | "glb" => gltf::load_gltf_mesh(path, options),
        other => Err(MeshIoError::UnsupportedFormat {
            path: path.to_path_buf(),
            extension: other.to_string(),
            expected: "meshes load from .ply, .obj, .gltf or .glb",
        }),
    }
}

/// Loads a mesh animation: a `.glb`/`.gltf` clip, a folder of numbered `.obj` frames, a `.npy`
/// array of shape `[frames, vertices, 3]`, or a single `.ply`/`.obj` mesh as one frame.
///
/// - glTF: the clip chosen by [`AnimationOptions::clip`] sampled at
///   [`AnimationOptions::frame_rate`] (skinning, morph targets, STEP/LINEAR/CUBICSPLINE).
/// - OBJ folder: frames in numeric order of the number in the file name (`2.obj` before
///   `10.obj`); every frame must have frame 0's vertex count and face list.
/// - `.pc2`/`.mdd` point caches: as `.npy` (an MDD's even frame times set the frame rate).
/// - `.npy`: positions only; the triangles come from [`AnimationOptions::topology`]. Without
///   it the animation has no triangles and [`LoadReport::topology_missing`] is set (so that
///   point-only consumers can still use the data; anything needing normals must pass one).
///
/// # Errors
/// As [`load_mesh`], plus: inconsistent frames (naming the first offending file, its frame
/// index and the counts), unknown clip, a clip longer than [`AnimationOptions::max_frames`],
/// a `.npy` of the wrong shape or dtype, a topology mesh with a different vertex count, a
/// non-positive frame rate.
pub fn load_animation(
    path: &Path,
    options: &AnimationOptions,
) -> Result<(Animation, LoadReport), MeshIoError> {
    if path.is_dir() {
        return obj::frames::load_obj_frames(path, options);
    }
    match extension(path).as_str() {
        "gltf" | "glb" => gltf::load_gltf_animation(path, options),
        "npy" => npy::load_npy_animation(path, options),
        "pc2" => pointcache::load_pc2(path, options),
        "mdd" => pointcache::load_mdd(path, options),
        "ply" | "obj" => {
            options.validate(path)?;
            let (mesh, report) = load_mesh(path, &LoadOptions::default())?;
            let animation = Animation {
                triangles: mesh.triangles,
                frames: vec![mesh.positions],
                frame_rate: options.frame_rate,
                uvs: mesh.uvs,
            };
            Ok((animation, report))
        }
        // No maintained Rust crate reads Alembic meshes (ogawa-rs 0.4 parses the container and
        // curves only; the `alembic` crate is a placeholder): say what to export instead.
        "abc" => Err(MeshIoError::UnsupportedFormat {
            path: path.to_path_buf(),
            extension: "abc".to_string(),
            expected: "Alembic is not read here (no maintained Rust reader of its PolyMesh \
                       schema); export the cache as .pc2 or .mdd (Blender, Maya, Houdini and 3ds \
                       Max all write them) with the rest mesh as --topology, or as an animated \
                       .glb or a folder of numbered .obj frames",
        }),
        other => Err(MeshIoError::UnsupportedFormat {
            path: path.to_path_buf(),
            extension: other.to_string(),
            expected: "animations load from .glb, .gltf, .npy, .pc2, .mdd, a folder of numbered .obj frames, or a single .ply/.obj",
        }),
    }
}
