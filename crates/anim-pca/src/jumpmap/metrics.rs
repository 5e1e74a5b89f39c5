//! Quality measures: E(c), E*(c) (thesis §3.2.3, eqs. 3.12–3.13) and measures of a generated
//! sequence (jump distances, velocity discontinuity at transitions, diversity, coverage).

use std::collections::HashSet;

use faer::MatRef;
use glam::Vec3;

use super::JumpMap;
use super::analysis::{fit, flatten, validate_clip, velocities};
use super::player::{Generated, GeneratedFrame};
use super::reconstruct::Reconstructor;
use crate::error::Result;

/// A vertex whose true velocity has ‖v‖² at most this fraction of the clip's largest ‖v‖²
/// (speed ≤ 1 % of the fastest vertex) is left out of E* (eq. 3.13 divides by ‖v‖², which is 0
/// for a vertex at rest); it counts in the 1/N as a zero term. With 1e-10 the chicken
/// sequence's nearly resting vertices put E* in the millions.
pub const VELOCITY_FLOOR: f64 = 1e-4;

/// E(c) and E*(c) for one c (one row of the thesis's Table 3.2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReconstructionError {
    /// Components c (used for both positions and velocities, as in Table 3.2; 0 = mean only).
    pub components: usize,
    /// E(c) (eq. 3.12): Σ_i Σ_n ‖p_in − p̃_in‖² / Σ_n ‖p_in‖² over the interior frames
    /// i = 1 … l−2 (the thesis's 1 … l−1 with frames numbered 0 … l).
    pub position: f64,
    /// E*(c) (eq. 3.13): Σ_i (1/N) Σ_n ‖v_in − ṽ_in‖² / ‖v_in‖², same frames, ṽ from the
    /// velocity PCA with c components; resting vertices skipped (see [`VELOCITY_FLOOR`]).
    pub velocity: f64,
}

/// E(c) and E*(c) (eqs. 3.12, 3.13) for every c in `components`, from one PCA of positions and
/// one of velocities (eq. 3.4, one-sided at the clip ends) with max(c) components.
///
/// # Errors
/// As [`JumpMap::analyze`] for the clip.
pub fn reconstruction_errors(
    positions: &[Vec<Vec3>],
    components: &[usize],
) -> Result<Vec<ReconstructionError>> {
    let n = validate_clip("reconstruction_errors", positions)?;
    let l = positions.len();
    let c_max = components.iter().copied().max().unwrap_or(0).max(1);
    let flat: Vec<f32> = positions
        .iter()
        .flatten()
        .flat_map(|v| v.to_array())
        .collect();
    let a = MatRef::from_row_major_slice(&flat, l, 3 * n);
    let pca = fit(a, c_max)?;
    let w = flatten(&pca.project(a)?);
    let vel = velocities(positions, None, None);
    let va = MatRef::from_row_major_slice(&vel, l, 3 * n);
    let vpca = fit(va, c_max)?;
    let wv = flatten(&vpca.project(va)?);
    let (rec, vrec) = (
        Reconstructor::from_pca(&pca, n, None),
        Reconstructor::from_pca(&vpca, n, None),
    );
    let (c_pos, c_vel) = (pca.n_components(), vpca.n_components());
    let v_max2 = vel
        .chunks_exact(3)
        .map(|v| v.iter().map(|x| f64::from(*x).powi(2)).sum::<f64>())
        .fold(0.0, f64::max);
    let floor = VELOCITY_FLOOR * v_max2;

    let mut buf = vec![Vec3::ZERO; n];
    let mut out = Vec::with_capacity(components.len());
    for &c in components {
        let (mut e, mut ev) = (0.0, 0.0);
        for i in 1..l.saturating_sub(1) {
            let cp = c.min(c_pos);
            rec.reconstruct(&w[i * c_pos..i * c_pos + cp], &mut buf)?;
            let (mut num, mut den) = (0.0, 0.0);
            for (p, q) in positions[i].iter().zip(&buf) {
                num += f64::from((*p - *q).length_squared());
                den += f64::from(p.length_squared());
            }
            if den > 0.0 {
                e += num / den;
            }
            let cv = c.min(c_vel);
            vrec.reconstruct(&wv[i * c_vel..i * c_vel + cv], &mut buf)?;
            let v = &vel[i * 3 * n..(i + 1) * 3 * n];
            let mut sum = 0.0;
            for (vt, q) in v.chunks_exact(3).zip(&buf) {
                let vt = Vec3::new(vt[0], vt[1], vt[2]);
                let v2 = f64::from(vt.length_squared());
                if v2 > floor {
                    sum += f64::from((vt - *q).length_squared()) / v2;
                }
            }
            ev += sum / n as f64;
        }
        out.push(ReconstructionError {
            components: c,
            position: e,
            velocity: ev,
        });
    }
    Ok(out)
}

/// Measures of a generated sequence.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SequenceStats {
    /// Generated frames.
    pub frames: usize,
    /// Transitions taken (j ≠ i + 1).
    pub transitions: usize,
    /// Distinct (i, j) transitions among them.
    pub distinct_transitions: usize,
    /// Fraction of the clip's frames visited as key frames.
    pub coverage: f64,
    /// Mean jump residual ‖Ã_{i+1} − Ã_j‖₂ over the transitions, in units of the clip's mean
    /// frame-to-frame distance d̄ (0 without transitions or for a static clip).
    pub mean_jump_distance: f64,
    /// Largest jump residual, in units of d̄.
    pub max_jump_distance: f64,
}

/// Counts and jump distances of `generated` (played over `map`).
pub fn sequence_stats(map: &JumpMap, generated: &Generated) -> SequenceStats {
    let mut visited = vec![false; map.n_frames()];
    for f in generated.frames.iter().filter(|f| f.is_key()) {
        visited[f.from] = true;
    }
    let distinct: HashSet<(usize, usize)> = generated
        .transitions
        .iter()
        .map(|t| (t.from, t.to))
        .collect();
    let unit = map.mean_frame_distance();
    let rel = |t: &super::Transition| {
        if unit > 0.0 {
            map.jump_residual(t.from, t.to) / unit
        } else {
            0.0
        }
    };
    let k = generated.transitions.len();
    SequenceStats {
        frames: generated.frames.len(),
        transitions: k,
        distinct_transitions: distinct.len(),
        coverage: visited.iter().filter(|v| **v).count() as f64 / visited.len() as f64,
        mean_jump_distance: if k > 0 {
            generated.transitions.iter().map(rel).sum::<f64>() / k as f64
        } else {
            0.0
        },
        max_jump_distance: generated.transitions.iter().map(rel).fold(0.0, f64::max),
    }
}

/// The largest per-vertex velocity change max_n ‖x̃_{t+1,n} − 2x̃_{t,n} + x̃_{t−1,n}‖ over the
/// frames t in `range` of a generated sequence (t needs both neighbours; others are skipped).
pub fn max_velocity_change(
    map: &JumpMap,
    frames: &[GeneratedFrame],
    range: std::ops::Range<usize>,
) -> f64 {
    let start = range.start.max(1);
    let end = range.end.min(frames.len().saturating_sub(1));
    if start >= end {
        return 0.0;
    }
    let rec = map.reconstructor();
    let n = map.n_vertices();
    let mut w = vec![0.0; map.components()];
    let mut bufs = [
        vec![Vec3::ZERO; n],
        vec![Vec3::ZERO; n],
        vec![Vec3::ZERO; n],
    ];
    let mut load = |t: usize, buf: &mut Vec<Vec3>| {
        frames[t].weights_into(map, &mut w);
        // Lengths match by construction.
        let _ = rec.reconstruct(&w, buf);
    };
    load(start - 1, &mut bufs[0]);
    load(start, &mut bufs[1]);
    let mut worst = 0.0f64;
    for t in start..end {
        load(t + 1, &mut bufs[2]);
        for ((a, b), c) in bufs[0].iter().zip(&bufs[1]).zip(&bufs[2]) {
            worst = worst.max(f64::from((*c - 2.0 * *b + *a).length()));
        }
        bufs.rotate_left(1);
    }
    worst
}

/// The clip's own largest per-vertex frame-to-frame velocity change, on the reconstructed key
/// frames 0 … l−1 (the reference for [`transition_velocity_change`]).
pub fn clip_max_velocity_change(map: &JumpMap) -> f64 {
    let keys: Vec<GeneratedFrame> = (0..map.n_frames()).map(GeneratedFrame::key).collect();
    max_velocity_change(map, &keys, 0..keys.len())
}

/// The largest per-vertex velocity change over all transitions of `generated`: for each, the
/// frames from the source key frame to the target key frame (blend frames included).
pub fn transition_velocity_change(map: &JumpMap, generated: &Generated) -> f64 {
    generated
        .transitions
        .iter()
        .map(|t| {
            max_velocity_change(
                map,
                &generated.frames,
                t.index..t.index + t.blend_frames + 2,
            )
        })
        .fold(0.0, f64::max)
}
