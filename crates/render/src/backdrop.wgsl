// The environment behind the objects: a screen-covering triangle at the far plane, drawn after
// the opaque passes with a depth test that passes only where nothing was drawn. Alpha 0: the
// backdrop is not part of the matte. `view.wgsl` is prepended.
//
// Lat-long convention (lightsphere): +Y up, θ from +Y, φ = atan2(z, x) in [0, 2π),
// texel (r, c) centred at θ = π (r + ½)/H, φ = 2π (c + ½)/W.

struct Env {
    env_from_world: mat4x4<f32>,
    // x = width, y = height.
    size: vec4<u32>,
};

@group(1) @binding(0) var<uniform> env: Env;
@group(1) @binding(1) var<storage, read> env_texels: array<vec4<f32>>;

struct BackdropOut {
    // Invariant: the Equal depth test needs exactly the cleared far depth.
    @builtin(position) @invariant clip: vec4<f32>,
    @location(0) ndc: vec2<f32>,
};

@vertex
fn vs_backdrop(@builtin(vertex_index) index: u32) -> BackdropOut {
    let uv = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    var out: BackdropOut;
    out.ndc = uv * 2.0 - 1.0;
    out.clip = vec4<f32>(out.ndc, view.viewport.z, 1.0);
    return out;
}

fn env_texel(row: i32, col: i32) -> vec3<f32> {
    let w = i32(env.size.x);
    let h = i32(env.size.y);
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
    let x = phi / (2.0 * pi) * f32(env.size.x) - 0.5;
    let y = theta / pi * f32(env.size.y) - 0.5;
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
fn fs_backdrop(in: BackdropOut) -> @location(0) vec4<f32> {
    // A point at NDC depth ½ is finite under both depth conventions (reversed infinite maps
    // the far plane to w = 0); the ray from the eye through it is the pixel's direction.
    let p = view.world_from_clip * vec4<f32>(in.ndc, 0.5, 1.0);
    let dir_in_world = p.xyz / p.w - view.eye.xyz;
    let dir_in_env = (env.env_from_world * vec4<f32>(dir_in_world, 0.0)).xyz;
    return vec4<f32>(env_radiance(dir_in_env), 0.0);
}
