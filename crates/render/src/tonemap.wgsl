// The tone-map pass: the resolved HDR frame to display values, on the GPU, exactly as
// `render::tone::Display::map` and `render::output::to_rgba8` do on the CPU (within one 8-bit
// code): exposure 2^EV, then the curve — 0: Narkowicz's ACES fit then sRGB encoding,
// 1: clamp then x^(1/gamma) (the seed's), 2: clamp then sRGB encoding — and, for a
// transparent background, colour un-premultiplied by the coverage alpha.
// The output format must not be an *Srgb format: the shader writes encoded values.

struct ToneParams {
    scale: f32,
    curve: u32,
    gamma: f32,
    transparent: u32,
}

@group(0) @binding(0) var hdr: texture_2d<f32>;
@group(0) @binding(1) var<uniform> params: ToneParams;

// One triangle covering the viewport.
@vertex
fn vs_tonemap(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    let x = f32((index << 1u) & 2u) * 2.0 - 1.0;
    let y = f32(index & 2u) * 2.0 - 1.0;
    return vec4<f32>(x, y, 0.0, 1.0);
}

fn srgb_encode(linear: f32) -> f32 {
    let v = clamp(linear, 0.0, 1.0);
    if v <= 0.0031308 {
        return 12.92 * v;
    }
    return 1.055 * pow(v, 1.0 / 2.4) - 0.055;
}

fn aces_fitted(x: f32) -> f32 {
    if !(x > 0.0) {
        return 0.0;
    }
    if x < 1.0 {
        return clamp(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
    }
    // Above 1, divided through by x² so that x² cannot overflow f32 (a sun far above 10^19).
    let inv = 1.0 / x;
    return clamp((2.51 + 0.03 * inv) / (2.43 + (0.59 + 0.14 * inv) * inv), 0.0, 1.0);
}

fn map_channel(linear: f32) -> f32 {
    let x = linear * params.scale;
    switch params.curve {
        case 0u: {
            return srgb_encode(aces_fitted(x));
        }
        case 1u: {
            return pow(clamp(x, 0.0, 1.0), 1.0 / params.gamma);
        }
        default: {
            return srgb_encode(x);
        }
    }
}

@fragment
fn fs_tonemap(@builtin(position) position: vec4<f32>) -> @location(0) vec4<f32> {
    let p = textureLoad(hdr, vec2<i32>(position.xy), 0);
    var rgb = p.rgb;
    var alpha = 1.0;
    if params.transparent != 0u {
        alpha = clamp(p.a, 0.0, 1.0);
        rgb = select(vec3<f32>(0.0), rgb / alpha, alpha > 0.0);
    }
    return vec4<f32>(map_channel(rgb.r), map_channel(rgb.g), map_channel(rgb.b), alpha);
}
