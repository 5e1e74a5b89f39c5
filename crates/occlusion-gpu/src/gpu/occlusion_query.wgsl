// occlusion-gpu, `query` backend, pass 2 (paper 000 §3.2, second pass): every receiver vertex
// drawn as a point of size 1 into the light's depth map of direction l_j, depth test
// LessEqual, no depth write, one hardware occlusion query per (vertex, direction).
//
// glPolygonOffset(1, 1) applies to polygons only (and Vulkan gives points no fixed-function
// bias), so the bias is applied here, with the same slope-scaled bias and normal offset as
// `occlusion_test.wgsl`: both GPU backends then test the same depth against the same texel.
// The point is snapped to the centre of the texel the compute test reads, and a point nearer
// than the near plane after the bias is clamped to depth 0 (the compute test passes it too).
// The draw's vertex index is the receiver i, its instance index the global direction j.

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

// A position outside the clip volume: the point is clipped and its query counts 0 samples.
const CULLED: vec4<f32> = vec4<f32>(2.0, 2.0, 2.0, 1.0);

@vertex
fn vs_main(@builtin(vertex_index) i: u32, @builtin(instance_index) j: u32) -> @builtin(position) vec4<f32> {
    let receiver = receivers[i];
    let light = lights[j];
    let n = receiver.normal.xyz;
    let cos_theta = dot(n, light.direction_weight.xyz);
    // Back-facing to l_j (or a zero normal): M_ij = 0 whatever the depth test says.
    if !(cos_theta > 0.0) {
        return CULLED;
    }
    let p = receiver.position.xyz + n * (params.normal_offset_texels * params.texel_world);
    let clip = light.clip_from_world * vec4<f32>(p, 1.0);
    let res = i32(params.resolution);
    let uv = vec2<f32>(clip.x * 0.5 + 0.5, 0.5 - clip.y * 0.5);
    let texel = clamp(vec2<i32>(floor(uv * f32(res))), vec2<i32>(0), vec2<i32>(res - 1));
    let centre = (vec2<f32>(texel) + vec2<f32>(0.5)) / f32(res);
    let tan_theta = sqrt(max(1.0 - cos_theta * cos_theta, 0.0)) / cos_theta;
    let slope = min(tan_theta, params.max_slope);
    let bias = (params.bias_constant_texels + params.bias_slope_texels * slope) * params.texel_depth;
    // Beyond the far plane stays beyond it (clipped: occluded, as in the compute test).
    let depth = max(clip.z - bias, 0.0);
    return vec4<f32>(centre.x * 2.0 - 1.0, 1.0 - centre.y * 2.0, depth, 1.0);
}
