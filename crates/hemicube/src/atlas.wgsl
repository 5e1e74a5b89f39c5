// Hemicube / single-plane visibility maps of many vertices in one instanced draw.
// Instance = (vertex slot, face). Every triangle is projected through the face's pinhole camera
// at the vertex's eye and placed in the slot's tile of the atlas; four clip distances keep it
// inside the face's rectangle. No depth buffer: any triangle covering a pixel centre occludes it.
enable clip_distances;

struct Face {
    forward: vec4<f32>,
    right: vec4<f32>,
    up: vec4<f32>,
    // u0, u1, v0, v1
    window: vec4<f32>,
    // x0, y0, width, height of the face inside a tile, in pixels
    rect: vec4<f32>,
};

struct Params {
    faces: array<Face, 5>,
    // atlas width, atlas height (pixels), near distance, tile width
    atlas: vec4<f32>,
    // faces per map, tiles per atlas row, tile height, unused
    grid: vec4<u32>,
};

struct Eye {
    eye: vec4<f32>,
    t: vec4<f32>,
    b: vec4<f32>,
    n: vec4<f32>,
};

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> eyes: array<Eye>;

struct VsOut {
    @builtin(position) position: vec4<f32>,
    @builtin(clip_distances) clip: array<f32, 4>,
};

@vertex
fn vs(@location(0) p: vec3<f32>, @builtin(instance_index) instance: u32) -> VsOut {
    let face_count = params.grid.x;
    let slot = instance / face_count;
    let face = params.faces[instance % face_count];
    let e = eyes[slot];
    let d = p - e.eye.xyz;
    let l = vec3<f32>(dot(d, e.t.xyz), dot(d, e.b.xyz), dot(d, e.n.xyz));
    let cu = dot(l, face.right.xyz);
    let cv = dot(l, face.up.xyz);
    let cd = dot(l, face.forward.xyz);
    let w = face.window;
    // The face's normalised device coordinates, times cd (clip space of the face camera).
    let xf = (2.0 * cu - (w.x + w.y) * cd) / (w.y - w.x);
    let yf = (2.0 * cv - (w.z + w.w) * cd) / (w.w - w.z);
    let size = params.atlas.xy;
    let tile_x = f32(slot % params.grid.y) * params.atlas.w;
    let tile_y = f32(slot / params.grid.y) * f32(params.grid.z);
    let r = face.rect;
    let x0 = tile_x + r.x;
    let y0 = tile_y + r.y;
    var out: VsOut;
    out.position = vec4<f32>(
        (2.0 * (x0 + 0.5 * r.z) / size.x - 1.0) * cd + xf * r.z / size.x,
        (1.0 - 2.0 * (y0 + 0.5 * r.w) / size.y) * cd + yf * r.w / size.y,
        params.atlas.z,
        cd,
    );
    out.clip = array<f32, 4>(cd - xf, cd + xf, cd - yf, cd + yf);
    return out;
}

@fragment
fn fs() -> @location(0) vec4<f32> {
    return vec4<f32>(1.0, 1.0, 1.0, 1.0);
}
