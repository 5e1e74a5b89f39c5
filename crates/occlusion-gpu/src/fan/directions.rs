//! The directions of fans: grouped into compact cones on the sphere ([`fan_groups`]), and a
//! fixed set (the lightsphere's) prepared once with its reciprocals and packed per vertex to
//! the directions above its tangent plane ([`PreparedDirections`], [`Packed`]).

use glam::{Vec3, Vec4};

#[cfg(target_arch = "x86_64")]
use super::avx2;
use super::{FAN_GROUP, FAN_SIZE, has_avx2, reciprocal};

/// Directions with their [`reciprocal`]s, ready to be packed into fans many times
/// ([`PreparedDirections::compact`], [`RayFan::fill`](crate::RayFan::fill)): the
/// lightsphere's, shared by every vertex.
pub(crate) struct PreparedDirections {
    /// Directions, four per vector (padded with zeros to a multiple of eight).
    pub(crate) xyz: [Vec<Vec4>; 3],
    /// Their reciprocals, likewise.
    pub(crate) inv: [Vec<Vec4>; 3],
    /// Number of directions.
    pub(crate) len: usize,
    /// Whether the CPU runs AVX2 (the eight-lane [`PreparedDirections::compact`]).
    pub(super) wide: bool,
}

/// One vertex's facing directions with their reciprocals, packed in order
/// ([`PreparedDirections::compact`]): the lanes of its fans, [`FAN_SIZE`] at a time.
#[derive(Default)]
pub(crate) struct Packed {
    /// x, y, z, then the reciprocals' x, y, z; each with room for eight more.
    pub(super) lanes: [Vec<f32>; 6],
    /// The index in [`PreparedDirections`] of each packed direction.
    pub(crate) index: Vec<u32>,
    /// Number of packed directions.
    pub(crate) len: usize,
}

impl PreparedDirections {
    pub(crate) fn new(directions: &[Vec3]) -> Self {
        let quads = 2 * directions.len().div_ceil(8);
        let xyz = [0, 1, 2].map(|k| {
            let mut coordinate = vec![Vec4::ZERO; quads];
            let flat: &mut [f32] = bytemuck::cast_slice_mut(&mut coordinate);
            for (f, d) in flat.iter_mut().zip(directions) {
                *f = d[k];
            }
            coordinate
        });
        let inv = [0, 1, 2].map(|k| xyz[k].iter().map(|&v| reciprocal(v)).collect());
        Self {
            xyz,
            inv,
            len: directions.len(),
            wide: has_avx2(),
        }
    }

    /// Bit i of word i / 64: direction i has d·`normal` > 0 (the same sum, in the same order,
    /// as `Vec3::dot`).
    pub(crate) fn facing(&self, normal: Vec3, words: &mut Vec<u64>) {
        words.clear();
        words.resize(self.len.div_ceil(64), 0);
        for (q, ((x, y), z)) in self.xyz[0]
            .iter()
            .zip(&self.xyz[1])
            .zip(&self.xyz[2])
            .enumerate()
        {
            let dot = *x * normal.x + *y * normal.y + *z * normal.z;
            words[q / 16] |= u64::from(dot.cmpgt(Vec4::ZERO).bitmask()) << (4 * (q % 16));
        }
    }

    /// Packs the directions whose bit is set in `words` ([`PreparedDirections::facing`]), in
    /// order, into `out`: eight at a time with AVX2 (one permute per coordinate), one at a
    /// time otherwise. Pushing them lane by lane took 5 % of the bunny's time at k = 258.
    pub(crate) fn compact(&self, words: &[u64], out: &mut Packed) {
        let blocks = self.len.div_ceil(8);
        for lanes in &mut out.lanes {
            lanes.resize(8 * blocks + 8, 0.0);
        }
        out.index.resize(8 * blocks + 8, 0);
        let [x, y, z] = &self.xyz;
        let [ix, iy, iz] = &self.inv;
        let sources: [&[f32]; 6] = [x, y, z, ix, iy, iz].map(|v| bytemuck::cast_slice(v));
        #[cfg(target_arch = "x86_64")]
        if self.wide {
            // SAFETY: `wide` is set only where the CPU runs AVX2.
            #[allow(unsafe_code)]
            unsafe {
                avx2::compact(&sources, words, blocks, out);
            }
            return;
        }
        let mut len = 0;
        for b in 0..blocks {
            let bits = (words[b / 8] >> (8 * (b % 8))) as u8;
            for j in 0..8 {
                for (lanes, source) in out.lanes.iter_mut().zip(&sources) {
                    lanes[len] = source[8 * b + j];
                }
                out.index[len] = (8 * b + j) as u32;
                len += usize::from(bits >> j & 1);
            }
        }
        out.len = len;
    }
}

/// Directions split into fans: groups of at most [`FAN_GROUP`] close directions (one SIMD
/// vector of the traversal), halved recursively at the median of the widest coordinate so
/// each group is a compact cone, and [`FAN_SIZE`] / [`FAN_GROUP`] neighbouring groups per
/// fan. Each fan is the list of its lanes' indices into `directions`, `u32::MAX` marking the
/// unused lanes at the end of a short group; push them in order, calling
/// [`RayFan::finish_group`](crate::RayFan::finish_group) after every [`FAN_GROUP`] lanes.
/// Deterministic.
pub fn fan_groups(directions: &[Vec3]) -> Vec<Vec<u32>> {
    fn split(directions: &[Vec3], mut indices: Vec<u32>, out: &mut Vec<Vec<u32>>) {
        if indices.len() <= FAN_GROUP {
            out.push(indices);
            return;
        }
        let (lo, hi) = indices
            .iter()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| {
                let d = directions[p as usize];
                (lo.min(d), hi.max(d))
            });
        let axis = (hi - lo).max_position();
        // Split into whole groups where possible, so no group is left nearly empty.
        let groups = indices.len().div_ceil(FAN_GROUP);
        let cut = groups.div_ceil(2) * indices.len() / groups;
        // A partition at the cut, not a sort: O(n) per level (HC 1024² has 3 M pixels).
        indices.select_nth_unstable_by(cut, |&a, &b| {
            directions[a as usize][axis].total_cmp(&directions[b as usize][axis])
        });
        let right = indices.split_off(cut);
        split(directions, indices, out);
        split(directions, right, out);
    }
    let mut groups = Vec::new();
    split(
        directions,
        (0..directions.len() as u32).collect(),
        &mut groups,
    );
    groups
        .chunks(FAN_SIZE / FAN_GROUP)
        .map(|fan| {
            fan.iter()
                .flat_map(|group| {
                    let pad = FAN_GROUP - group.len();
                    group
                        .iter()
                        .copied()
                        .chain(std::iter::repeat_n(u32::MAX, pad))
                })
                .collect()
        })
        .collect()
}
