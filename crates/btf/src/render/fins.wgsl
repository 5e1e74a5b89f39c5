// BTF fins (thesis §5.7.3, eq. 5.15, Listing 5.1): the fin quads of one frame textured with the
// compressed grazing-view images, drawn in two order-independent passes into the shared frame
// (`render/fins_gpu.rs`): `fs_absorb` multiplies what is behind by (1 − α), `fs_emit` adds the
// premultiplied colour. Each fin is 6 vertices of a non-indexed draw (V1 V2 V4, V1 V4 V3).
//
// `view.wgsl` is prepended (group 0, the camera); this pass's data is group 1.

struct FinUniform {
    // rgb: the light's radiance g.
    radiance: vec4<f32>,
    // x, y: image width and height; z: c + 1 (γ per end).
    dims: vec4<u32>,
    // x: alpha cut (Listing 5.1's alpha_adjust).
    params: vec4<f32>,
}

struct FinVertex {
    position: vec3<f32>,
    // Weight of the V2 end (blend02).
    end_weight: f32,
    st: vec2<f32>,
    _pad: vec2<f32>,
}

@group(1) @binding(0) var<uniform> u: FinUniform;
@group(1) @binding(1) var<storage, read> fin_vertices: array<FinVertex>;
// 2 · (c + 1) per fin: γ of the V1 end, then of the V2 end.
@group(1) @binding(2) var<storage, read> gammas: array<f32>;
// (c + 1) images (mean first) of h × w RGB texels, row 0 = the fibre tips.
@group(1) @binding(3) var<storage, read> images: array<f32>;

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) st: vec2<f32>,
    @location(1) end_weight: f32,
    @location(2) @interpolate(flat) fin: u32,
}

@vertex
fn vs_main(@builtin(vertex_index) vi: u32) -> VsOut {
    var corners = array<u32, 6>(0u, 1u, 3u, 0u, 3u, 2u);
    let fin = vi / 6u;
    let v = fin_vertices[4u * fin + corners[vi % 6u]];
    var out: VsOut;
    out.clip = view.clip_from_world * vec4<f32>(v.position, 1.0);
    out.st = v.st;
    out.end_weight = v.end_weight;
    out.fin = fin;
    return out;
}

// g ⊙ Σ_k γ_k B_k at texel (x, y) for end `end` of fin `fin`.
fn end_colour(fin: u32, end: u32, x: u32, y: u32) -> vec3<f32> {
    let n = u.dims.z;
    let texels = u.dims.x * u.dims.y;
    let first = (2u * fin + end) * n;
    var c = vec3<f32>(0.0);
    for (var k = 0u; k < n; k++) {
        let i = 3u * (k * texels + y * u.dims.x + x);
        c += gammas[first + k] * vec3<f32>(images[i], images[i + 1u], images[i + 2u]);
    }
    return c * u.radiance.rgb;
}

// Listing 5.1 with premultiplied colour: each end weighted, its alpha r + g + b cut below
// alpha_adjust (a cut end adds nothing), the two ends summed, alpha clamped to 1.
fn fin_colour(in: VsOut) -> vec4<f32> {
    let w = f32(u.dims.x);
    let h = f32(u.dims.y);
    let x = min(u32((in.st.x - floor(in.st.x)) * w), u.dims.x - 1u);
    let y = u32(clamp(floor((1.0 - in.st.y) * h), 0.0, h - 1.0));
    var out = vec4<f32>(0.0);
    let weights = vec2<f32>(1.0 - in.end_weight, in.end_weight);
    for (var e = 0u; e < 2u; e++) {
        let rgb = weights[e] * end_colour(in.fin, e, x, y);
        var a = rgb.r + rgb.g + rgb.b;
        if a >= u.params.x && a > 0.0 {
            out += vec4<f32>(rgb, min(a, 1.0));
        }
    }
    out.a = min(out.a, 1.0);
    return out;
}

// Pass 1 (blend: colour × (1 − α_src), alpha a + (1 − a) · dst): what is behind the fins is
// attenuated by every fin in front of it, in any order.
@fragment
fn fs_absorb(in: VsOut) -> @location(0) vec4<f32> {
    let c = fin_colour(in);
    if c.a <= 0.0 {
        discard;
    }
    return c;
}

// Pass 2 (blend: colour + src, alpha kept): the fins' own light, summed in any order.
@fragment
fn fs_emit(in: VsOut) -> @location(0) vec4<f32> {
    let c = fin_colour(in);
    if c.a <= 0.0 {
        discard;
    }
    return c;
}
