//! Per-face materials: which material each triangle of [`crate::load_mesh`] uses — OBJ
//! `usemtl`, glTF primitive materials — so that one mesh can wear several materials (garment
//! parts, thesis §5.6).

use std::path::Path;

use crate::MeshIoError;

/// The materials of a mesh file and, per triangle, which one it uses.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FaceMaterials {
    /// Material names: OBJ `usemtl` names in order of first use; glTF material names (or
    /// `material N` for an unnamed one), indexed as the file's `materials`.
    pub names: Vec<String>,
    /// Per triangle, in the order of [`crate::load_mesh`] with `remove_degenerate` off (the
    /// default) — also of [`crate::load_mesh_split_seams`] — an index into `names`, or `None`
    /// for a face before any `usemtl` / a primitive without a material.
    pub per_triangle: Vec<Option<u32>>,
}

impl FaceMaterials {
    /// The index of material `name`, if the file has it.
    pub fn index_of(&self, name: &str) -> Option<u32> {
        self.names.iter().position(|n| n == name).map(|i| i as u32)
    }
}

/// Reads the per-face materials of an OBJ or glTF file; `None` for a format without
/// materials (PLY).
///
/// # Errors
/// The loaders' errors for an unreadable or malformed file.
pub fn load_face_materials(path: &Path) -> Result<Option<FaceMaterials>, MeshIoError> {
    match crate::extension(path).as_str() {
        "obj" => {
            let data =
                input_guard::read_regular(path).map_err(|e| MeshIoError::io(path, "read", e))?;
            let mut report = crate::LoadReport::new(path, crate::SourceFormat::Obj);
            let obj = crate::obj::parse_obj(path, &data, &mut report)?;
            Ok(Some(FaceMaterials {
                names: obj.material_names,
                per_triangle: obj
                    .triangle_material
                    .into_iter()
                    .map(|m| (m != crate::obj::NO_INDEX).then_some(m))
                    .collect(),
            }))
        }
        "gltf" | "glb" => crate::gltf::face_materials(path).map(Some),
        _ => Ok(None),
    }
}
