// Seed 004's evaluation (TR 150, eq. 12 per pixel) in the shared frame: the surfaces the
// opaque pass drew are drawn again with depth `Equal` and L^e is added. `view.wgsl` and
// `common.wgsl` are prepended.
// requires: common.wgsl

@group(1) @binding(0) var<uniform> params: Params;
// E_lm (27 floats), then M per channel, 4 columns each (reduce.wgsl: sh_final).
@group(1) @binding(1) var<storage, read> coefficients: array<f32>;
@group(1) @binding(2) var first_layer: texture_2d<f32>;
@group(1) @binding(3) var second_layer: texture_2d<f32>;

const EMPTY: f32 = 1e29;
const PI: f32 = 3.14159265358979;

struct EvalOut {
    @builtin(position) @invariant clip: vec4<f32>,
    @location(0) centred: vec3<f32>,
    @location(1) normal: vec3<f32>,
};

@vertex
fn vs_eval(v: MeshIn) -> EvalOut {
    var out: EvalOut;
    out.clip = view.clip_from_world * vec4<f32>(v.world, 1.0);
    out.centred = v.centred;
    out.normal = v.normal;
    return out;
}

fn matrix(c: u32) -> mat4x4<f32> {
    let b = 27u + 16u * c;
    return mat4x4<f32>(
        vec4<f32>(coefficients[b], coefficients[b + 1u], coefficients[b + 2u], coefficients[b + 3u]),
        vec4<f32>(coefficients[b + 4u], coefficients[b + 5u], coefficients[b + 6u], coefficients[b + 7u]),
        vec4<f32>(coefficients[b + 8u], coefficients[b + 9u], coefficients[b + 10u], coefficients[b + 11u]),
        vec4<f32>(coefficients[b + 12u], coefficients[b + 13u], coefficients[b + 14u], coefficients[b + 15u]),
    );
}

// Where x falls in the light map (faces stacked vertically): continuous texel coordinates
// (x, y; texel centres at .5) within its face, the face, and the world size of one texel there.
fn light_lookup(x: vec3<f32>) -> vec4<f32> {
    let size = params.maps.y;
    var face = 0u;
    var uv: vec2<f32>;
    var texel_world: f32;
    if params.light.w > 0.5 {
        let d = x - params.light.xyz;
        let a = abs(d);
        // One fitted face (light.w = 2), or the six faces' dominant axis.
        if params.light.w > 1.5 {
            face = 0u;
        } else if a.x >= a.y && a.x >= a.z {
            face = select(1u, 0u, d.x > 0.0);
        } else if a.y >= a.z {
            face = select(3u, 2u, d.y > 0.0);
        } else {
            face = select(5u, 4u, d.z > 0.0);
        }
        let f = params.light_faces[3u * face];
        let w = dot(d, f.xyz);
        uv = f.w * vec2<f32>(dot(d, params.light_faces[3u * face + 1u].xyz), dot(d, params.light_faces[3u * face + 2u].xyz)) / w;
        texel_world = 2.0 * length(d) / (f.w * size);
    } else {
        let r = params.maps.z;
        uv = vec2<f32>(dot(x, params.light_faces[1].xyz), dot(x, params.light_faces[2].xyz)) / r;
        texel_world = 2.0 * r / size;
    }
    let t = vec2<f32>((uv.x + 1.0) * 0.5 * size, (1.0 - uv.y) * 0.5 * size);
    return vec4<f32>(t, f32(face), texel_world);
}

fn load_in_face(tex: texture_2d<f32>, p: vec2<i32>, face: i32) -> f32 {
    let size = i32(params.maps.y);
    let q = clamp(p, vec2<i32>(0), vec2<i32>(size - 1));
    return textureLoad(tex, vec2<i32>(q.x, q.y + face * size), 0).x;
}

// Bilinear interpolation of the first layer, empty texels left out (so a silhouette does not
// mix "nothing" into the distance); EMPTY when all four are empty.
fn first_distance(t: vec2<f32>, face: i32) -> f32 {
    let base = floor(t - 0.5);
    let f = t - 0.5 - base;
    let i = vec2<i32>(base);
    let w = array<f32, 4>((1.0 - f.x) * (1.0 - f.y), f.x * (1.0 - f.y), (1.0 - f.x) * f.y, f.x * f.y);
    let o = array<vec2<i32>, 4>(vec2<i32>(0, 0), vec2<i32>(1, 0), vec2<i32>(0, 1), vec2<i32>(1, 1));
    var sum = 0.0;
    var weight = 0.0;
    for (var k = 0; k < 4; k++) {
        let v = load_in_face(first_layer, i + o[k], face);
        if v < EMPTY {
            sum += w[k] * v;
            weight += w[k];
        }
    }
    return select(EMPTY, sum / weight, weight > 0.0);
}

@fragment
fn fs_eval(in: EvalOut, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    var n = normalize(in.normal);
    if !front_facing {
        n = -n;
    }
    let wo = normalize(params.eye.xyz - in.centred);
    let eta = params.sigma_t.w;
    // r = refract(−ω_out, n, 1/η) (SEED-NOTES §5.7.6); WGSL returns 0 on total reflection.
    var r = refract(-wo, n, 1.0 / eta);
    if dot(r, r) == 0.0 {
        r = -n;
    }
    // The shift fix (TR 143, §5.7.8): where x + t r leaves the box, in cube space.
    let he = params.half_extent.xyz;
    let p = clamp(in.centred / he, vec3<f32>(-1.0), vec3<f32>(1.0));
    let dc = normalize(r / he);
    var t = 1e30;
    for (var a = 0; a < 3; a++) {
        if dc[a] != 0.0 {
            t = min(t, (sign(dc[a]) - p[a]) / dc[a]);
        }
    }
    var s = p + max(t, 0.0) * dc;
    s = select(dc, normalize(s), dot(s, s) > 0.0);
    let s4 = vec4<f32>(s, 1.0);
    // eq. 10 with the documented clamp at 0.
    let b = max(vec3<f32>(dot(s4, matrix(0u) * s4), dot(s4, matrix(1u) * s4), dot(s4, matrix(2u) * s4)), vec3<f32>(0.0));

    // Thickness along the light ray (SEED-NOTES §5.7.7), and the peeled-layer test (TR 155).
    let dist = light_distance_of(params, in.centred);
    let look = light_lookup(in.centred);
    let face = i32(look.z);
    let first = first_distance(look.xy, face);
    let second = load_in_face(second_layer, vec2<i32>(floor(look.xy)), face);
    let tolerance = max(params.misc.y, 4.0 * look.w);
    if params.maps.w > 0.5 && second < EMPTY && dist > second + tolerance {
        return vec4<f32>(0.0);
    }
    var d = 0.0;
    if first < EMPTY {
        d = max(dist - first, 0.0);
    }
    // eq. 12's attenuation, clamped at the longest transport mean free path, the same for
    // every channel (model.rs: attenuation_clamped).
    let st = params.sigma_t.xyz;
    let sr = params.sigma_tr.xyz;
    let dm = vec3<f32>(max(d * params.sigma_tr.w, params.window.w));
    let atten = (sr * dm + 1.0) * exp(-sr * dm) / (st * dm * dm * dm);
    // Schlick's F_t(η, n·ω_out).
    let r0 = ((eta - 1.0) / (eta + 1.0)) * ((eta - 1.0) / (eta + 1.0));
    let c = clamp(dot(n, wo), 0.0, 1.0);
    let ft = 1.0 - r0 - (1.0 - r0) * pow(1.0 - c, 5.0);
    return vec4<f32>(params.misc.x * ft / PI * atten * b, 0.0);
}
