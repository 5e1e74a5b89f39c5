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
