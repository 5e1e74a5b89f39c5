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
/// frames 0 … l−1 of every cell (the reference for [`transition_velocity_change`]).
pub fn clip_max_velocity_change(map: &JumpMap) -> f64 {
    (0..map.n_cells())
        .map(|cell| {
            let keys: Vec<GeneratedFrame> = map.cell_range(cell).map(GeneratedFrame::key).collect();
            max_velocity_change(map, &keys, 0..keys.len())
        })
        .fold(0.0, f64::max)
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

/// Bytes of one stored float: frames, eigenframes and weights are all counted as f32 (the
/// weights are f64 inside [`JumpMap`], but f32 is what a compressed file or a GPU buffer would
/// hold, and the frames themselves come in as f32).
pub const BYTES_PER_FLOAT: u64 = 4;

/// What one frame vector A_i holds, for [`compression_ratio`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FrameContents {
    /// Positions only, 3N floats: the frame vectors of [`JumpMap::analyze`].
    Positions,
    /// Positions and normals, 6N floats: the frame vectors of
    /// [`JumpMap::analyze_with_normals`] and of the thesis (§3.2.2: "the vertex normals are
    /// also included in the vectors A_i").
    PositionsAndNormals,
}

impl FrameContents {
    /// Floats per vertex in A_i (3 or 6).
    pub fn floats_per_vertex(self) -> u64 {
        match self {
            Self::Positions => 3,
            Self::PositionsAndNormals => 6,
        }
    }
}

/// Storage of a clip and of its PCA representation with c components: one row of the thesis's
/// Table 3.1 (see [`compression_ratio`] for what is counted).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Compression {
    /// Components c (0 = the mean frame only).
    pub components: usize,
    /// What each frame vector holds.
    pub contents: FrameContents,
    /// The raw clip: l · N · (3 or 6) f32.
    pub raw_bytes: u64,
    /// The PCA representation: (1 + c) · N · (3 or 6) f32 for the mean and the eigenframes,
    /// plus l · c f32 weights.
    pub pca_bytes: u64,
}

impl Compression {
    /// r of the ratio 1:r, raw over PCA bytes (the thesis prints 1:15 for r = 15).
    pub fn ratio(&self) -> f64 {
        self.raw_bytes as f64 / self.pca_bytes as f64
    }

    /// The raw clip in MB (10⁶ bytes; the thesis does not say which megabyte it uses).
    pub fn raw_megabytes(&self) -> f64 {
        self.raw_bytes as f64 / 1e6
    }

    /// The PCA representation in MB (10⁶ bytes).
    pub fn pca_megabytes(&self) -> f64 {
        self.pca_bytes as f64 / 1e6
    }
}

/// Compression of a clip of `frames` frames of `vertices` vertices by a PCA with `components`
/// eigenframes (the thesis's Table 3.1, "PCA Compression Ratio", §3.2.3).
///
/// Counted, all as f32 ([`BYTES_PER_FLOAT`]):
/// * raw: l · N · k floats, k = 3 for positions, 6 for positions and normals
///   ([`FrameContents`]);
/// * PCA: the mean frame F_0 and c eigenframes F_1 … F_c of N · k floats each (eq. 3.1), and
///   l · c weights.
///
/// Not counted, in either: the connectivity and texture coordinates (the same in both, and
/// the thesis's conclusion lists them separately), the velocity PCA and the jump map (needed
/// for playback, not for reconstruction), any file header.
///
/// The thesis's Table 3.1 does not say what it counts. Its A_i hold positions and normals,
/// so [`FrameContents::PositionsAndNormals`] is the like-for-like row. Its figures do not
/// follow from a fixed cost per eigenframe: one avatar frame is 138 MB / 115 = 1.2 MB, so
/// c = 1 … 10 should add 9 · 1.2 = 10.8 MB, yet the column grows by 6.6 MB (and by 0.6 MB
/// from c = 2 to 4). Only the order of magnitude of its ratios can be compared.
///
/// # Errors
/// [`AnimPcaError::EmptyClip`](crate::AnimPcaError::EmptyClip) for no frames or no vertices;
/// [`AnimPcaError::InvalidParameter`](crate::AnimPcaError::InvalidParameter) when c exceeds
/// what a PCA of the clip can have (l − 1 components after centring, and at most the N · k
/// dimensions of A_i), or when the byte counts overflow u64.
///
/// # Examples
/// ```
/// use anim_pca::jumpmap::metrics::{FrameContents, compression_ratio};
/// // 100 frames of 1,000 vertices, positions only, c = 4:
/// // raw 100·1000·3·4 B = 1.2 MB; PCA (1 + 4)·1000·3·4 + 100·4·4 B = 61,600 B.
/// let row = compression_ratio(100, 1000, 4, FrameContents::Positions).unwrap();
/// assert_eq!((row.raw_bytes, row.pca_bytes), (1_200_000, 61_600));
/// assert!((row.ratio() - 19.48).abs() < 0.01);
/// ```
pub fn compression_ratio(
    frames: usize,
    vertices: usize,
    components: usize,
    contents: FrameContents,
) -> Result<Compression> {
    const WHAT: &str = "compression_ratio";
    if frames == 0 || vertices == 0 {
        return Err(crate::AnimPcaError::EmptyClip {
            what: WHAT,
            frames,
            vertices,
        });
    }
    let overflow = || {
        crate::error::invalid(
            WHAT,
            "vertices",
            vertices,
            "the clip's size in bytes overflows u64",
        )
    };
    let (l, n, c) = (frames as u64, vertices as u64, components as u64);
    let frame_floats = n
        .checked_mul(contents.floats_per_vertex())
        .ok_or_else(overflow)?;
    if c > l - 1 || c > frame_floats {
        return Err(crate::error::invalid(
            WHAT,
            "components",
            components,
            "c must be ≤ l − 1 and ≤ the floats per frame: a PCA of l frames has at most \
             l − 1 components",
        ));
    }
    let bytes = |floats: Option<u64>| {
        floats
            .and_then(|f| f.checked_mul(BYTES_PER_FLOAT))
            .ok_or_else(overflow)
    };
    let raw_bytes = bytes(l.checked_mul(frame_floats))?;
    let pca_bytes = bytes(
        (c + 1)
            .checked_mul(frame_floats)
            .and_then(|f| f.checked_add(l * c)),
    )?;
    Ok(Compression {
        components,
        contents,
        raw_bytes,
        pca_bytes,
    })
}

/// [`compression_ratio`] of an analysed clip with the components it kept
/// ([`JumpMap::components`]), counting normals when it was analysed with them.
///
/// # Panics
/// Never for a map built by [`JumpMap::analyze`] or [`JumpMap::analyze_with_normals`].
pub fn map_compression(map: &JumpMap) -> Compression {
    let contents = if map.reconstructor().has_normals() {
        FrameContents::PositionsAndNormals
    } else {
        FrameContents::Positions
    };
    // A map's clip has ≥ 2 frames and ≥ 1 vertex, it kept c ≤ l − 1 components, and its
    // frames were held in memory, so their byte count fits in u64: an error is a bug here.
    compression_ratio(map.n_frames(), map.n_vertices(), map.components(), contents)
        .expect("an analysed clip is non-empty, has c ≤ l − 1 and fits in memory")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{AnimPcaError, JumpMapParams};

    #[test]
    fn compression_matches_a_hand_count() {
        // 100 frames × 1,000 vertices × 3 floats × 4 B = 1,200,000 B; c = 4: the mean and four
        // eigenframes of 3,000 floats (60,000 B) and 100 × 4 weights (1,600 B).
        let row = compression_ratio(100, 1000, 4, FrameContents::Positions).unwrap();
        assert_eq!((row.raw_bytes, row.pca_bytes), (1_200_000, 61_600));
        assert!((row.ratio() - 1_200_000.0 / 61_600.0).abs() < 1e-12);
        assert!((row.raw_megabytes() - 1.2).abs() < 1e-12);
        // Normals double the frame vector but not the weights: 2,400,000 B against
        // 5 × 6,000 × 4 + 1,600 = 121,600 B.
        let row = compression_ratio(100, 1000, 4, FrameContents::PositionsAndNormals).unwrap();
        assert_eq!((row.raw_bytes, row.pca_bytes), (2_400_000, 121_600));
        // c = 0 keeps only the mean frame: the ratio is l.
        let row = compression_ratio(100, 1000, 0, FrameContents::Positions).unwrap();
        assert_eq!(row.pca_bytes, 12_000);
        assert_eq!(row.ratio(), 100.0);
    }

    #[test]
    fn each_component_costs_one_frame_plus_a_weight_per_frame_and_lowers_the_ratio() {
        for (l, n) in [(25, 8431), (170, 3030), (2, 1), (40, 7)] {
            for contents in [FrameContents::Positions, FrameContents::PositionsAndNormals] {
                let k = contents.floats_per_vertex();
                let rows: Vec<Compression> = (0..l)
                    .map(|c| compression_ratio(l, n, c, contents))
                    .take_while(|r| r.is_ok())
                    .map(Result::unwrap)
                    .collect();
                assert_eq!(rows.len(), l.min(n * k as usize + 1), "l = {l}, N = {n}");
                for w in rows.windows(2) {
                    assert_eq!(
                        w[1].pca_bytes - w[0].pca_bytes,
                        (n as u64 * k + l as u64) * BYTES_PER_FLOAT
                    );
                    assert_eq!(w[1].raw_bytes, w[0].raw_bytes);
                    assert!(w[1].ratio() < w[0].ratio(), "l = {l}, N = {n}: {w:?}");
                }
            }
        }
    }

    #[test]
    fn compression_refuses_an_empty_clip_and_more_components_than_frames() {
        assert!(matches!(
            compression_ratio(0, 10, 0, FrameContents::Positions),
            Err(AnimPcaError::EmptyClip { frames: 0, .. })
        ));
        assert!(matches!(
            compression_ratio(10, 0, 0, FrameContents::Positions),
            Err(AnimPcaError::EmptyClip { vertices: 0, .. })
        ));
        let e = compression_ratio(10, 100, 10, FrameContents::Positions).unwrap_err();
        assert!(e.to_string().contains("components"), "{e}");
        assert!(e.to_string().contains("10"), "{e}");
        let e = compression_ratio(usize::MAX, usize::MAX, 1, FrameContents::Positions);
        assert!(e.unwrap_err().to_string().contains("overflow"));
    }

    /// A 6 × 6 grid waving with a 9-frame period, 30 frames.
    fn wave() -> Vec<Vec<Vec3>> {
        (0..30)
            .map(|t| {
                let ph = t as f32 / 9.0 * std::f32::consts::TAU;
                (0..36)
                    .map(|n| {
                        let (x, y) = ((n % 6) as f32, (n / 6) as f32);
                        Vec3::new(x, y, (ph + 0.5 * x).sin() + 0.3 * (2.0 * ph + y).cos())
                    })
                    .collect()
            })
            .collect()
    }

    #[test]
    fn map_compression_counts_the_arrays_the_map_holds() {
        let clip = wave();
        let normals: Vec<Vec<Vec3>> = clip
            .iter()
            .map(|f| {
                f.iter()
                    .map(|p| Vec3::new(p.z, 0.3, 1.0).normalize())
                    .collect()
            })
            .collect();
        let params = JumpMapParams {
            components: 3,
            ..JumpMapParams::default()
        };
        for (map, contents) in [
            (
                JumpMap::analyze(&clip, &params).unwrap(),
                FrameContents::Positions,
            ),
            (
                JumpMap::analyze_with_normals(&clip, &normals, &params).unwrap(),
                FrameContents::PositionsAndNormals,
            ),
        ] {
            let row = map_compression(&map);
            assert_eq!(row.contents, contents);
            assert_eq!(row.components, 3);
            // Raw: the clip's own f32 storage (normals are as large as positions).
            let per_frame = 36 * std::mem::size_of::<Vec3>() as u64;
            let raw = 30 * per_frame * contents.floats_per_vertex() / 3;
            assert_eq!(row.raw_bytes, raw);
            // PCA: the mean and c eigenframes the map's PCA holds, and its l × c weights, as f32.
            let pca = map.pca();
            let floats = pca.mean().len()
                + (0..map.components())
                    .map(|k| pca.component(k).len())
                    .sum::<usize>()
                + map.n_frames() * map.weights(0).len();
            assert_eq!(row.pca_bytes, floats as u64 * BYTES_PER_FLOAT);
        }
    }
}
