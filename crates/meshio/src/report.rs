//! What a loader found and did: [`LoadReport`].

use std::collections::BTreeMap;
use std::path::PathBuf;

use crate::RepeatedTriangles;

/// The file format that was read.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum SourceFormat {
    /// Not set (a report built by hand).
    #[default]
    Unknown,
    /// PLY, `format ascii`.
    PlyAscii,
    /// PLY, `format binary_little_endian`.
    PlyBinaryLittleEndian,
    /// PLY, `format binary_big_endian`.
    PlyBinaryBigEndian,
    /// Wavefront OBJ.
    Obj,
    /// A folder of numbered OBJ frames.
    ObjFrames,
    /// glTF 2.0 JSON (`.gltf`).
    Gltf,
    /// glTF 2.0 binary container (`.glb`).
    Glb,
    /// NumPy `.npy` array.
    Npy,
    /// PC2 point cache (`.pc2`).
    Pc2,
    /// MDD point cache (`.mdd`).
    Mdd,
}

/// For reports: `binary little-endian PLY`, `OBJ`, `a folder of OBJ frames`, `glTF binary`,
/// `PC2 point cache`, …
impl std::fmt::Display for SourceFormat {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            SourceFormat::Unknown => "unknown format",
            SourceFormat::PlyAscii => "ascii PLY",
            SourceFormat::PlyBinaryLittleEndian => "binary little-endian PLY",
            SourceFormat::PlyBinaryBigEndian => "binary big-endian PLY",
            SourceFormat::Obj => "OBJ",
            SourceFormat::ObjFrames => "a folder of OBJ frames",
            SourceFormat::Gltf => "glTF JSON",
            SourceFormat::Glb => "glTF binary",
            SourceFormat::Npy => "NumPy .npy",
            SourceFormat::Pc2 => "PC2 point cache",
            SourceFormat::Mdd => "MDD point cache",
        })
    }
}

/// Why a triangle is degenerate.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum DegenerateKind {
    /// Two or three corners use the same vertex index.
    RepeatedIndex,
    /// Three distinct vertices whose positions are collinear or coincident (within
    /// [`ZERO_AREA_RELATIVE`](crate::ZERO_AREA_RELATIVE)).
    ZeroArea,
}

/// A degenerate triangle, by its index in the file's triangle list (after polygon and strip
/// triangulation, before any removal).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct DegenerateTriangle {
    /// Index of the triangle.
    pub triangle: u32,
    /// Why it is degenerate.
    pub kind: DegenerateKind,
}

/// What happened to a per-vertex attribute (texture coordinates or normals) of the file.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum AttributeStatus {
    /// The file has none.
    #[default]
    Absent,
    /// Loaded, one value per vertex.
    Loaded,
    /// The file stores the attribute per face corner (OBJ `f v/vt/vn`) and the corners of some
    /// vertex disagree (a UV seam, a hard edge) or lack a value, so no per-vertex attribute
    /// exists without splitting vertices; it was dropped to keep positions in file order.
    DroppedPerCorner {
        /// Vertices whose corners carry different values.
        conflicting_vertices: usize,
        /// Face corners without a value.
        missing_corners: usize,
    },
}

impl std::fmt::Display for AttributeStatus {
    /// `none in the file`, `loaded`, or why it was dropped with its counts, e.g. `dropped: per
    /// face corner, 46 vertices whose corners differ`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Self::Absent => f.write_str("none in the file"),
            Self::Loaded => f.write_str("loaded"),
            Self::DroppedPerCorner {
                conflicting_vertices,
                missing_corners,
            } => {
                f.write_str("dropped: per face corner")?;
                match conflicting_vertices {
                    0 => {}
                    1 => f.write_str(", 1 vertex whose corners differ")?,
                    n => write!(f, ", {n} vertices whose corners differ")?,
                }
                match missing_corners {
                    0 => {}
                    1 => f.write_str(", 1 corner without a value")?,
                    n => write!(f, ", {n} corners without a value")?,
                }
                Ok(())
            }
        }
    }
}

/// The glTF clip that was sampled.
#[derive(Clone, Debug, PartialEq)]
pub struct ClipInfo {
    /// Index in the file's `animations` array.
    pub index: usize,
    /// Its name, if any.
    pub name: Option<String>,
    /// Time of the first keyframe (seconds); frame 0 is sampled here.
    pub start_s: f32,
    /// Time of the last keyframe (seconds).
    pub end_s: f32,
}

/// Everything a loader noticed about the file: counts as written, problems that were reported
/// rather than fixed, and what was changed when the options asked for it.
///
/// For animations the mesh checks (unreferenced, degenerate, duplicates) describe frame 0.
#[derive(Clone, Debug, Default, PartialEq)]
#[non_exhaustive]
pub struct LoadReport {
    /// The file or folder that was read.
    pub source: PathBuf,
    /// Its format.
    pub format: SourceFormat,
    /// Vertices in the file (per frame for animations), before any removal.
    pub file_vertex_count: usize,
    /// Faces as written: PLY `face` rows, OBJ `f` lines, PLY strips, glTF primitives' triangles.
    pub file_face_count: usize,
    /// Triangles after fan and strip triangulation, before any removal.
    pub file_triangle_count: usize,
    /// Faces with more than three corners that were fan-triangulated.
    pub polygons_triangulated: usize,
    /// Vertices referenced by no (kept) triangle, as indices in the file's numbering.
    pub unreferenced_vertices: Vec<u32>,
    /// Degenerate triangles, as indices in the file's triangle list.
    pub degenerate_triangles: Vec<DegenerateTriangle>,
    /// Vertices whose position equals that of an earlier vertex bit for bit (`-0.0 == 0.0`):
    /// vertex count minus the number of distinct positions.
    pub duplicate_positions: usize,
    /// Triangles over the same three vertices as another: repeats and back-to-back pairs
    /// (as written, before any removal).
    pub repeated_triangles: RepeatedTriangles,
    /// True when normals were computed rather than read from the file.
    pub normals_computed: bool,
    /// Normals stored in the file.
    pub file_normals: AttributeStatus,
    /// Texture coordinates stored in the file.
    pub uvs: AttributeStatus,
    /// Unknown or unused line keywords (OBJ `vv`, `t`, `g`, `usemtl` …) with their counts.
    pub skipped_keywords: BTreeMap<String, usize>,
    /// Properties and elements that were read past but not used, e.g. `vertex.confidence`.
    pub skipped_properties: Vec<String>,
    /// Triangles removed (`remove_degenerate`).
    pub removed_triangles: usize,
    /// Vertices removed (`remove_unreferenced`).
    pub removed_vertices: usize,
    /// With `remove_unreferenced`: `vertex_remap[old] = Some(new)`, `None` for removed vertices.
    pub vertex_remap: Option<Vec<Option<u32>>>,
    /// A `.npy` animation was loaded without a topology mesh: it has no triangles.
    pub topology_missing: bool,
    /// The glTF clip that was sampled (`None` for other formats and for a rest pose).
    pub clip: Option<ClipInfo>,
    /// Frame files in frame order (OBJ folders).
    pub frame_files: Vec<PathBuf>,
    /// Anything else worth knowing (ignored files, trailing data, dropped attributes …).
    pub notes: Vec<String>,
}

impl LoadReport {
    /// A report for `source` in `format` with everything else empty.
    pub(crate) fn new(source: &std::path::Path, format: SourceFormat) -> Self {
        Self {
            source: source.to_path_buf(),
            format,
            ..Self::default()
        }
    }

    /// Counts one occurrence of a skipped keyword.
    pub(crate) fn skip_keyword(&mut self, keyword: &[u8]) {
        let key = String::from_utf8_lossy(keyword);
        if let Some(count) = self.skipped_keywords.get_mut(key.as_ref()) {
            *count += 1;
        } else {
            self.skipped_keywords.insert(key.into_owned(), 1);
        }
    }
}
