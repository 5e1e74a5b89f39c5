// Gouraud rendering of per-vertex radiance (paper 000 §3.3: colours are computed per vertex and
// interpolated), with two-sided colours for cloth, over an optional environment backdrop.
//
// Lat-long convention (lightsphere): +Y up, θ from +Y, φ = atan2(z, x) in [0, 2π),
// texel (r, c) centred at θ = π (r + ½)/H, φ = 2π (c + ½)/W.

struct Frame {
    clip_from_world: mat4x4<f32>,
    world_from_clip: mat4x4<f32>,
    env_from_world: mat4x4<f32>,
    eye: vec4<f32>,
    // x = width, y = height, z = 1 when an environment is bound.
    env_size: vec4<u32>,
};

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<storage, read> env_texels: array<vec4<f32>>;

struct MeshIn {
    @location(0) position: vec3<f32>,
    @location(1) front: vec3<f32>,
    @location(2) back: vec3<f32>,
};

struct MeshOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) front: vec3<f32>,
    @location(1) back: vec3<f32>,
};

@vertex
fn vs_mesh(v: MeshIn) -> MeshOut {
    var out: MeshOut;
    out.clip = frame.clip_from_world * vec4<f32>(v.position, 1.0);
    out.front = v.front;
    out.back = v.back;
    return out;
}

@fragment
fn fs_mesh(in: MeshOut, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    return vec4<f32>(select(in.back, in.front, front_facing), 1.0);
}

struct BackgroundOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) ndc: vec2<f32>,
};

@vertex
fn vs_background(@builtin(vertex_index) index: u32) -> BackgroundOut {
    // One triangle covering the screen.
    let uv = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    var out: BackgroundOut;
    out.ndc = uv * 2.0 - 1.0;
    out.clip = vec4<f32>(out.ndc, 0.0, 1.0);
    return out;
}

fn env_texel(row: i32, col: i32) -> vec3<f32> {
    let w = i32(frame.env_size.x);
    let h = i32(frame.env_size.y);
    let r = clamp(row, 0, h - 1);
    let c = ((col % w) + w) % w;
    return env_texels[u32(r * w + c)].xyz;
}

fn env_radiance(dir_in_env: vec3<f32>) -> vec3<f32> {
    let pi = 3.14159265358979;
    let d = normalize(dir_in_env);
    let theta = acos(clamp(d.y, -1.0, 1.0));
    var phi = atan2(d.z, d.x);
    if (phi < 0.0) {
        phi = phi + 2.0 * pi;
    }
    let x = phi / (2.0 * pi) * f32(frame.env_size.x) - 0.5;
    let y = theta / pi * f32(frame.env_size.y) - 0.5;
    let x0 = floor(x);
    let y0 = floor(y);
    let fx = x - x0;
    let fy = y - y0;
    let c0 = i32(x0);
    let r0 = i32(y0);
    let top = mix(env_texel(r0, c0), env_texel(r0, c0 + 1), fx);
    let bottom = mix(env_texel(r0 + 1, c0), env_texel(r0 + 1, c0 + 1), fx);
    return mix(top, bottom, fy);
}

@fragment
fn fs_background(in: BackgroundOut) -> @location(0) vec4<f32> {
    if (frame.env_size.z == 0u) {
        return vec4<f32>(0.0, 0.0, 0.0, 1.0);
    }
    let far = frame.world_from_clip * vec4<f32>(in.ndc, 1.0, 1.0);
    let dir_in_world = far.xyz / far.w - frame.eye.xyz;
    let dir_in_env = (frame.env_from_world * vec4<f32>(dir_in_world, 0.0)).xyz;
    return vec4<f32>(env_radiance(dir_in_env), 1.0);
}
