// Seed 004's pass 3: the separable Gaussian on the light distance map (TR 157).

// The light distance map (faces stacked vertically, `face_size` rows each); empty texels hold
// 1e30 and are left out of the weighted mean, so the blur never mixes "nothing" into a
// distance, and a vertical pass never crosses into the next face.
@group(0) @binding(0) var blur_src: texture_2d<f32>;
@group(0) @binding(1) var blur_dst: texture_storage_2d<r32float, write>;
// x: face size; then the faces in use, one per workgroup z (y, z, w and the rest in `more`).
struct Blur {
    size: vec4<f32>,
    faces: array<vec4<u32>, 2>,
};
@group(0) @binding(2) var<uniform> blur: Blur;

const EMPTY: f32 = 1e29;
// 9 taps, σ = 2 texels (the seed's "8×8" kernel has no centre; SEED-NOTES §5.7.9).
const TAPS = array<f32, 5>(0.2270270, 0.1945946, 0.1216216, 0.0540540, 0.0162162);

fn blur_at(p: vec2<i32>, step: vec2<i32>) -> f32 {
    let size = vec2<i32>(textureDimensions(blur_src));
    let face_size = i32(blur.size.x);
    let centre = textureLoad(blur_src, p, 0).x;
    if centre >= EMPTY {
        return centre;
    }
    let face = p.y / face_size;
    var sum = 0.0;
    var weight = 0.0;
    for (var i = -4; i <= 4; i++) {
        let q = p + i * step;
        if q.x < 0 || q.x >= size.x || q.y < face * face_size || q.y >= (face + 1) * face_size {
            continue;
        }
        let v = textureLoad(blur_src, q, 0).x;
        if v >= EMPTY {
            continue;
        }
        let w = TAPS[abs(i)];
        sum += w * v;
        weight += w;
    }
    return sum / weight;
}

// One texel of face `blur.faces[id.z]` filtered along `step`.
fn blur_texel(id: vec3<u32>, step: vec2<i32>) {
    let face_size = u32(blur.size.x);
    if id.x >= face_size || id.y >= face_size {
        return;
    }
    let face = blur.faces[id.z / 4u][id.z % 4u];
    let p = vec2<i32>(vec2<u32>(id.x, id.y + face * face_size));
    textureStore(blur_dst, p, vec4<f32>(blur_at(p, step), 0.0, 0.0, 0.0));
}

@compute @workgroup_size(8, 8)
fn blur_h(@builtin(global_invocation_id) id: vec3<u32>) {
    blur_texel(id, vec2<i32>(1, 0));
}

@compute @workgroup_size(8, 8)
fn blur_v(@builtin(global_invocation_id) id: vec3<u32>) {
    blur_texel(id, vec2<i32>(0, 1));
}
