// Seed 004's per-frame pipeline (Banterle & Chalmers; SEED-NOTES §5.2). Positions of the
// internal passes are relative to the accumulation point (the bounding box's centre), so a mesh
// far from the origin keeps its precision. `common.wgsl` is prepended.
// requires: common.wgsl

const EMPTY: f32 = 1e30;

// (forward, right, up) of the accumulation cube map's faces, wgpu's order (cube.rs: FACES).
const CUBE_FACES = array<vec3<f32>, 18>(
    vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 0.0, -1.0), vec3<f32>(0.0, 1.0, 0.0),
    vec3<f32>(-1.0, 0.0, 0.0), vec3<f32>(0.0, 0.0, 1.0), vec3<f32>(0.0, 1.0, 0.0),
    vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 0.0, -1.0),
    vec3<f32>(0.0, -1.0, 0.0), vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 0.0, 1.0),
    vec3<f32>(0.0, 0.0, 1.0), vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0),
    vec3<f32>(0.0, 0.0, -1.0), vec3<f32>(-1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0),
);

// A face's clip position moved into its slot of a texture stacking `faces` faces vertically
// (slot 0 at the top); the fragment shader discards what falls outside the slot.
fn stack(clip: vec4<f32>, face: u32, faces: f32) -> vec4<f32> {
    let offset = 1.0 - (2.0 * f32(face) + 1.0) / faces;
    return vec4<f32>(clip.x, clip.y / faces + offset * clip.w, clip.z, clip.w);
}

fn in_slot(frag_y: f32, face: u32, size: f32) -> bool {
    return frag_y >= f32(face) * size && frag_y < f32(face + 1u) * size;
}

// ---------------------------------------------------------------- pass 1: external cube map

@group(0) @binding(0) var<uniform> params: Params;

struct CubeOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) irradiance: vec3<f32>,
    @location(1) @interpolate(flat) face: u32,
};

// From the accumulation point, in cube space (the box scaled to [−1, 1]³), the farthest
// surface along each direction: depth grows with the distance and the test is `Greater`.
@vertex
fn vs_cube(v: MeshIn, @builtin(instance_index) face: u32) -> CubeOut {
    let p = v.centred / params.half_extent.xyz;
    let f = CUBE_FACES[3u * face];
    let r = CUBE_FACES[3u * face + 1u];
    let u = CUBE_FACES[3u * face + 2u];
    let w = dot(p, f);
    let near = 1e-4;
    let far = 2.0;
    let clip = vec4<f32>(dot(p, r), dot(p, u), far / (far - near) * (w - near), w);
    var out: CubeOut;
    out.clip = stack(clip, face, 6.0);
    out.irradiance = v.irradiance;
    out.face = face;
    return out;
}

@fragment
fn fs_cube(in: CubeOut) -> @location(0) vec4<f32> {
    if !in_slot(in.clip.y, in.face, params.maps.x) {
        discard;
    }
    return vec4<f32>(in.irradiance, 1.0);
}

// ---------------------------------------------------------------- pass 3: light distance map

struct LightOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) centred: vec3<f32>,
    @location(1) @interpolate(flat) face: u32,
};

fn light_distance(x: vec3<f32>) -> f32 {
    return light_distance_of(params, x);
}

@vertex
fn vs_light(v: MeshIn, @builtin(instance_index) instance: u32) -> LightOut {
    // Only the faces the object's box reaches are drawn: instance i draws the face stored in
    // the w of entry 3i + 1 (gpu.rs: needed_faces).
    let face = u32(params.light_faces[3u * instance + 1u].w);
    let f = params.light_faces[3u * face].xyz;
    let r = params.light_faces[3u * face + 1u].xyz;
    let u = params.light_faces[3u * face + 2u].xyz;
    var clip: vec4<f32>;
    if params.light.w > 0.5 {
        let d = v.centred - params.light.xyz;
        let w = dot(d, f);
        let near = params.misc.z;
        let far = params.misc.w;
        let s = params.light_faces[3u * face].w;
        clip = vec4<f32>(s * dot(d, r), s * dot(d, u), far / (far - near) * (w - near), w);
    } else {
        let radius = params.maps.z;
        let z = (light_distance(v.centred) + radius) / (2.0 * radius);
        clip = vec4<f32>(dot(v.centred, r) / radius, dot(v.centred, u) / radius, z, 1.0);
    }
    var out: LightOut;
    out.clip = stack(clip, face, params.half_extent.w);
    out.centred = v.centred;
    out.face = face;
    return out;
}

@fragment
fn fs_distance(in: LightOut) -> @location(0) vec4<f32> {
    if !in_slot(in.clip.y, in.face, params.maps.y) {
        discard;
    }
    return vec4<f32>(light_distance(in.centred), 0.0, 0.0, 0.0);
}

// The second layer (depth peeling, TR 155): the nearest surface farther than the first by ε.
@group(1) @binding(0) var first_layer: texture_2d<f32>;

@fragment
fn fs_peel(in: LightOut) -> @location(0) vec4<f32> {
    if !in_slot(in.clip.y, in.face, params.maps.y) {
        discard;
    }
    let dist = light_distance(in.centred);
    let first = textureLoad(first_layer, vec2<i32>(in.clip.xy), 0).x;
    if dist <= first + params.misc.y {
        discard;
    }
    return vec4<f32>(dist, 0.0, 0.0, 0.0);
}
