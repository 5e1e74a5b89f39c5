// occlusion-gpu, `depth` backend, pass 1 (paper 000 §3.2, first pass): the scene rendered
// into an orthographic Depth32Float map as seen from light direction l_j. Depth only: no
// fragment stage. The draw's instance index is the global direction index j, which selects
// the light's clip_from_world matrix.

struct Light {
    // Orthographic clip space of the light (wgpu: y up, depth 0..1) from the centred world.
    clip_from_world: mat4x4<f32>,
    // xyz: the unit direction l_j towards the light; w: ω_j / π (solid angle over π).
    direction_weight: vec4<f32>,
}

@group(0) @binding(0) var<storage, read> lights: array<Light>;

@vertex
fn vs_main(@location(0) position: vec3<f32>, @builtin(instance_index) j: u32) -> @builtin(position) vec4<f32> {
    return lights[j].clip_from_world * vec4<f32>(position, 1.0);
}
