//! Benchmark data shared by the criterion benches and the `compare` example: generated
//! deterministically from a seed (so Rust and scikit-learn see the same numbers, via .npy), and
//! the real chickenCrossing trajectories when `../shared/data` is present.
#![allow(dead_code)]

use std::io::Write;
use std::path::Path;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Light directions of a BTF view slot (UBO2003: 81).
pub const BTF_LIGHTS: usize = 81;
/// Texels × RGB of a 256² slot.
pub const BTF_FEATURES: usize = 256 * 256 * 3;
/// k-means benchmark: samples, dimensions, blobs.
pub const BLOB_N: usize = 50_000;
/// Dimensions of the blobs.
pub const BLOB_D: usize = 32;
/// Number of blobs (and k).
pub const BLOB_K: usize = 32;
/// Trajectory benchmark: vertices (rows) and frames (3 columns each).
pub const TRAJ_V: usize = 10_000;
/// Frames of the synthetic trajectories (3F = 600 columns).
pub const TRAJ_F: usize = 200;

fn uniform(r: &mut ChaCha8Rng) -> f64 {
    (r.next_u64() >> 11) as f64 / (1u64 << 53) as f64
}

fn normal(r: &mut ChaCha8Rng) -> f64 {
    let u1 = 1.0 - uniform(r);
    let u2 = uniform(r);
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

/// A BTF view slot: 81 light images of a 256² RGB woven texture, row-major 81 × 196,608 f32.
///
/// Radiance = Σ_r a_r(l) T_r(texel) + noise: eight texture layers (diffuse albedo, two weave
/// directions with their own shading, fibre noise, and four glossy lobes that shift across the
/// weave) times light-dependent factors (cos θ, anisotropic lobes). The spectrum decays like a
/// measured slot: a few dominant components, then a tail, then sensor noise (σ = 0.005).
pub fn btf_slot(seed: u64) -> Vec<f32> {
    let mut r = ChaCha8Rng::seed_from_u64(seed);
    const LAYERS: usize = 8;
    let (w, h) = (256usize, 256usize);
    // Texture layers.
    let phase: Vec<f64> = (0..LAYERS * 4)
        .map(|_| uniform(&mut r) * std::f64::consts::TAU)
        .collect();
    let tint: Vec<[f64; 3]> = (0..LAYERS)
        .map(|_| {
            [
                0.5 + 0.5 * uniform(&mut r),
                0.5 + 0.5 * uniform(&mut r),
                0.5 + 0.5 * uniform(&mut r),
            ]
        })
        .collect();
    let mut layers = vec![0.0f64; LAYERS * BTF_FEATURES];
    for y in 0..h {
        for x in 0..w {
            let (u, v) = (x as f64 / w as f64, y as f64 / h as f64);
            let warp = (std::f64::consts::TAU * 16.0 * u).sin().max(0.0);
            let weft = (std::f64::consts::TAU * 16.0 * v).sin().max(0.0);
            for l in 0..LAYERS {
                let p = &phase[l * 4..l * 4 + 4];
                let f = (l + 1) as f64;
                let val = match l {
                    0 => 0.6 + 0.2 * warp + 0.2 * weft,
                    1 => warp * (0.5 + 0.5 * (std::f64::consts::TAU * 4.0 * v + p[0]).sin()),
                    2 => weft * (0.5 + 0.5 * (std::f64::consts::TAU * 4.0 * u + p[1]).sin()),
                    _ => {
                        let s = (std::f64::consts::TAU * (f * 3.0 * u + p[2])).sin()
                            * (std::f64::consts::TAU * (f * 2.0 * v + p[3])).cos();
                        0.5 * s * if l % 2 == 0 { warp } else { weft }
                    }
                };
                for c in 0..3 {
                    layers[l * BTF_FEATURES + (y * w + x) * 3 + c] = val * tint[l][c];
                }
            }
        }
    }
    // Light factors on a 9 × 9 hemisphere grid.
    let mut out = vec![0.0f32; BTF_LIGHTS * BTF_FEATURES];
    for j in 0..BTF_LIGHTS {
        let theta = (j / 9) as f64 / 9.0 * 1.4;
        let phi = (j % 9) as f64 / 9.0 * std::f64::consts::TAU;
        let (st, ct) = theta.sin_cos();
        let a: Vec<f64> = (0..LAYERS)
            .map(|l| match l {
                0 => ct,
                1 => ct * (1.0 + 0.8 * st * phi.cos()),
                2 => ct * (1.0 + 0.8 * st * phi.sin()),
                _ => {
                    let lobe = (phi - l as f64).cos() * st;
                    0.4 * (lobe.max(0.0)).powi(3) / l as f64
                }
            })
            .collect();
        let row = &mut out[j * BTF_FEATURES..(j + 1) * BTF_FEATURES];
        for (f, o) in row.iter_mut().enumerate() {
            let mut s = 0.0;
            for l in 0..LAYERS {
                s += a[l] * layers[l * BTF_FEATURES + f];
            }
            *o = (s + 0.005 * normal(&mut r)) as f32;
        }
    }
    out
}

/// 32 Gaussian blobs in 32-D with unequal sizes (∝ 0.93^b) and spreads (0.5–2.5), centers
/// uniform in [−6, 6]³²: row-major 50,000 × 32 f64 and the generating labels.
pub fn kmeans_blobs(seed: u64) -> (Vec<f64>, Vec<usize>) {
    let mut r = ChaCha8Rng::seed_from_u64(seed);
    let weights: Vec<f64> = (0..BLOB_K).map(|b| 0.93f64.powi(b as i32)).collect();
    let total: f64 = weights.iter().sum();
    let mut sizes: Vec<usize> = weights
        .iter()
        .map(|w| (w / total * BLOB_N as f64).floor() as usize)
        .collect();
    let short = BLOB_N - sizes.iter().sum::<usize>();
    sizes[0] += short;
    let centers: Vec<f64> = (0..BLOB_K * BLOB_D)
        .map(|_| (uniform(&mut r) - 0.5) * 12.0)
        .collect();
    let spread: Vec<f64> = (0..BLOB_K).map(|_| 0.5 + 2.0 * uniform(&mut r)).collect();
    let mut x = Vec::with_capacity(BLOB_N * BLOB_D);
    let mut labels = Vec::with_capacity(BLOB_N);
    for (b, &s) in sizes.iter().enumerate() {
        for _ in 0..s {
            for f in 0..BLOB_D {
                x.push(centers[b * BLOB_D + f] + spread[b] * normal(&mut r));
            }
            labels.push(b);
        }
    }
    // Shuffle rows so that order carries no information.
    let mut order: Vec<usize> = (0..BLOB_N).collect();
    for i in (1..BLOB_N).rev() {
        let j = (r.next_u64() % (i as u64 + 1)) as usize;
        order.swap(i, j);
    }
    let xs = order
        .iter()
        .flat_map(|&i| x[i * BLOB_D..(i + 1) * BLOB_D].iter().copied())
        .collect();
    let ls = order.iter().map(|&i| labels[i]).collect();
    (xs, ls)
}

/// Synthetic vertex trajectories, row-major 10,000 × 600 (x, y, z per frame for 200 frames):
/// 10 rigid parts of unequal size moving with smooth rotations and translations, a quarter of
/// the vertices skinned to two parts, plus a travelling cloth-like wave and 1e-3 noise.
pub fn trajectories(seed: u64) -> Vec<f64> {
    let mut r = ChaCha8Rng::seed_from_u64(seed);
    const PARTS: usize = 10;
    let d = 3 * TRAJ_F;
    // Per part: rotation axis, amplitude, frequency, phase; translation Fourier coefficients.
    struct Part {
        axis: [f64; 3],
        amp: f64,
        freq: f64,
        phase: f64,
        origin: [f64; 3],
        trans: [[f64; 4]; 3],
        wave: f64,
    }
    let parts: Vec<Part> = (0..PARTS)
        .map(|_| {
            let a = [normal(&mut r), normal(&mut r), normal(&mut r)];
            let na = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
            Part {
                axis: [a[0] / na, a[1] / na, a[2] / na],
                amp: 0.3 + 0.7 * uniform(&mut r),
                freq: 1.0 + 3.0 * uniform(&mut r),
                phase: uniform(&mut r) * std::f64::consts::TAU,
                origin: [
                    4.0 * normal(&mut r),
                    4.0 * normal(&mut r),
                    4.0 * normal(&mut r),
                ],
                trans: [0; 3].map(|_| [0; 4].map(|_| 0.5 * normal(&mut r))),
                wave: 0.05 + 0.1 * uniform(&mut r),
            }
        })
        .collect();
    let part_weight: Vec<f64> = (0..PARTS).map(|p| 1.0 + p as f64 * 0.4).collect();
    let wsum: f64 = part_weight.iter().sum();
    let mut x = vec![0.0; TRAJ_V * d];
    for v in 0..TRAJ_V {
        // Part by weighted choice; a quarter of the vertices blend with the next part.
        let mut u = uniform(&mut r) * wsum;
        let mut p = 0;
        while u > part_weight[p] && p + 1 < PARTS {
            u -= part_weight[p];
            p += 1;
        }
        let blend = if uniform(&mut r) < 0.25 {
            0.2 + 0.3 * uniform(&mut r)
        } else {
            0.0
        };
        let q = (p + 1) % PARTS;
        let rest = [normal(&mut r), normal(&mut r), normal(&mut r)];
        for t in 0..TRAJ_F {
            let time = t as f64 / TRAJ_F as f64;
            let mut pos = [0.0; 3];
            for (part, w) in [(p, 1.0 - blend), (q, blend)] {
                if w == 0.0 {
                    continue;
                }
                let pt = &parts[part];
                let angle = pt.amp * (std::f64::consts::TAU * pt.freq * time + pt.phase).sin();
                let rot = rotate(pt.axis, angle, rest);
                let wave = pt.wave * (3.0 * rest[0] - std::f64::consts::TAU * 2.0 * time).sin();
                for c in 0..3 {
                    let tr: f64 = (0..4)
                        .map(|h| {
                            pt.trans[c][h] * (std::f64::consts::TAU * (h + 1) as f64 * time).sin()
                        })
                        .sum();
                    pos[c] += w * (pt.origin[c] + rot[c] + tr + if c == 1 { wave } else { 0.0 });
                }
            }
            for c in 0..3 {
                x[v * d + 3 * t + c] = pos[c] + 1e-3 * normal(&mut r);
            }
        }
    }
    x
}

/// Rodrigues rotation of `p` about unit `axis` by `angle`.
fn rotate(axis: [f64; 3], angle: f64, p: [f64; 3]) -> [f64; 3] {
    let (s, c) = angle.sin_cos();
    let d = axis[0] * p[0] + axis[1] * p[1] + axis[2] * p[2];
    let cross = [
        axis[1] * p[2] - axis[2] * p[1],
        axis[2] * p[0] - axis[0] * p[2],
        axis[0] * p[1] - axis[1] * p[0],
    ];
    [0, 1, 2].map(|i| p[i] * c + cross[i] * s + axis[i] * d * (1.0 - c))
}

/// The chickenCrossing trajectory matrix (3,030 vertices × 3·170 frames), parsed from the `v`
/// lines of the OBJ frames in `../shared/data/anim/chickenCrossing`; None (with a note on
/// stderr) when absent. Benchmarks treat the real data as optional, also under CI.
pub fn chicken() -> Option<(Vec<f64>, usize, usize)> {
    let dir = test_data::data_root().join("anim/chickenCrossing");
    if !dir.join("1.obj").is_file() {
        eprintln!(
            "note: {} not found; skipping the chickenCrossing case",
            dir.display()
        );
        return None;
    }
    let frames = 170;
    let mut per_frame: Vec<Vec<[f64; 3]>> = Vec::with_capacity(frames);
    for f in 1..=frames {
        let text = std::fs::read_to_string(dir.join(format!("{f}.obj"))).ok()?;
        let verts: Vec<[f64; 3]> = text
            .lines()
            .filter_map(|l| l.strip_prefix("v "))
            .map(|l| {
                let mut it = l
                    .split_whitespace()
                    .map(|t| t.parse::<f64>().unwrap_or(f64::NAN));
                [
                    it.next().unwrap_or(f64::NAN),
                    it.next().unwrap_or(f64::NAN),
                    it.next().unwrap_or(f64::NAN),
                ]
            })
            .collect();
        per_frame.push(verts);
    }
    let v = per_frame[0].len();
    if per_frame.iter().any(|f| f.len() != v) {
        return None;
    }
    let d = 3 * frames;
    let mut x = vec![0.0; v * d];
    for (t, frame) in per_frame.iter().enumerate() {
        for (i, p) in frame.iter().enumerate() {
            x[i * d + 3 * t..i * d + 3 * t + 3].copy_from_slice(p);
        }
    }
    Some((x, v, d))
}

/// Writes a C-order 2-D .npy file (format 1.0).
pub fn write_npy(
    path: &Path,
    rows: usize,
    cols: usize,
    descr: &str,
    bytes: &[u8],
) -> std::io::Result<()> {
    let mut header =
        format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': ({rows}, {cols}), }}");
    let unpadded = 10 + header.len() + 1;
    header.push_str(&" ".repeat(unpadded.div_ceil(64) * 64 - unpadded));
    header.push('\n');
    let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
    f.write_all(b"\x93NUMPY\x01\x00")?;
    f.write_all(&(header.len() as u16).to_le_bytes())?;
    f.write_all(header.as_bytes())?;
    f.write_all(bytes)?;
    f.flush()
}

/// f64 values as little-endian bytes.
pub fn f64_bytes(v: &[f64]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// f32 values as little-endian bytes.
pub fn f32_bytes(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}
