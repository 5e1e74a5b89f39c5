// occlusion-gpu, `query` backend, pass 3: the resolved occlusion-query results of a batch of
// directions (one u64 sample count per (vertex, direction), resolved with resolve_query_set)
// turned into the visibility bits and ambient sums the `depth` backend writes — on the GPU,
// without a read-back per batch (paper 000 §3.2, M_ij = n_i·l_j when visible; §8.1, M stays
// on the GPU).
//
// Query q = d · vertex_count + i holds vertex i towards direction first_direction + d. One
// invocation per vertex owns its row of bits and its ambient sum, so no atomics are needed.

struct Light {
    clip_from_world: mat4x4<f32>,
    // xyz: unit l_j; w: ω_j / π.
    direction_weight: vec4<f32>,
}

struct Receiver {
    position: vec4<f32>,
    normal: vec4<f32>,
}

struct Params {
    vertex_count: u32,
    first_direction: u32,
    direction_count: u32,
    words_per_row: u32,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> receivers: array<Receiver>;
@group(0) @binding(2) var<storage, read> lights: array<Light>;
// u64 sample counts as (low, high) 32-bit halves (little endian).
@group(0) @binding(3) var<storage, read> counts: array<vec2<u32>>;
@group(0) @binding(4) var<storage, read_write> bits: array<u32>;
@group(0) @binding(5) var<storage, read_write> ambient: array<f32>;

const WORKGROUP_SIZE: u32 = 64u;

@compute @workgroup_size(64)
fn cs_main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // 2D dispatch for vertex counts above 65535 workgroups.
    let i = id.x + id.y * groups.x * WORKGROUP_SIZE;
    if i >= params.vertex_count {
        return;
    }
    let n = receivers[i].normal.xyz;
    var sum = 0.0;
    for (var d = 0u; d < params.direction_count; d++) {
        let j = params.first_direction + d;
        let light = lights[j];
        let cos_theta = dot(n, light.direction_weight.xyz);
        let samples = counts[d * params.vertex_count + i];
        let visible = cos_theta > 0.0 && (samples.x | samples.y) != 0u;
        let word = i * params.words_per_row + j / 32u;
        let mask = 1u << (j % 32u);
        if visible {
            bits[word] = bits[word] | mask;
            sum += light.direction_weight.w * cos_theta;
        } else {
            bits[word] = bits[word] & ~mask;
        }
    }
    ambient[i] = ambient[i] + sum;
}
