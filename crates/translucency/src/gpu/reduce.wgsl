// Seed 004's pass 2: SH projection of the external cube map by a two-level reduction (TR 143:
// "a MIP-map-like reduction"), then eq. 10's matrices.

// ---------------------------------------------------------------- SH projection

// The stacked cube map (size × 6·size, Rgba32Float) and per texel Y_lm(centre)·Δω, 9 floats
// (cube.rs: projection_weights — the "Y_lm tables", the only precomputation).
@group(0) @binding(0) var cube: texture_2d<f32>;
@group(0) @binding(1) var<storage, read> weights: array<f32>;
// Per workgroup, 27 partial sums (coefficient-major, then channel).
@group(0) @binding(2) var<storage, read_write> partials: array<f32>;

const GROUP: u32 = 64u;
const GROUPS: u32 = 64u;
var<workgroup> shared_sums: array<array<f32, 27>, 64>;

@compute @workgroup_size(64)
fn sh_partial(@builtin(local_invocation_index) local: u32, @builtin(workgroup_id) group: vec3<u32>) {
    let size = textureDimensions(cube);
    let count = size.x * size.y;
    var acc: array<f32, 27>;
    for (var k = 0u; k < 27u; k++) {
        acc[k] = 0.0;
    }
    for (var t = group.x * GROUP + local; t < count; t += GROUP * GROUPS) {
        let e = textureLoad(cube, vec2<u32>(t % size.x, t / size.x), 0).rgb;
        for (var k = 0u; k < 9u; k++) {
            let w = weights[9u * t + k];
            acc[3u * k] += w * e.r;
            acc[3u * k + 1u] += w * e.g;
            acc[3u * k + 2u] += w * e.b;
        }
    }
    shared_sums[local] = acc;
    workgroupBarrier();
    for (var stride = GROUP / 2u; stride > 0u; stride /= 2u) {
        if local < stride {
            for (var k = 0u; k < 27u; k++) {
                shared_sums[local][k] += shared_sums[local + stride][k];
            }
        }
        workgroupBarrier();
    }
    if local == 0u {
        for (var k = 0u; k < 27u; k++) {
            partials[27u * group.x + k] = shared_sums[0][k];
        }
    }
}

struct Window {
    // h0, h1, h2.
    factors: vec4<f32>,
};

@group(1) @binding(0) var<uniform> window: Window;
// E_lm (27 floats, as `partials`), then M per channel as 4 columns each (48 floats).
@group(1) @binding(1) var<storage, read_write> coefficients: array<f32>;

const C1: f32 = 0.42904276540489171;
const C2: f32 = 0.51166335397324424;
const C3: f32 = 0.74312386830112711;
const C4: f32 = 0.88622692545275801;
const C5: f32 = 0.24770795610037571;

@compute @workgroup_size(1)
fn sh_final() {
    var e: array<f32, 27>;
    for (var k = 0u; k < 27u; k++) {
        var s = 0.0;
        for (var g = 0u; g < GROUPS; g++) {
            s += partials[27u * g + k];
        }
        let band = select(select(2u, 1u, k < 12u), 0u, k < 3u);
        e[k] = s * window.factors[band];
        coefficients[k] = s;
    }
    // eq. 10, corrected (sh.rs: irradiance_matrix), column-major.
    for (var c = 0u; c < 3u; c++) {
        let base = 27u + 16u * c;
        let e00 = e[c]; let e1m = e[3u + c]; let e10 = e[6u + c]; let e11 = e[9u + c];
        let e2m2 = e[12u + c]; let e2m1 = e[15u + c]; let e20 = e[18u + c];
        let e21 = e[21u + c]; let e22 = e[24u + c];
        let m = array<f32, 16>(
            C1 * e22, C1 * e2m2, C1 * e21, C2 * e11,
            C1 * e2m2, -C1 * e22, C1 * e2m1, C2 * e1m,
            C1 * e21, C1 * e2m1, C3 * e20, C2 * e10,
            C2 * e11, C2 * e1m, C2 * e10, C4 * e00 - C5 * e20,
        );
        for (var i = 0u; i < 16u; i++) {
            coefficients[base + i] = m[i];
        }
    }
}
