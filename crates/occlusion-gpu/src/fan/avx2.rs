//! The fan traversal eight lanes at a time (AVX2), chosen at run time where the CPU has it.
//!
//! The same traversal as the SSE path of [`FanTracer`] — the same nodes in the same order,
//! the same slab and common-origin triangle formulas with the same operand order and no
//! fused multiply-add — so every lane's answer is bit for bit the SSE path's (a unit test
//! compares them); only the width of a group changes: a fan's 64 lanes are 8 groups of 8
//! instead of 16 groups of 4, halving the per-group loops.

use std::arch::x86_64::{
    __m256, __m256i, _CMP_GE_OS, _CMP_GT_OS, _CMP_LE_OS, _CMP_LT_OS, _mm256_add_epi32,
    _mm256_add_ps, _mm256_and_ps, _mm256_andnot_ps, _mm256_cmp_ps, _mm256_max_ps, _mm256_min_ps,
    _mm256_movemask_ps, _mm256_mul_ps, _mm256_or_ps, _mm256_permutevar8x32_ps, _mm256_set1_epi32,
    _mm256_set1_ps, _mm256_setzero_ps,
};

use glam::{Vec3A, Vec4};

use super::{
    ALONE, FanNode, FanSetup, FanTracer, FanTriangle, GROUPS, Packed, RayFan, Stacks, lanes_alone,
    live_wide,
};
use crate::cpu::EDGE_TOLERANCE;

/// Lanes per AVX2 group.
const WIDE: usize = 8;
/// Groups of eight lanes per fan.
const WIDE_GROUPS: usize = super::FAN_SIZE / WIDE;

/// Eight-lane groups of one coordinate (`[Vec4; 16]` seen as `[[f32; 8]; 8]`).
fn widen(lanes: &[Vec4; GROUPS]) -> [__m256; WIDE_GROUPS] {
    let wide: &[[f32; WIDE]; WIDE_GROUPS] = bytemuck::cast_ref(lanes);
    wide.map(bytemuck::cast)
}

/// A fan's directions and reciprocals as eight-lane vectors, and its whole-fan interval.
struct WideFan<'a> {
    x: [__m256; WIDE_GROUPS],
    y: [__m256; WIDE_GROUPS],
    z: [__m256; WIDE_GROUPS],
    ix: [__m256; WIDE_GROUPS],
    iy: [__m256; WIDE_GROUPS],
    iz: [__m256; WIDE_GROUPS],
    setup: &'a FanSetup,
}

/// The SSE path's `traverse`, eight lanes at a time.
#[target_feature(enable = "avx2")]
pub(super) fn traverse<const BOUNDED: bool>(
    tracer: &FanTracer,
    origin: Vec3A,
    fan: &RayFan,
    mask: u64,
    max_t: f32,
    stacks: &mut Stacks,
) -> u64 {
    let mask = mask & fan.full_mask();
    if tracer.nodes.is_empty() || mask == 0 {
        return mask;
    }
    let setup = FanSetup::new(fan, mask);
    let wide = WideFan {
        x: widen(&fan.x),
        y: widen(&fan.y),
        z: widen(&fan.z),
        ix: widen(&fan.ix),
        iy: widen(&fan.iy),
        iz: widen(&fan.iz),
        setup: &setup,
    };
    let mut visible = mask;
    let Stacks { fan: stack, single } = stacks;
    stack.clear();
    let root = box_lanes::<BOUNDED>(tracer.node(tracer.root), origin, &wide, mask, max_t);
    if root != 0 {
        stack.push((tracer.root, root));
    }
    while let Some((index, m)) = stack.pop() {
        let mut m = m & visible;
        if m == 0 {
            continue;
        }
        if tracer.single && m.count_ones() <= ALONE {
            visible &= !lanes_alone::<BOUNDED>(tracer, index, origin, fan, m, max_t, single);
            if visible == 0 {
                return 0;
            }
            continue;
        }
        let node = tracer.node(index);
        if node.prim_count > 0 {
            let first = node.first_index as usize;
            for t in &tracer.triangles[first..first + node.prim_count as usize] {
                let hit = triangle_lanes::<BOUNDED>(t, origin, &wide, m, max_t);
                visible &= !hit;
                m &= !hit;
                if m == 0 {
                    break;
                }
            }
            if visible == 0 {
                return 0;
            }
        } else {
            let first = node.first_index;
            let (a, b) = (tracer.node(first), tracer.node(first + 1));
            let distance = |n: &FanNode| (n.min + n.max - 2.0 * origin).length_squared();
            let order = if distance(a) <= distance(b) {
                [(first + 1, b), (first, a)]
            } else {
                [(first, a), (first + 1, b)]
            };
            for (child, node) in order {
                stack.push((child, box_lanes::<BOUNDED>(node, origin, &wide, m, max_t)));
            }
        }
    }
    visible
}

/// The lanes of `mask` whose rays enter `node`'s box before `max_t` (the SSE path's
/// `box_lanes`, eight lanes per group).
#[target_feature(enable = "avx2")]
#[inline]
fn box_lanes<const BOUNDED: bool>(
    node: &FanNode,
    origin: Vec3A,
    fan: &WideFan<'_>,
    mask: u64,
    max_t: f32,
) -> u64 {
    let low = node.min - origin;
    let high = node.max - origin;
    if low.cmple(Vec3A::ZERO).all() && high.cmpge(Vec3A::ZERO).all() {
        return mask;
    }
    let inv = fan.setup;
    if inv.interval {
        let (pa, pc) = (low * inv.bound_lo, low * inv.bound_hi);
        let (qa, qc) = (high * inv.bound_lo, high * inv.bound_hi);
        let enter = Vec3A::select(inv.bounded, pa.min(pc).min(qa.min(qc)), Vec3A::NEG_INFINITY);
        let leave = Vec3A::select(inv.bounded, pa.max(pc).max(qa.max(qc)), Vec3A::INFINITY);
        if enter.max_element().max(0.0) > leave.min_element().min(max_t) {
            return 0;
        }
    }
    let (lx, ly, lz) = (
        _mm256_set1_ps(low.x),
        _mm256_set1_ps(low.y),
        _mm256_set1_ps(low.z),
    );
    let (hx, hy, hz) = (
        _mm256_set1_ps(high.x),
        _mm256_set1_ps(high.y),
        _mm256_set1_ps(high.z),
    );
    let far = _mm256_set1_ps(max_t);
    let zero = _mm256_setzero_ps();
    let sliced = node.half.is_finite();
    let (nx, ny, nz) = (
        _mm256_set1_ps(node.normal.x),
        _mm256_set1_ps(node.normal.y),
        _mm256_set1_ps(node.normal.z),
    );
    let s0 = _mm256_set1_ps(node.normal.dot(origin) - node.centre);
    let (half, minus_half) = (_mm256_set1_ps(node.half), _mm256_set1_ps(-node.half));
    let mut out = 0u64;
    let mut live = live_wide(mask);
    while live != 0 {
        let g = live.trailing_zeros() as usize / WIDE;
        live &= live - 1;
        let (x1, x2) = (_mm256_mul_ps(lx, fan.ix[g]), _mm256_mul_ps(hx, fan.ix[g]));
        let (y1, y2) = (_mm256_mul_ps(ly, fan.iy[g]), _mm256_mul_ps(hy, fan.iy[g]));
        let (z1, z2) = (_mm256_mul_ps(lz, fan.iz[g]), _mm256_mul_ps(hz, fan.iz[g]));
        let enter = _mm256_max_ps(
            _mm256_max_ps(_mm256_min_ps(x1, x2), _mm256_min_ps(y1, y2)),
            _mm256_max_ps(_mm256_min_ps(z1, z2), zero),
        );
        let leave = _mm256_min_ps(
            _mm256_min_ps(_mm256_max_ps(x1, x2), _mm256_max_ps(y1, y2)),
            _mm256_max_ps(z1, z2),
        );
        let leave = if BOUNDED {
            _mm256_min_ps(leave, far)
        } else {
            leave
        };
        let mut inside = _mm256_cmp_ps::<_CMP_LE_OS>(enter, leave);
        if sliced {
            // The signed distance to the slab's mid-plane where the ray enters and leaves the
            // box: a lane is out when both ends lie beyond the same face.
            let along = _mm256_add_ps(
                _mm256_add_ps(_mm256_mul_ps(fan.x[g], nx), _mm256_mul_ps(fan.y[g], ny)),
                _mm256_mul_ps(fan.z[g], nz),
            );
            let (a, b) = (
                _mm256_add_ps(s0, _mm256_mul_ps(enter, along)),
                _mm256_add_ps(s0, _mm256_mul_ps(leave, along)),
            );
            let above = _mm256_and_ps(
                _mm256_cmp_ps::<_CMP_GT_OS>(a, half),
                _mm256_cmp_ps::<_CMP_GT_OS>(b, half),
            );
            let below = _mm256_and_ps(
                _mm256_cmp_ps::<_CMP_LT_OS>(a, minus_half),
                _mm256_cmp_ps::<_CMP_LT_OS>(b, minus_half),
            );
            inside = _mm256_andnot_ps(_mm256_or_ps(above, below), inside);
        }
        let bits = _mm256_movemask_ps(inside);
        out |= u64::from(bits as u8) << (WIDE * g);
    }
    out & mask
}

/// The lanes of `mask` whose rays meet triangle `t` at 0 < t < `max_t` (the SSE path's
/// `triangle_lanes`, eight lanes per group).
#[target_feature(enable = "avx2")]
#[inline]
fn triangle_lanes<const BOUNDED: bool>(
    t: &FanTriangle,
    origin: Vec3A,
    fan: &WideFan<'_>,
    mask: u64,
    max_t: f32,
) -> u64 {
    let [a, b, c] = t.0.map(|v| v - origin);
    let (mut n0, mut n1, mut n2) = (b.cross(c), c.cross(a), a.cross(b));
    let mut det = a.dot(n0);
    if det == 0.0 || !det.is_finite() {
        return 0;
    }
    let sign = 1.0f32.copysign(det);
    (n0, n1, n2, det) = (n0 * sign, n1 * sign, n2 * sign, det * sign);
    let n = [n0, n1, n2].map(|v| {
        [
            _mm256_set1_ps(v.x),
            _mm256_set1_ps(v.y),
            _mm256_set1_ps(v.z),
        ]
    });
    let minus_tol = _mm256_set1_ps(-EDGE_TOLERANCE);
    let (det, far) = (_mm256_set1_ps(det), _mm256_set1_ps(max_t));
    let mut out = 0u64;
    let mut live = live_wide(mask);
    while live != 0 {
        let g = live.trailing_zeros() as usize / WIDE;
        live &= live - 1;
        let (x, y, z) = (fan.x[g], fan.y[g], fan.z[g]);
        // (x·n.x + y·n.y) + z·n.z, in the order glam's `Vec4` arithmetic computes it.
        let [e0, e1, e2] = n.map(|[nx, ny, nz]| {
            _mm256_add_ps(
                _mm256_add_ps(_mm256_mul_ps(x, nx), _mm256_mul_ps(y, ny)),
                _mm256_mul_ps(z, nz),
            )
        });
        let sum = _mm256_add_ps(_mm256_add_ps(e0, e1), e2);
        let tol = _mm256_mul_ps(sum, minus_tol);
        let mut hit = _mm256_cmp_ps::<_CMP_GE_OS>(_mm256_min_ps(_mm256_min_ps(e0, e1), e2), tol);
        if BOUNDED {
            hit = _mm256_and_ps(
                hit,
                _mm256_cmp_ps::<_CMP_LT_OS>(det, _mm256_mul_ps(sum, far)),
            );
        }
        out |= u64::from(_mm256_movemask_ps(hit) as u8) << (WIDE * g);
    }
    out & mask
}

/// For each 8-bit mask, the positions of its set bits in order (the rest zero): the
/// permutation that packs those lanes to the front.
const PACK: [[u32; 8]; 256] = {
    let mut table = [[0u32; 8]; 256];
    let mut mask = 0;
    while mask < 256 {
        let (mut bit, mut n) = (0, 0);
        while bit < 8 {
            if mask >> bit & 1 == 1 {
                table[mask][n] = bit as u32;
                n += 1;
            }
            bit += 1;
        }
        mask += 1;
    }
    table
};

/// The AVX2 [`super::PreparedDirections::compact`]: per block of eight directions of
/// `sources` (x, y, z, reciprocals), those whose bit is set in `words` packed to the front by
/// one permute per coordinate and written eight lanes at a time, the next block's written
/// from the first lane it did not fill.
#[target_feature(enable = "avx2")]
pub(super) fn compact(sources: &[&[f32]; 6], words: &[u64], blocks: usize, out: &mut Packed) {
    let mut len = 0;
    for b in 0..blocks {
        let bits = (words[b / 8] >> (8 * (b % 8))) as u8;
        if bits == 0 {
            continue;
        }
        let order: __m256i = bytemuck::cast(PACK[usize::from(bits)]);
        for (lanes, source) in out.lanes.iter_mut().zip(sources) {
            let block: [f32; 8] = source[8 * b..8 * b + 8].try_into().expect("eight lanes");
            let packed = _mm256_permutevar8x32_ps(bytemuck::cast(block), order);
            lanes[len..len + 8].copy_from_slice(&bytemuck::cast::<__m256, [f32; 8]>(packed));
        }
        let index = _mm256_add_epi32(order, _mm256_set1_epi32(8 * b as i32));
        out.index[len..len + 8].copy_from_slice(&bytemuck::cast::<__m256i, [u32; 8]>(index));
        len += bits.count_ones() as usize;
    }
    out.len = len;
}
