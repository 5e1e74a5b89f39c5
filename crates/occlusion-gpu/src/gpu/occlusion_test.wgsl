// occlusion-gpu, `depth` backend, pass 2: every receiver vertex depth-tested against a batch
// of light depth maps (a 2D array, one layer per direction) with a slope-scaled bias, the
// compute-shader counterpart of the seed's per-vertex occlusion query with polygon offset
// (paper 000 §3.2) and of its future work (§8.1: M stays on the GPU).
//
// One invocation per vertex: it owns its row of visibility bits (32 directions per word, row
// major) and its ambient sum, so no atomics are needed.

struct Light {
    clip_from_world: mat4x4<f32>,
    // xyz: unit l_j; w: ω_j / π.
    direction_weight: vec4<f32>,
}

struct Receiver {
    // xyz: centred world position.
    position: vec4<f32>,
    // xyz: unit world normal, zero for a vertex used by no triangle.
    normal: vec4<f32>,
}

struct Params {
    vertex_count: u32,
    // Global index j of layer 0 of the bound depth array.
    first_direction: u32,
    layer_count: u32,
    words_per_row: u32,
    resolution: u32,
    // Size of one depth-map texel in world units, and in depth (0..1) units.
    texel_world: f32,
    texel_depth: f32,
    // Bias = (constant + slope · min(tan θ, max_slope)) texels of depth.
    bias_constant_texels: f32,
    bias_slope_texels: f32,
    max_slope: f32,
    // The tested point is pushed this many texels along the normal (normal-offset shadows).
    normal_offset_texels: f32,
    _pad: f32,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> receivers: array<Receiver>;
@group(0) @binding(2) var<storage, read> lights: array<Light>;
@group(0) @binding(3) var depth_maps: texture_depth_2d_array;
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
    let receiver = receivers[i];
    let n = receiver.normal.xyz;
    let p = receiver.position.xyz + n * (params.normal_offset_texels * params.texel_world);
    let res = i32(params.resolution);
    var sum = 0.0;
    for (var layer = 0u; layer < params.layer_count; layer++) {
        let j = params.first_direction + layer;
        let light = lights[j];
        let l = light.direction_weight.xyz;
        let cos_theta = dot(n, l);
        var visible = false;
        if cos_theta > 0.0 {
            let clip = light.clip_from_world * vec4<f32>(p, 1.0);
            let uv = vec2<f32>(clip.x * 0.5 + 0.5, 0.5 - clip.y * 0.5);
            let texel = clamp(vec2<i32>(floor(uv * f32(res))), vec2<i32>(0), vec2<i32>(res - 1));
            let stored = textureLoad(depth_maps, texel, i32(layer), 0);
            let tan_theta = sqrt(max(1.0 - cos_theta * cos_theta, 0.0)) / cos_theta;
            let slope = min(tan_theta, params.max_slope);
            let bias = (params.bias_constant_texels + params.bias_slope_texels * slope) * params.texel_depth;
            visible = clip.z - bias <= stored;
        }
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
