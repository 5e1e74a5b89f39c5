//! The scene of a glTF file flattened for evaluation: the node hierarchy (rest transforms,
//! parents first), every mesh instance of the scene with its primitives' vertex data, morph
//! targets and skin influences, and the merged triangle list (glTF 2.0 §3.5 "Nodes and
//! hierarchy", §3.7 "Geometry", §3.7.3 "Skins").
//!
//! Instances are merged in scene traversal order (depth first, children in file order); each
//! primitive's vertices follow the previous one's, and its indices are offset accordingly.
//! A mesh instantiated by several nodes is decoded once and shared; each instance charges the
//! decode budget for the merged vertices and triangles it adds, so a small file listing one
//! mesh thousands of times is refused before the merge allocates.

use std::collections::HashMap;
use std::sync::Arc;

use glam::{Mat4, Quat, Vec2, Vec3};
use gltf::Semantic;
use gltf::accessor::Dimensions;
use gltf::mesh::Mode;

use super::accessor::{read_mat4, read_uints, read_vec2, read_vec3, read_vec4};
use super::source::GltfSource;
use crate::MeshIoError;

/// Translation, rotation, scale.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Trs {
    pub translation: Vec3,
    pub rotation: Quat,
    pub scale: Vec3,
}

impl Trs {
    /// `T · R · S` (glTF 2.0 §3.5.3).
    pub(crate) fn matrix(&self) -> Mat4 {
        Mat4::from_scale_rotation_translation(self.scale, self.rotation, self.translation)
    }
}

pub(crate) struct Node {
    pub parent: Option<usize>,
    pub rest: Trs,
    /// The node's local matrix as written (exact for `matrix` nodes).
    pub rest_matrix: Mat4,
    /// Number of morph targets of the node's mesh (0 without a mesh).
    pub morph_targets: usize,
}

/// Skin influences of a primitive: `per_vertex` (joint, weight) pairs per vertex, weights
/// normalised to sum 1 (all zero for a vertex without weights).
pub(crate) struct Influences {
    pub per_vertex: usize,
    pub joints: Vec<u32>,
    pub weights: Vec<f32>,
}

/// Bytes the merged scene holds per vertex an instance adds, charged to the decode budget:
/// positions and normals (12 + 12) and UVs (8) in the rig, and the copies the mesh or animation
/// finish makes of them (positions, normalised normals, UVs: 32).
const MERGED_BYTES_PER_VERTEX: u64 = 64;

/// Bytes the merged scene holds per triangle an instance adds: the rig's list and the copy
/// handed to validation (12 + 12).
const MERGED_BYTES_PER_TRIANGLE: u64 = 24;

/// One primitive as decoded, shared by every instance of its mesh.
struct Decoded {
    primitive: Arc<Primitive>,
    /// Local (unoffset) triangles.
    triangles: Vec<[u32; 3]>,
    uvs: Option<Vec<Vec2>>,
}

/// Decoded meshes by (mesh index, joint count of the instancing node's skin).
type DecodedMeshes = HashMap<(usize, Option<usize>), Arc<Vec<Decoded>>>;

pub(crate) struct Primitive {
    /// Triangles this primitive contributes to the merged list.
    pub triangle_count: usize,
    /// Its material index, if any.
    pub material: Option<usize>,
    pub positions: Vec<Vec3>,
    pub normals: Option<Vec<Vec3>>,
    pub morph_positions: Vec<Vec<Vec3>>,
    pub morph_normals: Vec<Option<Vec<Vec3>>>,
    pub influences: Option<Influences>,
}

pub(crate) struct Instance {
    pub node: usize,
    pub skin: Option<usize>,
    pub primitives: Vec<Arc<Primitive>>,
    pub default_weights: Vec<f32>,
}

pub(crate) struct Skin {
    pub joints: Vec<usize>,
    pub inverse_bind: Vec<Mat4>,
}

pub(crate) struct Rig {
    pub nodes: Vec<Node>,
    /// Node indices, every parent before its children.
    pub order: Vec<usize>,
    pub instances: Vec<Instance>,
    pub skins: Vec<Skin>,
    pub vertex_count: usize,
    pub triangles: Vec<[u32; 3]>,
    /// Per merged triangle, its primitive's material index (`None`: the default material).
    pub triangle_material: Vec<Option<usize>>,
    pub uvs: Option<Vec<Vec2>>,
    /// Every primitive has normals.
    pub has_normals: bool,
    pub primitive_count: usize,
    pub notes: Vec<String>,
}

fn rest_trs(node: &gltf::Node<'_>) -> Trs {
    let (t, r, s) = node.transform().decomposed();
    // A zero or non-finite rotation (e.g. decomposed from a zero-scale matrix) becomes identity.
    let rotation = super::sampler::try_normalize(Quat::from_array(r)).unwrap_or(Quat::IDENTITY);
    Trs {
        translation: Vec3::from_array(t),
        rotation,
        scale: Vec3::from_array(s),
    }
}

impl Rig {
    /// Flattens the default scene (or the first; without scenes, every parentless node).
    pub(crate) fn build(src: &GltfSource) -> Result<Self, MeshIoError> {
        let doc = &src.document;
        let mut nodes: Vec<Node> = doc
            .nodes()
            .map(|n| Node {
                parent: None,
                rest: rest_trs(&n),
                rest_matrix: Mat4::from_cols_array_2d(&n.transform().matrix()),
                morph_targets: n.mesh().map_or(0, |m| {
                    m.primitives().next().map_or(0, |p| p.morph_targets().len())
                }),
            })
            .collect();
        for node in doc.nodes() {
            for child in node.children() {
                if nodes[child.index()].parent.is_some() || child.index() == node.index() {
                    return Err(src.error(
                        format!("node {}", child.index()),
                        "has more than one parent; the hierarchy must be a tree",
                    ));
                }
                nodes[child.index()].parent = Some(node.index());
            }
        }
        let order = parents_first(src, &nodes)?;
        let roots: Vec<usize> = match doc.default_scene().or_else(|| doc.scenes().next()) {
            Some(scene) => scene.nodes().map(|n| n.index()).collect(),
            None => (0..nodes.len())
                .filter(|&i| nodes[i].parent.is_none())
                .collect(),
        };
        let skins = doc
            .skins()
            .map(|skin| read_skin(src, &skin))
            .collect::<Result<Vec<_>, _>>()?;
        let mut rig = Rig {
            nodes,
            order,
            instances: Vec::new(),
            skins,
            vertex_count: 0,
            triangles: Vec::new(),
            triangle_material: Vec::new(),
            uvs: Some(Vec::new()),
            has_normals: true,
            primitive_count: 0,
            notes: Vec::new(),
        };
        let mut stack: Vec<usize> = roots.into_iter().rev().collect();
        let mut decoded = DecodedMeshes::new();
        while let Some(index) = stack.pop() {
            let Some(node) = doc.nodes().nth(index) else {
                continue;
            };
            if let Some(mesh) = node.mesh() {
                rig.add_instance(src, &node, &mesh, &mut decoded)?;
            }
            stack.extend(
                node.children()
                    .map(|c| c.index())
                    .collect::<Vec<_>>()
                    .into_iter()
                    .rev(),
            );
        }
        rig.flip_mirrored_instances();
        Ok(rig)
    }

    fn add_instance(
        &mut self,
        src: &GltfSource,
        node: &gltf::Node<'_>,
        mesh: &gltf::Mesh<'_>,
        decoded: &mut DecodedMeshes,
    ) -> Result<(), MeshIoError> {
        let skin = node.skin().map(|s| s.index());
        let target_count = self.nodes[node.index()].morph_targets;
        let default_weights = match node.weights().or_else(|| mesh.weights()) {
            Some(w) => w.to_vec(),
            None => vec![0.0; target_count],
        };
        if default_weights.len() != target_count {
            return Err(src.error(
                format!("node {} mesh {}", node.index(), mesh.index()),
                format!(
                    "has {} default morph weights for {target_count} morph targets",
                    default_weights.len()
                ),
            ));
        }
        let joint_count = skin.map(|s| self.skins[s].joints.len());
        let parts = match decoded.get(&(mesh.index(), joint_count)) {
            Some(parts) => Arc::clone(parts),
            None => {
                let parts = Arc::new(decode_mesh(src, mesh, joint_count, target_count)?);
                decoded.insert((mesh.index(), joint_count), Arc::clone(&parts));
                parts
            }
        };
        let what = format!("node {} mesh {}", node.index(), mesh.index());
        let vertices: u64 = parts
            .iter()
            .map(|d| d.primitive.positions.len() as u64)
            .sum();
        let triangles: u64 = parts.iter().map(|d| d.triangles.len() as u64).sum();
        src.charge(
            &what,
            vertices
                .saturating_mul(MERGED_BYTES_PER_VERTEX)
                .saturating_add(triangles.saturating_mul(MERGED_BYTES_PER_TRIANGLE)),
        )?;
        let mut primitives = Vec::with_capacity(parts.len());
        for part in parts.iter() {
            let offset = self.vertex_count as u32;
            self.vertex_count += part.primitive.positions.len();
            if u32::try_from(self.vertex_count).is_err() {
                return Err(src.error(&what, "the scene has 2^32 or more vertices in total"));
            }
            self.has_normals &= part.primitive.normals.is_some();
            self.uvs = match (self.uvs.take(), &part.uvs) {
                (Some(mut all), Some(uvs)) => {
                    all.extend_from_slice(uvs);
                    Some(all)
                }
                _ => None,
            };
            self.triangles
                .extend(part.triangles.iter().map(|t| t.map(|i| i + offset)));
            self.triangle_material.extend(std::iter::repeat_n(
                part.primitive.material,
                part.triangles.len(),
            ));
            self.primitive_count += 1;
            primitives.push(Arc::clone(&part.primitive));
        }
        self.instances.push(Instance {
            node: node.index(),
            skin,
            primitives,
            default_weights,
        });
        Ok(())
    }
}

/// Decodes every primitive of `mesh` once, for all the nodes that instantiate it.
fn decode_mesh(
    src: &GltfSource,
    mesh: &gltf::Mesh<'_>,
    joint_count: Option<usize>,
    target_count: usize,
) -> Result<Vec<Decoded>, MeshIoError> {
    let mut parts = Vec::new();
    for primitive in mesh.primitives() {
        let what = format!("mesh {} primitive {}", mesh.index(), primitive.index());
        let (prim, triangles, uvs) = read_primitive(src, &primitive, &what, joint_count)?;
        if prim.morph_positions.len() != target_count {
            return Err(src.error(
                &what,
                format!(
                    "has {} morph targets, the mesh's first primitive {target_count}",
                    prim.morph_positions.len()
                ),
            ));
        }
        parts.push(Decoded {
            primitive: Arc::new(Primitive {
                triangle_count: triangles.len(),
                material: primitive.material().index(),
                ..prim
            }),
            triangles,
            uvs,
        });
    }
    Ok(parts)
}

/// Orders nodes parents first; a node that no root reaches lies on a cycle.
fn parents_first(src: &GltfSource, nodes: &[Node]) -> Result<Vec<usize>, MeshIoError> {
    let mut children = vec![Vec::new(); nodes.len()];
    for (i, node) in nodes.iter().enumerate() {
        if let Some(parent) = node.parent {
            children[parent].push(i);
        }
    }
    let mut order: Vec<usize> = (0..nodes.len())
        .filter(|&i| nodes[i].parent.is_none())
        .collect();
    let mut next = 0;
    while next < order.len() {
        order.extend_from_slice(&children[order[next]]);
        next += 1;
    }
    if order.len() != nodes.len() {
        let mut reached = vec![false; nodes.len()];
        order.iter().for_each(|&i| reached[i] = true);
        let cyclic = reached.iter().position(|r| !r).unwrap_or(0);
        return Err(src.error(
            format!("node {cyclic}"),
            "is part of a cycle in the node hierarchy",
        ));
    }
    Ok(order)
}

fn read_skin(src: &GltfSource, skin: &gltf::Skin<'_>) -> Result<Skin, MeshIoError> {
    let what = format!("skin {}", skin.index());
    let joints: Vec<usize> = skin.joints().map(|j| j.index()).collect();
    let inverse_bind = match skin.inverse_bind_matrices() {
        Some(accessor) => read_mat4(src, &accessor, &what)?,
        None => vec![Mat4::IDENTITY; joints.len()],
    };
    if inverse_bind.len() != joints.len() {
        return Err(src.error(
            &what,
            format!(
                "has {} joints but {} inverse bind matrices",
                joints.len(),
                inverse_bind.len()
            ),
        ));
    }
    if let Some((k, m)) = inverse_bind
        .iter()
        .enumerate()
        .find(|(_, m)| !m.is_finite())
    {
        return Err(src.error(
            &what,
            format!("inverse bind matrix {k} is not finite: {m:?}"),
        ));
    }
    Ok(Skin {
        joints,
        inverse_bind,
    })
}

type PrimitiveParts = (Primitive, Vec<[u32; 3]>, Option<Vec<Vec2>>);

/// Reads one primitive's attributes, triangles (local indices) and UVs.
fn read_primitive(
    src: &GltfSource,
    primitive: &gltf::Primitive<'_>,
    what: &str,
    skin_joints: Option<usize>,
) -> Result<PrimitiveParts, MeshIoError> {
    let accessor = |semantic: Semantic| primitive.get(&semantic);
    let Some(pos) = accessor(Semantic::Positions) else {
        return Err(src.error(what, "has no POSITION attribute"));
    };
    let positions = read_vec3(src, &pos, what)?;
    let n = positions.len();
    let check_len = |len: usize, name: &str| {
        if len == n {
            Ok(())
        } else {
            Err(src.error(what, format!("{name} has {len} entries for {n} positions")))
        }
    };
    let normals = accessor(Semantic::Normals)
        .map(|a| read_vec3(src, &a, what))
        .transpose()?;
    if let Some(normals) = &normals {
        check_len(normals.len(), "NORMAL")?;
    }
    let uvs = accessor(Semantic::TexCoords(0))
        .map(|a| read_vec2(src, &a, what))
        .transpose()?;
    if let Some(uvs) = &uvs {
        check_len(uvs.len(), "TEXCOORD_0")?;
    }
    let mut morph_positions = Vec::new();
    let mut morph_normals = Vec::new();
    for (t, target) in primitive.morph_targets().enumerate() {
        let dp = match target.positions() {
            Some(a) => read_vec3(src, &a, what)?,
            None => {
                // An empty target `{}` is legal; hundreds of them still allocate n each.
                src.charge(what, (n as u64).saturating_mul(12))?;
                vec![Vec3::ZERO; n]
            }
        };
        check_len(dp.len(), &format!("morph target {t} POSITION"))?;
        let dn = target
            .normals()
            .map(|a| read_vec3(src, &a, what))
            .transpose()?;
        if let Some(dn) = &dn {
            check_len(dn.len(), &format!("morph target {t} NORMAL"))?;
        }
        morph_positions.push(dp);
        morph_normals.push(dn);
    }
    let influences = match skin_joints {
        Some(joint_count) => Some(read_influences(src, primitive, what, n, joint_count)?),
        None => None,
    };
    let indices: Vec<u32> = match primitive.indices() {
        Some(a) => read_uints(src, &a, what, Dimensions::Scalar)?,
        None => (0..n as u32).collect(),
    };
    if let Some((k, &i)) = indices.iter().enumerate().find(|(_, i)| **i as usize >= n) {
        return Err(MeshIoError::IndexOutOfRange {
            path: src.path.clone(),
            line: None,
            element: format!("glTF {what} index {k}"),
            index: i64::from(i),
            vertex_count: n,
        });
    }
    let triangles = triangulate(src, primitive.mode(), &indices, what)?;
    let prim = Primitive {
        triangle_count: 0,
        material: None,
        positions,
        normals,
        morph_positions,
        morph_normals,
        influences,
    };
    Ok((prim, triangles, uvs))
}

/// Triangles of a TRIANGLES, TRIANGLE_STRIP or TRIANGLE_FAN primitive (glTF 2.0 §3.7.2.1).
fn triangulate(
    src: &GltfSource,
    mode: Mode,
    idx: &[u32],
    what: &str,
) -> Result<Vec<[u32; 3]>, MeshIoError> {
    Ok(match mode {
        Mode::Triangles => {
            if !idx.len().is_multiple_of(3) {
                return Err(src.error(
                    what,
                    format!(
                        "TRIANGLES primitive has {} indices, not a multiple of 3",
                        idx.len()
                    ),
                ));
            }
            idx.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect()
        }
        // p_i = {v_i, v_{i+(1+i%2)}, v_{i+(2-i%2)}}
        Mode::TriangleStrip => (0..idx.len().saturating_sub(2))
            .map(|i| [idx[i], idx[i + 1 + i % 2], idx[i + 2 - i % 2]])
            .collect(),
        // p_i = {v_{i+1}, v_{i+2}, v_0}
        Mode::TriangleFan => (0..idx.len().saturating_sub(2))
            .map(|i| [idx[i + 1], idx[i + 2], idx[0]])
            .collect(),
        other => {
            return Err(src.error(
                what,
                format!("primitive mode {other:?} has no surface; only TRIANGLES, TRIANGLE_STRIP and TRIANGLE_FAN are loaded. Remove the point/line primitive or export it as triangles"),
            ));
        }
    })
}

/// Reads JOINTS_n / WEIGHTS_n sets, checks joint indices, normalises weights per vertex.
fn read_influences(
    src: &GltfSource,
    primitive: &gltf::Primitive<'_>,
    what: &str,
    n: usize,
    joint_count: usize,
) -> Result<Influences, MeshIoError> {
    let mut sets = Vec::new();
    for set in 0u32.. {
        let (Some(j), Some(w)) = (
            primitive.get(&Semantic::Joints(set)),
            primitive.get(&Semantic::Weights(set)),
        ) else {
            break;
        };
        let joints = read_uints(src, &j, what, Dimensions::Vec4)?;
        let weights = read_vec4(src, &w, what)?;
        if joints.len() != 4 * n || weights.len() != n {
            return Err(src.error(
                what,
                format!("JOINTS_{set}/WEIGHTS_{set} do not have one entry per vertex ({n})"),
            ));
        }
        sets.push((joints, weights));
    }
    if sets.is_empty() {
        return Err(src.error(
            what,
            "belongs to a skinned node but has no JOINTS_0/WEIGHTS_0 attributes",
        ));
    }
    let per_vertex = 4 * sets.len();
    let mut joints = Vec::with_capacity(n * per_vertex);
    let mut weights = Vec::with_capacity(n * per_vertex);
    for v in 0..n {
        let start = weights.len();
        for (set_joints, set_weights) in &sets {
            for k in 0..4 {
                let (joint, weight) = (set_joints[4 * v + k], set_weights[v][k]);
                if !(weight.is_finite() && weight >= 0.0) {
                    return Err(src.error(what, format!("vertex {v} has skin weight {weight}; weights must be finite and non-negative")));
                }
                if weight > 0.0 && joint as usize >= joint_count {
                    return Err(src.error(
                        what,
                        format!(
                            "vertex {v} uses joint {joint}, but the skin has {joint_count} joints"
                        ),
                    ));
                }
                joints.push(joint.min(joint_count.saturating_sub(1) as u32));
                weights.push(weight);
            }
        }
        let sum: f32 = weights[start..].iter().sum();
        if sum > 0.0 {
            weights[start..].iter_mut().for_each(|w| *w /= sum);
        }
    }
    Ok(Influences {
        per_vertex,
        joints,
        weights,
    })
}
