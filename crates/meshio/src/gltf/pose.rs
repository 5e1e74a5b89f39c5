//! Evaluating a [`Rig`] in a pose: global node transforms, morph targets, skinning
//! (glTF 2.0 §3.7.3.3 "Joint hierarchy", §3.7.2.2 "Morph targets").
//!
//! - Morphing: `p = p₀ + Σ_t w_t Δp_t` (likewise for normals).
//! - Skinning: joint matrix `J_k = G(joint_k) · IBM_k`, vertex `p' = (Σ_k w_k J_k) p`, with
//!   weights normalised to sum 1. As the specification requires, the skinned mesh node's own
//!   transform is ignored. A skinned vertex whose weights are all zero falls back to the mesh
//!   node's global transform.
//! - Unskinned instances: `p' = G(node) p`.
//!
//! Normals are transformed by the cofactor matrix of the same 3×3 part (the inverse transpose
//! up to a positive factor, valid for non-uniform scale) and normalised.

use glam::{Mat3, Mat4, Vec3};

use super::rig::{Instance, Primitive, Rig};

/// Local transforms of every node and morph weights of every instance.
#[derive(Clone, Debug)]
pub(crate) struct Pose {
    pub locals: Vec<Mat4>,
    pub weights: Vec<Vec<f32>>,
}

/// The normal matrix of `m`: cofactor of its 3×3 part, sign-corrected for mirroring.
fn normal_matrix(m: &Mat4) -> Mat3 {
    let (a, b, c) = (
        m.x_axis.truncate(),
        m.y_axis.truncate(),
        m.z_axis.truncate(),
    );
    let cofactor = Mat3::from_cols(b.cross(c), c.cross(a), a.cross(b));
    if a.dot(b.cross(c)) < 0.0 {
        -cofactor
    } else {
        cofactor
    }
}

impl Rig {
    /// The pose of the file as written: rest transforms, default morph weights.
    pub(crate) fn rest_pose(&self) -> Pose {
        Pose {
            locals: self.nodes.iter().map(|n| n.rest_matrix).collect(),
            weights: self
                .instances
                .iter()
                .map(|i| i.default_weights.clone())
                .collect(),
        }
    }

    /// Global transforms `G(i) = G(parent) · L(i)`.
    pub(crate) fn globals(&self, locals: &[Mat4]) -> Vec<Mat4> {
        let mut globals = vec![Mat4::IDENTITY; self.nodes.len()];
        for &i in &self.order {
            globals[i] = match self.nodes[i].parent {
                Some(parent) => globals[parent] * locals[i],
                None => locals[i],
            };
        }
        globals
    }

    /// Joint matrices of every skin.
    fn joint_matrices(&self, globals: &[Mat4]) -> Vec<Vec<Mat4>> {
        self.skins
            .iter()
            .map(|skin| {
                skin.joints
                    .iter()
                    .zip(&skin.inverse_bind)
                    .map(|(&j, ibm)| globals[j] * *ibm)
                    .collect()
            })
            .collect()
    }

    /// Per-vertex transform of instance `instance`: skin blend, or the node's global matrix.
    fn vertex_matrix(
        instance: &Instance,
        prim: &Primitive,
        joints: &[Vec<Mat4>],
        globals: &[Mat4],
        v: usize,
    ) -> Mat4 {
        let node_matrix = globals[instance.node];
        let (Some(skin), Some(inf)) = (instance.skin, &prim.influences) else {
            return node_matrix;
        };
        let range = v * inf.per_vertex..(v + 1) * inf.per_vertex;
        let mut blended = Mat4::ZERO;
        let mut any = false;
        for (&joint, &weight) in inf.joints[range.clone()].iter().zip(&inf.weights[range]) {
            if weight > 0.0 {
                blended += joints[skin][joint as usize] * weight;
                any = true;
            }
        }
        if any { blended } else { node_matrix }
    }

    /// Positions of all instances in `pose`, merged in rig order.
    pub(crate) fn positions(&self, pose: &Pose) -> Vec<Vec3> {
        let globals = self.globals(&pose.locals);
        let joints = self.joint_matrices(&globals);
        let mut out = Vec::with_capacity(self.vertex_count);
        for (instance, weights) in self.instances.iter().zip(&pose.weights) {
            let active = active_targets(weights);
            for prim in &instance.primitives {
                for (v, &p0) in prim.positions.iter().enumerate() {
                    let p = morph(p0, &prim.morph_positions, &active, v);
                    out.push(
                        Self::vertex_matrix(instance, prim, &joints, &globals, v)
                            .transform_point3(p),
                    );
                }
            }
        }
        out
    }

    /// Normals of all instances in `pose`; `None` unless every primitive has normals.
    pub(crate) fn normals(&self, pose: &Pose) -> Option<Vec<Vec3>> {
        if !self.has_normals {
            return None;
        }
        let globals = self.globals(&pose.locals);
        let joints = self.joint_matrices(&globals);
        let mut out = Vec::with_capacity(self.vertex_count);
        for (instance, weights) in self.instances.iter().zip(&pose.weights) {
            let active = active_targets(weights);
            for prim in &instance.primitives {
                let normals = prim.normals.as_ref()?;
                for (v, &n0) in normals.iter().enumerate() {
                    let mut n = n0;
                    for &(t, w) in &active {
                        if let Some(Some(delta)) = prim.morph_normals.get(t) {
                            n += w * delta[v];
                        }
                    }
                    let m = Self::vertex_matrix(instance, prim, &joints, &globals, v);
                    out.push((normal_matrix(&m) * n).normalize_or_zero());
                }
            }
        }
        Some(out)
    }

    /// Whether the rest pose mirrors an unskinned instance (negative determinant), per
    /// triangle range; used to keep triangles front-facing after the transform.
    pub(crate) fn flip_mirrored_instances(&mut self) {
        let globals = self.globals(&self.rest_pose().locals);
        let mut start = 0usize;
        let mut flips = Vec::new();
        for instance in &self.instances {
            for prim in &instance.primitives {
                let end = start + prim.triangle_count;
                let mirrored =
                    instance.skin.is_none() && globals[instance.node].determinant() < 0.0;
                if mirrored {
                    flips.push(start..end);
                }
                start = end;
            }
        }
        for range in flips {
            for tri in &mut self.triangles[range] {
                tri.swap(1, 2);
            }
        }
    }
}

/// The morph targets with a non-zero weight, in target order: a clip stored as one target per
/// frame has one of thousands active per pose, and skipping the rest keeps sampling linear in
/// the frame count. (A zero weight adds exactly nothing: `p + 0·Δ = p` for finite Δ.)
fn active_targets(weights: &[f32]) -> Vec<(usize, f32)> {
    weights
        .iter()
        .enumerate()
        .filter(|(_, w)| **w != 0.0)
        .map(|(t, w)| (t, *w))
        .collect()
}

fn morph(p0: Vec3, deltas: &[Vec<Vec3>], active: &[(usize, f32)], v: usize) -> Vec3 {
    active
        .iter()
        .filter_map(|&(t, w)| deltas.get(t).map(|d| (d, w)))
        .fold(p0, |p, (delta, w)| p + w * delta[v])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_matrix_handles_non_uniform_scale_and_mirroring() {
        // Scaling x by 2 tilts a 45° normal towards y: n' ∝ (1/2, 1, 0).
        let m = Mat4::from_scale(Vec3::new(2.0, 1.0, 1.0));
        let n = (normal_matrix(&m) * Vec3::new(1.0, 1.0, 0.0)).normalize();
        assert!((n - Vec3::new(0.5, 1.0, 0.0).normalize()).length() < 1e-6);
        // A mirror in x flips the x component of normals only.
        let m = Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0));
        let n = (normal_matrix(&m) * Vec3::new(1.0, 1.0, 0.0)).normalize();
        assert!((n - Vec3::new(-1.0, 1.0, 0.0).normalize()).length() < 1e-6);
    }
}
