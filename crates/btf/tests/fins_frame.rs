//! Fins in the shared frame (thesis §5.7.3, Fig. 5.22): one fin against the CPU's
//! [`fin_fragment`] composited over the background, the opaque surface hiding fins behind it,
//! and the same image whatever order the fins are submitted in.
#![cfg(feature = "gpu")]

use btf::fin_pca::{FIN_SAMPLING, FinPca};
use btf::fins::FinMesh;
use btf::render::{FinShading, GpuFinRenderer, Light, fin_fragment, fin_gammas};
use btf::{BtfPcaParams, DIRECTIONS, Storage, ViewSlot};
use glam::{Vec2, Vec3};
use gpu_context::testing::gpu_or_skip;
use render::{Background, Camera, DrawMesh, FrameFormat, Renderer};

const W: usize = 8;
const H: usize = 4;

/// Orange fibres in even columns, dimmer blue ones in odd columns, brighter towards the base, with
/// a forward lobe: alpha r + g + b well above the cut, so overlapping fins matter.
fn fin_set() -> FinPca {
    let data = (0..DIRECTIONS)
        .flat_map(|i| {
            let l = FIN_SAMPLING.vector(i);
            let light = 0.3 * l.z + 0.25 * (-l.x).max(0.0);
            (0..H).flat_map(move |y| {
                (0..W).flat_map(move |x| {
                    // Two colours, so that "over" (unlike the two passes) would not commute:
                    // for fins of one chromaticity with alpha = r + g + b it does.
                    let (cover, colour) = if x.is_multiple_of(2) {
                        (1.0, [0.9f32, 0.5, 0.2])
                    } else {
                        (0.6, [0.2, 0.5, 0.9])
                    };
                    let cover = cover * (y + 1) as f32 / H as f32;
                    colour.map(|c| c * cover * light)
                })
            })
        })
        .collect();
    let params = BtfPcaParams {
        components: 81,
        storage: Storage::F32,
        mean_storage: Storage::F32,
        ..Default::default()
    };
    FinPca::from_images(&ViewSlot::new(0, W, H, data).unwrap(), &params).unwrap()
}

/// One fin per quad: base (a, b), tips along `up`, s from `d` to `d + len`; its two ends are
/// mesh vertices 2f, 2f + 1 (positions a, b, normals `up`).
struct Fins {
    mesh: FinMesh,
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
}

fn fins(quads: &[(Vec3, Vec3, Vec3, f32, f32)]) -> Fins {
    let mut out = Fins {
        mesh: FinMesh::default(),
        positions: Vec::new(),
        normals: Vec::new(),
    };
    for (f, &(a, b, up, d, len)) in quads.iter().enumerate() {
        let m = &mut out.mesh;
        m.positions.extend([a, b, a + up, b + up]);
        m.texcoords.extend([
            Vec2::new(d, 0.0),
            Vec2::new(d + len, 0.0),
            Vec2::new(d, 1.0),
            Vec2::new(d + len, 1.0),
        ]);
        m.end_weight.extend([0.0, 1.0, 0.0, 1.0]);
        m.ends.push([2 * f as u32, 2 * f as u32 + 1]);
        m.chain.push(f as u32);
        out.positions.extend([a, b]);
        out.normals.extend([up.normalize(), up.normalize()]);
    }
    out
}

fn render(
    gpu: &gpu_context::GpuContext,
    fins_set: &FinPca,
    fins: &Fins,
    camera: &Camera,
    light: &Light,
    background: Background,
    occluder: Option<&[Vec3; 4]>,
) -> Vec<[f32; 4]> {
    let mut renderer = Renderer::new(&gpu.device, FrameFormat::single_sample(&gpu.device));
    if let Some(q) = occluder {
        let grey = [Vec3::splat(0.2); 4];
        renderer
            .gouraud
            .set_meshes(
                &gpu.device,
                &gpu.queue,
                &[DrawMesh {
                    positions: q,
                    triangles: &[[0, 1, 2], [0, 2, 3]],
                    front: &grey,
                    back: &grey,
                }],
            )
            .unwrap();
    }
    let fin_renderer =
        GpuFinRenderer::for_frame(&gpu.device, fins_set, &renderer.pass_context()).unwrap();
    let draw = fin_renderer
        .prepare(
            &fins.mesh,
            &fins.positions,
            &fins.normals,
            light,
            camera.eye,
            &FinShading::default(),
        )
        .unwrap();
    assert_eq!(draw.fins(), fins.mesh.len());
    renderer
        .render(&gpu.device, &gpu.queue, camera, background, &[&draw])
        .unwrap()
        .pixels()
        .to_vec()
}

/// Where the ray through pixel (x, y) meets the plane z = 0.
fn on_plane(camera: &Camera, x: u32, y: u32) -> Vec3 {
    let inv = camera.clip_from_world().unwrap().inverse();
    let ndc = Vec2::new(
        (x as f32 + 0.5) / camera.width as f32 * 2.0 - 1.0,
        1.0 - (y as f32 + 0.5) / camera.height as f32 * 2.0,
    );
    let dir = inv.project_point3(ndc.extend(0.5)) - camera.eye;
    camera.eye + dir * (-camera.eye.z / dir.z)
}

#[test]
fn one_fin_is_the_cpu_fragment_over_the_background_and_the_surface_hides_it() {
    let Some(gpu) = gpu_or_skip() else { return };
    let set = fin_set();
    let camera = Camera::look_at(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, Vec3::Y, 40.0, 96, 64);
    // A fin in the plane z = 0 facing the camera, tips up, s from 0.25 over two repeats.
    let (a, b, up) = (
        Vec3::new(-1.0, -0.5, 0.0),
        Vec3::new(1.0, -0.5, 0.0),
        Vec3::Y,
    );
    let quad = fins(&[(a, b, up, 0.25, 2.0)]);
    let light = Light::Directional {
        dir_to_light_world: Vec3::new(-0.3, 0.8, 0.5),
        radiance: Vec3::new(1.5, 1.2, 1.0),
    };
    let bg = [0.25, 0.3, 0.35];
    let image = render(
        &gpu,
        &set,
        &quad,
        &camera,
        &light,
        Background::Color(bg),
        None,
    );
    let mut gammas = Vec::new();
    fin_gammas(
        &set,
        &quad.mesh,
        &quad.positions,
        &quad.normals,
        &light,
        camera.eye,
        &mut gammas,
    )
    .unwrap();
    let n = set.gamma_len();
    let (mut checked, mut worst) = (0, 0.0f32);
    for y in 0..camera.height {
        for x in 0..camera.width {
            let p = on_plane(&camera, x, y);
            let (u, v) = ((p.x - a.x) / 2.0, p.y - a.y);
            let (s, t) = (0.25 + 2.0 * u, v);
            let near_edge = |q: f32| (q - q.round()).abs() < 0.05;
            if !(0.0..=1.0).contains(&u)
                || !(0.0..=1.0).contains(&v)
                || near_edge(s * W as f32)
                || near_edge(t * H as f32)
            {
                continue;
            }
            let f = fin_fragment(
                &set,
                [&gammas[..n], &gammas[n..]],
                light.radiance(),
                [s, t],
                u,
                &FinShading::default(),
            );
            let got = image[(y * camera.width + x) as usize];
            for c in 0..3 {
                let want = f[c] + (1.0 - f[3]) * bg[c];
                worst = worst.max((got[c] - want).abs());
            }
            checked += 1;
        }
    }
    assert!(checked > 500, "{checked} pixels checked");
    assert!(worst < 2e-4, "largest difference {worst}");

    // A grey quad in front of the fin's left half hides it there.
    let occluder = [
        Vec3::new(-2.0, -2.0, 0.5),
        Vec3::new(-0.2, -2.0, 0.5),
        Vec3::new(-0.2, 2.0, 0.5),
        Vec3::new(-2.0, 2.0, 0.5),
    ];
    let hidden = render(
        &gpu,
        &set,
        &quad,
        &camera,
        &light,
        Background::Color(bg),
        Some(&occluder),
    );
    let centre_left = hidden[(32 * camera.width + 30) as usize];
    assert!(
        (centre_left[0] - 0.2).abs() < 1e-5,
        "the surface in front wins: {centre_left:?}"
    );
}

#[test]
fn the_image_does_not_depend_on_the_order_of_the_fins() {
    let Some(gpu) = gpu_or_skip() else { return };
    let set = fin_set();
    let camera = Camera::look_at(Vec3::new(0.3, 0.2, 5.0), Vec3::ZERO, Vec3::Y, 40.0, 96, 96);
    // 24 fins at different depths and tilts, overlapping in the middle of the image.
    let mut state = 7u64;
    let mut next = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    let quads: Vec<_> = (0..24)
        .map(|_| {
            let a = Vec3::new(-1.2 + next(), -1.0 + next(), -1.0 + 2.0 * next());
            let b = a + Vec3::new(1.0 + next(), 0.4 * next() - 0.2, 0.5 * next() - 0.25);
            let up = Vec3::new(0.3 * next() - 0.15, 1.0 + next(), 0.3 * next() - 0.15);
            (a, b, up, 3.0 * next(), 0.5 + 2.0 * next())
        })
        .collect();
    let light = Light::Point {
        position_world: Vec3::new(-2.0, 3.0, -1.0),
        radiance: Vec3::splat(0.6),
    };
    let background = Background::Transparent;
    let forward = render(&gpu, &set, &fins(&quads), &camera, &light, background, None);
    let mut shuffled = quads.clone();
    shuffled.reverse();
    shuffled.rotate_left(7);
    let backward = render(
        &gpu,
        &set,
        &fins(&shuffled),
        &camera,
        &light,
        background,
        None,
    );
    let mut worst = 0.0f32;
    for (p, q) in forward.iter().zip(&backward) {
        for c in 0..4 {
            worst = worst.max((p[c] - q[c]).abs());
        }
    }
    assert!(worst < 1e-5, "order changes the image by {worst}");
    // The fins do overlap: some pixel is more opaque than any single fin fragment can be
    // (the largest alpha of either end over every texel, computed on the CPU).
    let f = fins(&quads);
    let mut gammas = Vec::new();
    fin_gammas(
        &set,
        &f.mesh,
        &f.positions,
        &f.normals,
        &light,
        camera.eye,
        &mut gammas,
    )
    .unwrap();
    let mut single = 0.0f32;
    for g in gammas.chunks_exact(set.gamma_len()) {
        for y in 0..H {
            for x in 0..W {
                let t = set.texel(g, x, y);
                single = single.max(light.radiance().x * (t[0] + t[1] + t[2]));
            }
        }
    }
    let max_alpha = forward.iter().map(|p| p[3]).fold(0.0, f32::max);
    assert!(single < 0.9, "single-fin alpha {single}");
    assert!(
        max_alpha > single + 0.02,
        "max alpha {max_alpha}, single {single}"
    );
}
