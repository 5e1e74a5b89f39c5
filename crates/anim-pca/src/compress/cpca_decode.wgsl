// CPCA decompression on the GPU (thesis §3.3.2 "Decompression", Fig. 3.18):
//   p_m(f) = r_{I_m}(f) + Σ_h w_mh E_{I_m h}(f)
// one invocation per vertex (`decode_frame`). With time compression, `rows_from_time` first
// rebuilds the (c + 1) × 3 values r_j(f), E_j1(f), …, E_jc(f) of every cluster at frame f:
//   E_jh(f) = μ(f) + Σ_s a_jhs B_s(f)
// one invocation per (cluster, row). The summation order is the CPU `Decoder`'s.
// Indices run over a 2-D dispatch (x fastest) so that more than 65,535 workgroups fit.

struct Params {
    vertices: u32,
    clusters: u32,
    components: u32,
    frame: u32,
    // First value of frame f's k row blocks in `rows` (f·k·(c+1)·3, or 0 with time compression).
    row_base: u32,
    // c* (0 without time compression).
    time_components: u32,
    _pad0: u32,
    _pad1: u32,
}

const WORKGROUP: u32 = 64u;

@group(0) @binding(0) var<uniform> params: Params;

// decode_frame
// I_m, length V.
@group(0) @binding(1) var<storage, read> labels: array<u32>;
// w_mh at h·V + m (component-major: neighbouring invocations read neighbouring words).
@group(0) @binding(2) var<storage, read> weights: array<f32>;
// [f][j][r][axis] (direct), or [j][r][axis] of frame f (time); r = 0 the mean.
@group(0) @binding(3) var<storage, read> rows: array<f32>;
// (x, y, z, 1) per vertex: a vertex buffer of Float32x4 (or Float32x3 at stride 16).
@group(0) @binding(4) var<storage, read_write> positions: array<vec4<f32>>;

// rows_from_time
// r_j(f) at [f][j][axis].
@group(0) @binding(5) var<storage, read> means: array<f32>;
// a_jhs at (j·c + h)·c* + s.
@group(0) @binding(6) var<storage, read> coef: array<f32>;
// μ(f) at [f][axis].
@group(0) @binding(7) var<storage, read> time_mean: array<f32>;
// B_s(f) at [f][s][axis].
@group(0) @binding(8) var<storage, read> basis: array<f32>;
// Output: [j][r][axis] of frame f (bound as `rows` by decode_frame).
@group(0) @binding(9) var<storage, read_write> frame_rows: array<f32>;

fn linear_index(gid: vec3<u32>, groups: vec3<u32>) -> u32 {
    return gid.y * groups.x * WORKGROUP + gid.x;
}

@compute @workgroup_size(64)
fn decode_frame(
    @builtin(global_invocation_id) gid: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let m = linear_index(gid, groups);
    if m >= params.vertices {
        return;
    }
    let c = params.components;
    let base = params.row_base + labels[m] * (c + 1u) * 3u;
    var p = vec3<f32>(rows[base], rows[base + 1u], rows[base + 2u]);
    for (var h = 0u; h < c; h++) {
        let w = weights[h * params.vertices + m];
        let e = base + 3u * (h + 1u);
        p += w * vec3<f32>(rows[e], rows[e + 1u], rows[e + 2u]);
    }
    positions[m] = vec4<f32>(p, 1.0);
}

@compute @workgroup_size(64)
fn rows_from_time(
    @builtin(global_invocation_id) gid: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let i = linear_index(gid, groups);
    let c = params.components;
    let k = params.clusters;
    if i >= k * (c + 1u) {
        return;
    }
    let j = i / (c + 1u);
    let r = i % (c + 1u);
    let f = params.frame;
    var e: vec3<f32>;
    if r == 0u {
        let at = (f * k + j) * 3u;
        e = vec3<f32>(means[at], means[at + 1u], means[at + 2u]);
    } else {
        let cs = params.time_components;
        let a = (j * c + r - 1u) * cs;
        e = vec3<f32>(time_mean[3u * f], time_mean[3u * f + 1u], time_mean[3u * f + 2u]);
        for (var s = 0u; s < cs; s++) {
            let b = (f * cs + s) * 3u;
            e += coef[a + s] * vec3<f32>(basis[b], basis[b + 1u], basis[b + 2u]);
        }
    }
    let out = (j * (c + 1u) + r) * 3u;
    frame_rows[out] = e.x;
    frame_rows[out + 1u] = e.y;
    frame_rows[out + 2u] = e.z;
}
