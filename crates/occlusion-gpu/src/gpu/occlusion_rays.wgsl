// occlusion-gpu, `rays` backend: exact visibility on the GPU, the `cpu` backend's rays cast
// by a compute shader. One invocation per (receiver row, 32-direction word of M): for each of
// the word's directions l_j with n·l_j > 0 it walks a binary BVH (any hit, a stack of nodes)
// from the receiver's ray origin and tests the leaves' triangles with the same Möller–Trumbore
// arithmetic and edge tolerance as the CPU's single-ray test; it writes its word of bits and
// its share of a_i. A second entry point adds each row's shares to a_i.
//
// Coordinates arrive scaled by the power of two that brings the scene's diagonal into
// (8, 16] (no f32 product leaves the normal range), and the origins p + offset·n are computed
// on the CPU, so that they round as the `cpu` backend's do.

struct Params {
    rows: u32,
    // Words of M per row (⌈k/32⌉).
    words_per_row: u32,
    // The word of this dispatch's first column, and how many words it covers.
    first_word: u32,
    word_count: u32,
    // Columns first_direction..k are computed; the others stay 0.
    first_direction: u32,
    k: u32,
    // Hits count for 0 < t < max_t (scaled; f32::MAX for unbounded rays).
    max_t: f32,
    node_count: u32,
    // The word of the first column of the whole call (the shares' layout).
    call_first_word: u32,
    call_word_count: u32,
    _pad0: u32,
    _pad1: u32,
}

struct Origin {
    // xyz: the ray origin p + offset·n (scaled); w unused.
    position: vec4<f32>,
    // xyz: unit normal, zero for a vertex used by no triangle.
    normal: vec4<f32>,
}

struct Node {
    lo: vec3<f32>,
    // Inner node: index of the first child (the second follows it); leaf: first triangle.
    first: u32,
    hi: vec3<f32>,
    // Triangles of a leaf; 0 for an inner node.
    count: u32,
}

struct Triangle {
    v0: vec4<f32>,
    e1: vec4<f32>,
    e2: vec4<f32>,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> origins: array<Origin>;
// xyz: unit l_j; w: ω_j / π.
@group(0) @binding(2) var<storage, read> directions: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> nodes: array<Node>;
@group(0) @binding(4) var<storage, read> triangles: array<Triangle>;
@group(0) @binding(5) var<storage, read_write> bits: array<u32>;
// Per (row, word of the call): the word's share of a_i.
@group(0) @binding(6) var<storage, read_write> shares: array<f32>;
@group(0) @binding(7) var<storage, read_write> ambient: array<f32>;
// The row of each origin slot (the origins are in Morton order of their positions).
@group(0) @binding(8) var<storage, read> row_of: array<u32>;

const WORKGROUP_SIZE: u32 = 64u;
// Deepest root-to-leaf path the stack holds (checked on the CPU before the dispatch).
const STACK_SIZE: u32 = 64u;
const EDGE_TOLERANCE: f32 = 1e-6;
const F32_MAX: f32 = 3.40282347e38;

// The CPU's `EdgeTriangle::intersect`: both faces, edges and vertices count as hits within
// EDGE_TOLERANCE; true for a hit with 0 < t < max_t.
fn hits(tri: Triangle, o: vec3<f32>, d: vec3<f32>, max_t: f32) -> bool {
    let e1 = tri.e1.xyz;
    let e2 = tri.e2.xyz;
    let p = cross(d, e2);
    let det = dot(e1, p);
    // det = 0, infinite or NaN: no hit.
    if det == 0.0 || !(abs(det) <= F32_MAX) {
        return false;
    }
    let inv_det = 1.0 / det;
    let s = o - tri.v0.xyz;
    let u = dot(s, p) * inv_det;
    if !(u >= -EDGE_TOLERANCE && u <= 1.0 + EDGE_TOLERANCE) {
        return false;
    }
    let q = cross(s, e1);
    let v = dot(d, q) * inv_det;
    if v < -EDGE_TOLERANCE || u + v > 1.0 + EDGE_TOLERANCE {
        return false;
    }
    let t = dot(e2, q) * inv_det;
    return t > 0.0 && t < max_t;
}

// Entry distance of the ray into the node's box, or -1 when it misses within [0, max_t].
// Conservative: the boxes are padded on the CPU, so no hit the triangle test would count is
// dropped here.
fn enter(node: Node, o: vec3<f32>, inv: vec3<f32>, max_t: f32) -> f32 {
    let t1 = (node.lo - o) * inv;
    let t2 = (node.hi - o) * inv;
    let near = min(t1, t2);
    let far = max(t1, t2);
    let t_in = max(max(max(near.x, near.y), near.z), 0.0);
    let t_out = min(min(min(far.x, far.y), far.z), max_t);
    return select(-1.0, t_in, t_in <= t_out);
}

fn occluded(o: vec3<f32>, d: vec3<f32>, max_t: f32) -> bool {
    if params.node_count == 0u {
        return false;
    }
    // A zero component becomes ±1e-30: its slabs then hold the ray for every t when the
    // origin lies between them and for none (within f32's range) when it does not, and
    // 0 × ∞ never appears.
    let tiny = select(vec3<f32>(-1e-30), vec3<f32>(1e-30), d >= vec3<f32>(0.0));
    let inv = 1.0 / select(d, tiny, abs(d) < vec3<f32>(1e-30));
    var stack: array<u32, STACK_SIZE>;
    var depth = 0u;
    var index = 0u;
    loop {
        let node = nodes[index];
        if node.count > 0u {
            for (var t = node.first; t < node.first + node.count; t++) {
                if hits(triangles[t], o, d, max_t) {
                    return true;
                }
            }
        } else {
            let a = node.first;
            let b = a + 1u;
            let ta = enter(nodes[a], o, inv, max_t);
            let tb = enter(nodes[b], o, inv, max_t);
            if ta >= 0.0 && tb >= 0.0 {
                // The nearer child first; the other waits on the stack.
                let near_first = ta <= tb;
                stack[depth] = select(a, b, near_first);
                depth += 1u;
                index = select(b, a, near_first);
                continue;
            }
            if ta >= 0.0 {
                index = a;
                continue;
            }
            if tb >= 0.0 {
                index = b;
                continue;
            }
        }
        if depth == 0u {
            return false;
        }
        depth -= 1u;
        index = stack[depth];
    }
    return false;
}

@compute @workgroup_size(64)
fn trace(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // 2D dispatch for more than 65535 workgroups. Neighbouring invocations take neighbouring
    // origin slots of the same word: the same directions from nearby origins (Morton order;
    // on lavapipe 1.17-1.19x faster than the rows' file order on the bunny, same bits).
    let cell = id.x + id.y * groups.x * WORKGROUP_SIZE;
    if cell >= params.rows * params.word_count {
        return;
    }
    let slot = cell % params.rows;
    let row = row_of[slot];
    let word = params.first_word + cell / params.rows;
    let origin = origins[slot];
    let o = origin.position.xyz;
    let n = origin.normal.xyz;
    var found = 0u;
    var share = 0.0;
    let first = max(word * 32u, params.first_direction);
    let end = min(word * 32u + 32u, params.k);
    for (var j = first; j < end; j++) {
        let l = directions[j];
        let cos_theta = dot(n, l.xyz);
        if cos_theta > 0.0 && !occluded(o, l.xyz, params.max_t) {
            found |= 1u << (j % 32u);
            share += l.w * cos_theta;
        }
    }
    bits[row * params.words_per_row + word] = found;
    shares[row * params.call_word_count + (word - params.call_first_word)] = share;
}

@compute @workgroup_size(64)
fn sum_rows(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let row = id.x + id.y * groups.x * WORKGROUP_SIZE;
    if row >= params.rows {
        return;
    }
    var sum = 0.0;
    for (var w = 0u; w < params.call_word_count; w++) {
        sum += shares[row * params.call_word_count + w];
    }
    ambient[row] = ambient[row] + sum;
}
