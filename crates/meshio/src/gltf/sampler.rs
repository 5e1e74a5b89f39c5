//! Animation clips: channels, keyframe interpolation, and the pose at a time
//! (glTF 2.0 §3.11 "Animations", Appendix C "Animation sampler interpolation modes").
//!
//! - STEP: the value of the last keyframe at or before `t`.
//! - LINEAR: component-wise lerp; rotations use spherical linear interpolation along the
//!   shorter arc, renormalised.
//! - CUBICSPLINE: cubic Hermite with the in/out tangents scaled by the keyframe interval
//!   `t_d`: `p(s) = (2s³−3s²+1)v_k + t_d(s³−2s²+s)b_k + (−2s³+3s²)v_{k+1} + t_d(s³−s²)a_{k+1}`;
//!   rotations are renormalised.
//!
//! Before the first keyframe a channel holds its first value, after the last its last value.

use glam::{Quat, Vec3};
use gltf::animation::{Interpolation, Property};

use super::accessor::read_flat;
use super::pose::Pose;
use super::rig::{Rig, Trs};
use super::source::GltfSource;
use crate::MeshIoError;

/// Above this cosine of the angle between two unit quaternions slerp falls back to a
/// normalised lerp: the sine in the denominator would lose precision (the usual 0.9995).
const SLERP_LERP_THRESHOLD: f32 = 0.9995;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Target {
    Translation,
    Rotation,
    Scale,
    Weights,
}

struct Channel {
    node: usize,
    target: Target,
    interpolation: Interpolation,
    times: Vec<f32>,
    /// Per keyframe: `width` values (× 3 for CUBICSPLINE: in-tangent, value, out-tangent).
    values: Vec<f32>,
    width: usize,
}

/// One animation of the file, ready to sample.
pub(crate) struct Clip {
    channels: Vec<Channel>,
    /// Time of the earliest keyframe (s).
    pub start: f32,
    /// Time of the latest keyframe (s).
    pub end: f32,
}

impl Clip {
    /// Reads and checks every channel of `animation` against the rig.
    pub(crate) fn read(
        src: &GltfSource,
        rig: &Rig,
        animation: &gltf::Animation<'_>,
    ) -> Result<Self, MeshIoError> {
        let mut channels = Vec::new();
        for channel in animation.channels() {
            let what = format!(
                "animation {} channel {}",
                animation.index(),
                channel.index()
            );
            let sampler = channel.sampler();
            let (times, time_components) = read_flat(src, &sampler.input(), &what)?;
            if time_components != 1 {
                return Err(src.error(
                    &what,
                    "sampler input (keyframe times) must be a SCALAR accessor",
                ));
            }
            let (values, _) = read_flat(src, &sampler.output(), &what)?;
            let node = channel.target().node().index();
            let target = match channel.target().property() {
                Property::Translation => Target::Translation,
                Property::Rotation => Target::Rotation,
                Property::Scale => Target::Scale,
                Property::MorphTargetWeights => Target::Weights,
            };
            let interpolation = sampler.interpolation();
            if times.is_empty() {
                return Err(src.error(&what, "has no keyframes"));
            }
            let bad_time = times
                .iter()
                .position(|t| !t.is_finite())
                .or_else(|| times.windows(2).position(|w| w[1] < w[0]));
            if let Some(k) = bad_time {
                return Err(src.error(
                    &what,
                    format!(
                        "keyframe times must be finite and increasing; problem at keyframe {k}"
                    ),
                ));
            }
            if let Some(k) = values.iter().position(|v| !v.is_finite()) {
                return Err(src.error(&what, format!("output value {k} is {}", values[k])));
            }
            let per_key = if interpolation == Interpolation::CubicSpline {
                3
            } else {
                1
            };
            let width = match target {
                Target::Translation | Target::Scale => 3,
                Target::Rotation => 4,
                Target::Weights => rig.nodes[node].morph_targets,
            };
            if values.len() != times.len() * per_key * width {
                return Err(src.error(
                    &what,
                    format!(
                        "has {} output values for {} keyframes of {width} values ({interpolation:?}); expected {}",
                        values.len(),
                        times.len(),
                        times.len() * per_key * width
                    ),
                ));
            }
            channels.push(Channel {
                node,
                target,
                interpolation,
                times,
                values,
                width,
            });
        }
        let start = channels
            .iter()
            .map(|c| c.times[0])
            .fold(f32::INFINITY, f32::min);
        let end = channels
            .iter()
            .map(|c| c.times[c.times.len() - 1])
            .fold(f32::NEG_INFINITY, f32::max);
        let (start, end) = if channels.is_empty() {
            (0.0, 0.0)
        } else {
            (start, end)
        };
        Ok(Self {
            channels,
            start,
            end,
        })
    }

    /// The pose at time `t` (seconds, in the file's time base).
    pub(crate) fn pose(&self, rig: &Rig, t: f32) -> Pose {
        let mut trs: Vec<Trs> = rig.nodes.iter().map(|n| n.rest).collect();
        let mut animated = vec![false; rig.nodes.len()];
        let mut node_weights: Vec<Option<Vec<f32>>> = vec![None; rig.nodes.len()];
        let mut buffer = Vec::new();
        for channel in &self.channels {
            buffer.resize(channel.width, 0.0);
            channel.sample(t, &mut buffer);
            let node = &mut trs[channel.node];
            match channel.target {
                Target::Translation => node.translation = Vec3::from_slice(&buffer),
                Target::Scale => node.scale = Vec3::from_slice(&buffer),
                Target::Rotation => node.rotation = Quat::from_slice(&buffer),
                Target::Weights => node_weights[channel.node] = Some(buffer.clone()),
            }
            animated[channel.node] |= channel.target != Target::Weights;
        }
        let locals = rig
            .nodes
            .iter()
            .zip(&trs)
            .zip(&animated)
            .map(|((node, trs), &animated)| {
                if animated {
                    trs.matrix()
                } else {
                    node.rest_matrix
                }
            })
            .collect();
        let weights = rig
            .instances
            .iter()
            .map(|i| {
                node_weights[i.node]
                    .clone()
                    .unwrap_or_else(|| i.default_weights.clone())
            })
            .collect();
        Pose { locals, weights }
    }
}

impl Channel {
    /// Value `k` (the keyframe value, skipping tangents for CUBICSPLINE).
    fn value(&self, k: usize) -> &[f32] {
        let stride = if self.interpolation == Interpolation::CubicSpline {
            3
        } else {
            1
        };
        let start = (k * stride + stride / 2) * self.width;
        &self.values[start..start + self.width]
    }

    fn sample(&self, t: f32, out: &mut [f32]) {
        let n = self.times.len();
        let after = self.times.partition_point(|&time| time <= t);
        if after == 0 || after >= n {
            out.copy_from_slice(self.value(if after == 0 { 0 } else { n - 1 }));
            return self.finish(out);
        }
        let k = after - 1;
        let dt = self.times[k + 1] - self.times[k];
        let s = if dt > 0.0 {
            (t - self.times[k]) / dt
        } else {
            0.0
        };
        match self.interpolation {
            Interpolation::Step => out.copy_from_slice(self.value(k)),
            Interpolation::Linear if self.target == Target::Rotation => {
                let q = slerp(
                    Quat::from_slice(self.value(k)),
                    Quat::from_slice(self.value(k + 1)),
                    s,
                );
                out.copy_from_slice(&q.to_array());
            }
            Interpolation::Linear => {
                let (a, b) = (self.value(k), self.value(k + 1));
                for (o, (x, y)) in out.iter_mut().zip(a.iter().zip(b)) {
                    *o = x + (y - x) * s;
                }
            }
            Interpolation::CubicSpline => {
                let w = self.width;
                let base0 = 3 * k * w;
                let base1 = 3 * (k + 1) * w;
                let (s2, s3) = (s * s, s * s * s);
                let (h00, h10, h01, h11) = (
                    2.0 * s3 - 3.0 * s2 + 1.0,
                    s3 - 2.0 * s2 + s,
                    -2.0 * s3 + 3.0 * s2,
                    s3 - s2,
                );
                for (c, o) in out.iter_mut().enumerate() {
                    let v0 = self.values[base0 + w + c];
                    let b0 = self.values[base0 + 2 * w + c];
                    let a1 = self.values[base1 + c];
                    let v1 = self.values[base1 + w + c];
                    *o = h00 * v0 + dt * h10 * b0 + h01 * v1 + dt * h11 * a1;
                }
            }
        }
        self.finish(out);
    }

    /// Renormalises rotations (a zero quaternion becomes the identity).
    fn finish(&self, out: &mut [f32]) {
        if self.target == Target::Rotation {
            let q = try_normalize(Quat::from_slice(out)).unwrap_or(Quat::IDENTITY);
            out.copy_from_slice(&q.to_array());
        }
    }
}

/// `q / |q|`, or `None` when `q` is zero or not finite.
pub(crate) fn try_normalize(q: Quat) -> Option<Quat> {
    glam::Vec4::from(q).try_normalize().map(Quat::from_vec4)
}

/// Spherical linear interpolation along the shorter arc, renormalised.
pub(crate) fn slerp(a: Quat, b: Quat, s: f32) -> Quat {
    let (a, mut b) = (a.normalize(), b.normalize());
    let mut cos = a.dot(b);
    if cos < 0.0 {
        b = -b;
        cos = -cos;
    }
    if cos > SLERP_LERP_THRESHOLD {
        return (a + (b - a) * s).normalize();
    }
    let theta = cos.clamp(-1.0, 1.0).acos();
    let sin = theta.sin();
    (a * (((1.0 - s) * theta).sin() / sin) + b * ((s * theta).sin() / sin)).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slerp_halfway_between_identity_and_quarter_turn_is_eighth_turn() {
        let q = slerp(
            Quat::IDENTITY,
            Quat::from_rotation_z(std::f32::consts::FRAC_PI_2),
            0.5,
        );
        let expected = Quat::from_rotation_z(std::f32::consts::FRAC_PI_4);
        assert!(q.dot(expected).abs() > 1.0 - 1e-6);
    }

    #[test]
    fn slerp_takes_the_shorter_arc() {
        // -q is the same rotation as q: the halfway point must equal the endpoints.
        let q = Quat::from_rotation_y(0.3);
        let mid = slerp(q, -q, 0.5);
        assert!(mid.dot(q).abs() > 1.0 - 1e-6);
    }
}
