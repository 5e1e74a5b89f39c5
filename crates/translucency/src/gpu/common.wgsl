// Shared by the pipeline's passes and the evaluation pass (gpu.rs: ParamsUniform).

struct Params {
    // xyz: the box's half extents (the "blindness" scale); w: faces of the light map (1 or 6).
    half_extent: vec4<f32>,
    // xyz: point light (centred) or unit direction towards a directional light; w: 0
    // directional, 1 point (six 90° faces around it), 2 point (one face fitted to the bounding
    // sphere, the light standing back from the object).
    light: vec4<f32>,
    // xyz: the eye, centred.
    eye: vec4<f32>,
    // σ_tr per channel (mm⁻¹); w: millimetres per scene unit.
    sigma_tr: vec4<f32>,
    // σ′_t per channel (mm⁻¹); w: η.
    sigma_t: vec4<f32>,
    // x: intensity scale; y: peel ε (scene units); z: near; w: far (light map).
    misc: vec4<f32>,
    // x: cube face size; y: light map size; z: orthographic radius; w: 1 = the peeled test on.
    maps: vec4<f32>,
    // Window factors h0, h1, h2 (SH bands); w: the attenuation's clamp distance (mm).
    window: vec4<f32>,
    // Per light-map face: forward, right, up; the w of entry 3i + 1 is the face instance i
    // draws; the w of a point light's forward is 1 / tan of the face's half-angle (1 for the
    // six 90° faces).
    light_faces: array<vec4<f32>, 18>,
};

struct MeshIn {
    @location(0) world: vec3<f32>,
    @location(1) centred: vec3<f32>,
    @location(2) normal: vec3<f32>,
    @location(3) irradiance: vec3<f32>,
};

// Distance along the light's ray (model.rs: Light::distance), centred coordinates.
fn light_distance_of(p: Params, x: vec3<f32>) -> f32 {
    if p.light.w > 0.5 {
        return length(x - p.light.xyz);
    }
    return -dot(x, p.light.xyz);
}
