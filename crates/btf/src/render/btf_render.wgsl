// BTF mesh renderer (thesis §5.5, eqs. 5.3–5.5): per fragment, the textures of the triangle's
// three vertices T_v(uv) = Σ_m ω_m Σ_k γ_{k j_m} B_{k j_m}(uv), blended with the barycentrics
// (Chen et al. 2002), times the light's radiance g. The per-vertex ω, slots and γ come from
// the CPU (`render/shade.rs`); the sums follow `render/cpu.rs` term for term.
//
// Non-indexed draw of 3 × triangles vertices: the vertex shader fetches the triangle's three
// vertex ids from `triangles`, passes them flat to all three corners together with a
// barycentric coordinate (1,0,0), (0,1,0), (0,0,1), interpolated perspective-correct.
//
// Drawn into the shared frame (crate `render`): `view.wgsl` is prepended and binds the camera
// at group 0; this pass's data is group 1.

struct Frame {
    // rgb: the light's radiance g.
    radiance: vec4<f32>,
    // xy: uv scale.
    uv_scale: vec4<f32>,
    // x, y: normtexture width and height; z: tiles along x per slice; w: tiles per slice.
    tex: vec4<u32>,
    // x: γ stride (max c_j + 1, times 3 with RGB γ*); y: u32 words per vertex record
    // (8 + 4 · γ stride); z: 1 when γ is RGB (environment light, §5.5.2), else 0.
    strides: vec4<u32>,
}

struct GeomVertex {
    position: vec3<f32>,
    u: f32,
    v: f32,
    _pad0: f32,
    _pad1: f32,
    _pad2: f32,
}

// One texture B_kj: value = lo + step · code (quantized) or bitcast<f32>(code) (raw f32).
struct LayerInfo {
    lo: f32,
    step: f32,
    raw: u32,
    _pad: u32,
}

@group(1) @binding(0) var<uniform> frame: Frame;
@group(1) @binding(1) var<storage, read> geometry: array<GeomVertex>;
@group(1) @binding(2) var<storage, read> triangles: array<u32>;
// Per vertex: slots j_0..j_3 (u32), ω_0..ω_3 (f32 bits), then 4 × γ stride γ values (f32 bits).
@group(1) @binding(3) var<storage, read> records: array<u32>;
@group(1) @binding(4) var<storage, read> layers: array<LayerInfo>;
// Per view slot: (first layer, c_j + 1).
@group(1) @binding(5) var<storage, read> slots: array<vec2<u32>>;
@group(1) @binding(6) var textures: texture_3d<u32>;

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    // Centroid: under MSAA, shade inside the triangle (no extrapolated barycentrics).
    @location(0) @interpolate(perspective, centroid) bary: vec3<f32>,
    @location(1) @interpolate(flat) ids: vec3<u32>,
}

@vertex
fn vs_main(@builtin(vertex_index) index: u32) -> VsOut {
    let t = index / 3u;
    let corner = index % 3u;
    let ids = vec3<u32>(triangles[3u * t], triangles[3u * t + 1u], triangles[3u * t + 2u]);
    var out: VsOut;
    out.clip = view.clip_from_world * vec4<f32>(geometry[ids[corner]].position, 1.0);
    var b = vec3<f32>(0.0);
    b[corner] = 1.0;
    out.bary = b;
    out.ids = ids;
    return out;
}

fn uv_of(v: u32) -> vec2<f32> {
    return vec2<f32>(geometry[v].u, geometry[v].v);
}

// The texel index of coordinate u with wrap-around, as `BtfPca::nearest_texel`.
fn wrap_index(u: f32, n: u32) -> u32 {
    let f = u - floor(u);
    return min(u32(floor(f * f32(n))), n - 1u);
}

// The stored codes of texel (x, y) of layer `layer` (tiled: tiles_x × tiles_y per z slice).
fn load(layer: u32, x: u32, y: u32) -> vec4<u32> {
    let z = layer / frame.tex.w;
    let r = layer % frame.tex.w;
    let ox = (r % frame.tex.z) * frame.tex.x;
    let oy = (r / frame.tex.z) * frame.tex.y;
    return textureLoad(textures, vec3<i32>(i32(ox + x), i32(oy + y), i32(z)), 0);
}

@fragment
fn fs_main(in: VsOut) -> @location(0) vec4<f32> {
    let b = in.bary;
    let uv = b.x * uv_of(in.ids.x) + b.y * uv_of(in.ids.y) + b.z * uv_of(in.ids.z);
    let x = wrap_index(uv.x * frame.uv_scale.x, frame.tex.x);
    let y = wrap_index(uv.y * frame.uv_scale.y, frame.tex.y);
    var rgb = vec3<f32>(0.0);
    for (var c = 0u; c < 3u; c++) {
        let base = in.ids[c] * frame.strides.y;
        var texture = vec3<f32>(0.0);
        for (var m = 0u; m < 4u; m++) {
            let omega = bitcast<f32>(records[base + 4u + m]);
            if omega == 0.0 {
                continue;
            }
            let slot = slots[records[base + m]];
            let g_base = base + 8u + m * frame.strides.x;
            var t = vec3<f32>(0.0);
            for (var k = 0u; k < slot.y; k++) {
                var g: vec3<f32>;
                if frame.strides.z != 0u {
                    let r = g_base + 3u * k;
                    g = vec3<f32>(
                        bitcast<f32>(records[r]),
                        bitcast<f32>(records[r + 1u]),
                        bitcast<f32>(records[r + 2u]),
                    );
                } else {
                    g = vec3<f32>(bitcast<f32>(records[g_base + k]));
                }
                if all(g == vec3<f32>(0.0)) {
                    continue;
                }
                let info = layers[slot.x + k];
                let q = load(slot.x + k, x, y);
                if info.raw != 0u {
                    t += g * bitcast<vec3<f32>>(q.xyz);
                } else {
                    let a0 = g * info.lo;
                    let a1 = g * info.step;
                    t += a0 + a1 * vec3<f32>(q.xyz);
                }
            }
            texture += omega * t;
        }
        rgb += b[c] * texture;
    }
    // A truncated PCA can ring slightly below zero in dark texels; radiance cannot be
    // negative (the CPU reference clamps alike).
    return vec4<f32>(max(frame.radiance.xyz * rgb, vec3<f32>(0.0)), 1.0);
}
