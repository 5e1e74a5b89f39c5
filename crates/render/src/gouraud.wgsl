// Gouraud rendering of per-vertex radiance (paper 000 §3.3: colours are computed per vertex and
// interpolated), with two-sided colours for cloth. `view.wgsl` is prepended.

struct MeshIn {
    @location(0) position: vec3<f32>,
    @location(1) front: vec3<f32>,
    @location(2) back: vec3<f32>,
};

// Centroid sampling: under MSAA a fragment of a partly covered pixel is shaded inside its
// triangle, not at the pixel centre, where interpolation would extrapolate (and a steep
// radiance gradient at a silhouette goes negative).
// Invariant position: passes that draw the same surface again with depth `Equal` (a light
// term added where the shadow stencil is 0) land on exactly this depth.
struct MeshOut {
    @builtin(position) @invariant clip: vec4<f32>,
    @location(0) @interpolate(perspective, centroid) front: vec3<f32>,
    @location(1) @interpolate(perspective, centroid) back: vec3<f32>,
};

@vertex
fn vs_mesh(v: MeshIn) -> MeshOut {
    var out: MeshOut;
    out.clip = view.clip_from_world * vec4<f32>(v.position, 1.0);
    out.front = v.front;
    out.back = v.back;
    return out;
}

// Alpha 1: objects are opaque; the resolved alpha is their coverage (the matte).
@fragment
fn fs_mesh(in: MeshOut, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    return vec4<f32>(select(in.back, in.front, front_facing), 1.0);
}
