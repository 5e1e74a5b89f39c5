//! The packet traversal eight rays at a time (AVX2), chosen at run time where the CPU has it.
//!
//! The same nodes in the same order as the scalar [`PacketTracer::unoccluded`], the same slab
//! test and the same Möller–Trumbore arithmetic in the same operand order (glam's `Vec3A` dot
//! product is (x + y) + z; no fused multiply-add), so every ray's answer is bit for bit the
//! scalar one (a unit test compares them). What the rays of a packet share — the direction,
//! its reciprocal, and per triangle p = d × e₂, det and 1 / det — is computed once; a node's
//! box or a triangle is then tested against eight origins per instruction, the origins
//! stored structure of arrays.

use std::arch::x86_64::{
    __m256, _CMP_GE_OQ, _CMP_GT_OQ, _CMP_LE_OQ, _CMP_LT_OQ, _mm256_add_ps, _mm256_and_ps,
    _mm256_andnot_ps, _mm256_cmp_ps, _mm256_loadu_ps, _mm256_max_ps, _mm256_min_ps,
    _mm256_movemask_ps, _mm256_mul_ps, _mm256_or_ps, _mm256_set1_ps, _mm256_setzero_ps,
    _mm256_sub_ps,
};

use glam::Vec3A;
use obvhs::bvh2::node::Bvh2Node;

use super::{PACKET, PacketSetup, PacketTracer, Soa};
use crate::cpu::EDGE_TOLERANCE;
use crate::fan::live_wide;

/// Rays per AVX2 group.
const WIDE: usize = 8;

/// Eight lanes of one axis of the origins, from ray `8g`.
#[target_feature(enable = "avx2")]
#[inline]
fn lanes(axis: &[f32; PACKET], g: usize) -> __m256 {
    let eight: &[f32; WIDE] = axis[WIDE * g..WIDE * g + WIDE]
        .try_into()
        .expect("eight lanes");
    // SAFETY: `eight` is eight readable f32s; the load has no alignment requirement.
    #[allow(unsafe_code)]
    unsafe {
        _mm256_loadu_ps(eight.as_ptr())
    }
}

/// The rays of `mask` that enter `node`'s box (the scalar `hits`, eight rays per group).
#[target_feature(enable = "avx2")]
#[inline]
fn box_rays(node: &Bvh2Node, origins: &Soa, setup: &PacketSetup, mask: u64) -> u64 {
    if setup.misses(node) {
        return 0;
    }
    let (min, max, inv) = (node.aabb.min, node.aabb.max, setup.inv);
    let splat = |v: Vec3A| v.to_array().map(|c| _mm256_set1_ps(c));
    let ([lx, ly, lz], [hx, hy, hz], [ix, iy, iz]) = (splat(min), splat(max), splat(inv));
    let zero = _mm256_setzero_ps();
    let mut out = 0u64;
    let mut live = live_wide(mask);
    while live != 0 {
        let g = live.trailing_zeros() as usize / WIDE;
        live &= live - 1;
        let (ox, oy, oz) = (
            lanes(&origins[0], g),
            lanes(&origins[1], g),
            lanes(&origins[2], g),
        );
        let (x1, x2) = (
            _mm256_mul_ps(_mm256_sub_ps(lx, ox), ix),
            _mm256_mul_ps(_mm256_sub_ps(hx, ox), ix),
        );
        let (y1, y2) = (
            _mm256_mul_ps(_mm256_sub_ps(ly, oy), iy),
            _mm256_mul_ps(_mm256_sub_ps(hy, oy), iy),
        );
        let (z1, z2) = (
            _mm256_mul_ps(_mm256_sub_ps(lz, oz), iz),
            _mm256_mul_ps(_mm256_sub_ps(hz, oz), iz),
        );
        let near = _mm256_max_ps(
            _mm256_max_ps(
                _mm256_max_ps(_mm256_min_ps(x1, x2), _mm256_min_ps(y1, y2)),
                _mm256_min_ps(z1, z2),
            ),
            zero,
        );
        let far = _mm256_min_ps(
            _mm256_min_ps(_mm256_max_ps(x1, x2), _mm256_max_ps(y1, y2)),
            _mm256_max_ps(z1, z2),
        );
        let inside = _mm256_cmp_ps::<_CMP_LE_OQ>(near, far);
        out |= u64::from(_mm256_movemask_ps(inside) as u8) << (WIDE * g);
    }
    out & mask
}

/// `(x·a + y·b) + z·c`, glam's `Vec3A` dot product lane by lane.
#[target_feature(enable = "avx2")]
#[inline]
fn dot(x: __m256, y: __m256, z: __m256, [a, b, c]: [__m256; 3]) -> __m256 {
    _mm256_add_ps(
        _mm256_add_ps(_mm256_mul_ps(x, a), _mm256_mul_ps(y, b)),
        _mm256_mul_ps(z, c),
    )
}

/// The rays of `mask` that meet the triangle `v0`, `e1`, `e2` at 0 < t < `max_t`: the scalar
/// `EdgeTriangle::intersect` eight origins at a time.
#[target_feature(enable = "avx2")]
#[inline]
fn triangle_rays(
    [v0, e1, e2]: [Vec3A; 3],
    origins: &Soa,
    direction: Vec3A,
    mask: u64,
    max_t: f32,
) -> u64 {
    let p = direction.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 || !det.is_finite() {
        return 0;
    }
    let inv_det = _mm256_set1_ps(1.0 / det);
    let splat = |v: Vec3A| v.to_array().map(|c| _mm256_set1_ps(c));
    let ([v0x, v0y, v0z], [e1x, e1y, e1z], e2s) = (splat(v0), splat(e1), splat(e2));
    let (ps, ds) = (splat(p), splat(direction));
    let (low, high) = (
        _mm256_set1_ps(-EDGE_TOLERANCE),
        _mm256_set1_ps(1.0 + EDGE_TOLERANCE),
    );
    let (zero, far) = (_mm256_setzero_ps(), _mm256_set1_ps(max_t));
    let mut out = 0u64;
    let mut live = live_wide(mask);
    while live != 0 {
        let g = live.trailing_zeros() as usize / WIDE;
        live &= live - 1;
        let sx = _mm256_sub_ps(lanes(&origins[0], g), v0x);
        let sy = _mm256_sub_ps(lanes(&origins[1], g), v0y);
        let sz = _mm256_sub_ps(lanes(&origins[2], g), v0z);
        let u = _mm256_mul_ps(dot(sx, sy, sz, ps), inv_det);
        // s × e₁ (glam's cross product: each component one difference of two products).
        let qx = _mm256_sub_ps(_mm256_mul_ps(sy, e1z), _mm256_mul_ps(sz, e1y));
        let qy = _mm256_sub_ps(_mm256_mul_ps(sz, e1x), _mm256_mul_ps(sx, e1z));
        let qz = _mm256_sub_ps(_mm256_mul_ps(sx, e1y), _mm256_mul_ps(sy, e1x));
        let v = _mm256_mul_ps(dot(qx, qy, qz, ds), inv_det);
        let t = _mm256_mul_ps(dot(qx, qy, qz, e2s), inv_det);
        // u in [−ε, 1 + ε] (false for NaN, as `contains`); then a miss where v < −ε or
        // u + v > 1 + ε (ordered: NaN passes, as the scalar `||` does); then 0 < t < max_t.
        let u_in = _mm256_and_ps(
            _mm256_cmp_ps::<_CMP_GE_OQ>(u, low),
            _mm256_cmp_ps::<_CMP_LE_OQ>(u, high),
        );
        let v_out = _mm256_or_ps(
            _mm256_cmp_ps::<_CMP_LT_OQ>(v, low),
            _mm256_cmp_ps::<_CMP_GT_OQ>(_mm256_add_ps(u, v), high),
        );
        let t_in = _mm256_and_ps(
            _mm256_cmp_ps::<_CMP_GT_OQ>(t, zero),
            _mm256_cmp_ps::<_CMP_LT_OQ>(t, far),
        );
        let hit = _mm256_and_ps(_mm256_andnot_ps(v_out, u_in), t_in);
        out |= u64::from(_mm256_movemask_ps(hit) as u8) << (WIDE * g);
    }
    out & mask
}

/// The scalar `unoccluded`, eight rays per group.
#[target_feature(enable = "avx2")]
pub(super) fn unoccluded(
    tracer: &PacketTracer,
    origins: &Soa,
    setup: &PacketSetup,
    direction: Vec3A,
    mask: u64,
    max_t: f32,
) -> u64 {
    let mut visible = mask;
    let mut stack: Vec<(u32, u64)> = Vec::with_capacity(64);
    let root = box_rays(&tracer.nodes[0], origins, setup, mask);
    if root != 0 {
        stack.push((0, root));
    }
    while let Some((index, m)) = stack.pop() {
        let mut m = m & visible;
        if m == 0 {
            continue;
        }
        let node = &tracer.nodes[index as usize];
        if node.prim_count > 0 {
            let first = node.first_index as usize;
            for t in &tracer.triangles[first..first + node.prim_count as usize] {
                let hit = triangle_rays([t.v0, t.e1, t.e2], origins, direction, m, max_t);
                visible &= !hit;
                m &= !hit;
                if m == 0 {
                    break;
                }
            }
            if visible == 0 {
                break;
            }
        } else {
            let first = node.first_index;
            for child in [first + 1, first] {
                let cm = box_rays(&tracer.nodes[child as usize], origins, setup, m);
                if cm != 0 {
                    stack.push((child, cm));
                }
            }
        }
    }
    visible
}
