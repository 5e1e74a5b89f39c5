// The frame's view, bound at group 0 for every pass (render crate, `frame.rs`).
struct View {
    clip_from_world: mat4x4<f32>,
    world_from_clip: mat4x4<f32>,
    // xyz: the eye in world space.
    eye: vec4<f32>,
    // x, y: image size in pixels; z: the depth of the far plane in NDC (1 standard,
    // 0 reversed infinite); w: unused.
    viewport: vec4<f32>,
};

@group(0) @binding(0) var<uniform> view: View;
