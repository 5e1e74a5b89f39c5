// occlusion-gpu, vertex filtering (paper 000 §4.1): which triangles are visible from the
// camera. The mesh is drawn non-indexed (three expanded vertices per triangle) with depth
// test and both faces rasterised; every fragment writes its triangle's id + 1 into an R32Uint
// target (0 = background), so after read-back a triangle is visible iff its id + 1 covers at
// least one pixel. The id comes from the vertex index (vertex_index / 3), flat-interpolated:
// portable, no primitive_index feature needed.

struct Camera {
    // Perspective clip space (wgpu: y up, depth 0..1) from the centred world frame.
    clip_from_world: mat4x4<f32>,
}

@group(0) @binding(0) var<uniform> camera: Camera;

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) @interpolate(flat) id: u32,
}

@vertex
fn vs_main(@location(0) position: vec3<f32>, @builtin(vertex_index) v: u32) -> VertexOut {
    var out: VertexOut;
    out.clip = camera.clip_from_world * vec4<f32>(position, 1.0);
    out.id = v / 3u + 1u;
    return out;
}

@fragment
fn fs_main(in: VertexOut) -> @location(0) u32 {
    return in.id;
}
