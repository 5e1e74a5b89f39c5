// Stencil shadow volumes (thesis §2.4.1; z-fail counting, Everitt & Kilgard 2002).
// `view.wgsl` of the render crate is prepended. Positions are invariant so that a receiver drawn
// twice, or a volume cap drawn over the face it came from, lands on the same depth.

// Volume vertices are homogeneous: w = 0 at infinity, w = 1 otherwise.
@vertex
fn vs_volume(@location(0) position: vec4<f32>) -> @builtin(position) @invariant vec4<f32> {
    return view.clip_from_world * position;
}

@vertex
fn vs_receiver(@location(0) position: vec3<f32>) -> @builtin(position) @invariant vec4<f32> {
    return view.clip_from_world * vec4<f32>(position, 1.0);
}

// One triangle covering the viewport; its depth is irrelevant (the pass compares Always).
@vertex
fn vs_fullscreen(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let x = f32(i32(i & 1u) * 4 - 1);
    let y = f32(i32(i >> 1u) * 4 - 1);
    return vec4<f32>(x, y, 0.5, 1.0);
}

// Where the stencil test let a fragment through: the cell is in shadow.
@fragment
fn fs_mark() -> @location(0) vec4<f32> {
    return vec4<f32>(1.0, 1.0, 1.0, 1.0);
}

// Depth and stencil only.
@fragment
fn fs_none() -> @location(0) vec4<f32> {
    return vec4<f32>(0.0, 0.0, 0.0, 0.0);
}

// ---- The light pass of the shared frame: one light's direct term, added where its stencil
// count is 0 (depth equal to the receiver drawn by the opaque passes).

struct ShadowLight {
    // xyz: position (w = 1) or unit direction towards the light (w = 0).
    position: vec4<f32>,
    // rgb: radiant intensity of a point light (W/sr, irradiance I/d²) or irradiance of a
    // directional light at normal incidence; w: 1 to apply the boundary texture (eq. 5.6).
    intensity: vec4<f32>,
};

@group(1) @binding(0) var<uniform> shadow_light: ShadowLight;
// The 1-D boundary texture, u ascending (boundary.rs).
@group(1) @binding(1) var<storage, read> boundary: array<f32>;

struct LitIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) albedo: vec3<f32>,
    // Eq. 5.6's u for the front side (x) and the back side (y) of the vertex.
    @location(3) u: vec2<f32>,
};

struct LitOut {
    @builtin(position) @invariant clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) albedo: vec3<f32>,
    @location(3) u: vec2<f32>,
};

@vertex
fn vs_lit(v: LitIn) -> LitOut {
    var out: LitOut;
    out.clip = view.clip_from_world * vec4<f32>(v.position, 1.0);
    out.world = v.position;
    out.normal = v.normal;
    out.albedo = v.albedo;
    out.u = v.u;
    return out;
}

// Lambertian direct light: ρ/π · E · max(n·l, 0) · tex(u); alpha is left to the opaque pass.
@fragment
fn fs_lit(in: LitOut, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    var n = normalize(in.normal);
    if !front_facing {
        n = -n;
    }
    var l = shadow_light.position.xyz;
    var irradiance = shadow_light.intensity.rgb;
    if shadow_light.position.w > 0.5 {
        let d = shadow_light.position.xyz - in.world;
        l = normalize(d);
        // Only a light on the surface itself is guarded: an absolute 1e-12 flattened the
        // falloff of every light nearer than 1e-6 units.
        irradiance = irradiance / max(dot(d, d), 1e-37);
    }
    var visibility = 1.0;
    if shadow_light.intensity.w > 0.5 {
        let u = select(in.u.y, in.u.x, front_facing);
        let texels = arrayLength(&boundary);
        let i = min(u32(clamp(u, 0.0, 1.0) * f32(texels)), texels - 1u);
        visibility = boundary[i];
    }
    let radiance = in.albedo / 3.14159265358979 * irradiance * max(dot(n, l), 0.0) * visibility;
    return vec4<f32>(radiance, 0.0);
}
