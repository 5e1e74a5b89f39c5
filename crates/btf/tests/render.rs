//! The BTF mesh renderer (thesis §5.5): the CPU reference against the stored images (eq. 5.4),
//! the GPU path against the CPU, horizon and input errors, tangent frames.

use std::sync::OnceLock;

use btf::render::{
    BtfMesh, Camera, Light, RenderParams, RenderedImage, render_cpu, tangent_frames,
};
use btf::{BtfError, BtfPca, BtfPcaParams, DIRECTIONS, Sampling, ViewSlot};
use glam::{Mat3, Vec2, Vec3, Vec4};
use synth::{WovenBtf, WovenBtfParams};

/// Normtexture resolution of the test BTF.
const RES: usize = 16;
/// Components per slot.
const COMPONENTS: usize = 8;
/// Sampling of the test BTF.
const SAMPLING: Sampling = Sampling::H1;

/// The woven cloth of `synth` at 16², all 81 views rendered in memory, compressed to c = 8 in
/// the default 8-bit storage.
fn woven_pca() -> &'static BtfPca {
    static PCA: OnceLock<BtfPca> = OnceLock::new();
    PCA.get_or_init(|| {
        let woven = WovenBtf::new(&WovenBtfParams {
            res: RES,
            supersample: 1,
            ..Default::default()
        })
        .expect("woven BTF");
        let load = |j: usize| {
            let hits = woven
                .view(SAMPLING.vector(j))
                .expect("view above the horizon");
            let data = (0..DIRECTIONS)
                .flat_map(|i| hits.shade(SAMPLING.vector(i)))
                .flatten()
                .collect();
            ViewSlot::new(j, RES, RES, data)
        };
        let params = BtfPcaParams {
            components: COMPONENTS,
            ..Default::default()
        };
        BtfPca::compress_with(SAMPLING, RES, RES, &params, load, None)
            .expect("compress")
            .0
    })
}

/// An owned mesh with everything `BtfMesh` borrows.
struct OwnedMesh {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    tangents: Vec<Vec4>,
    uvs: Vec<Vec2>,
    triangles: Vec<[u32; 3]>,
}

impl OwnedMesh {
    fn new(
        positions: Vec<Vec3>,
        normals: Vec<Vec3>,
        uvs: Vec<Vec2>,
        triangles: Vec<[u32; 3]>,
    ) -> Self {
        let tangents = tangent_frames(&positions, &normals, &uvs, &triangles).expect("tangents");
        Self {
            positions,
            normals,
            tangents,
            uvs,
            triangles,
        }
    }

    fn mesh(&self) -> BtfMesh<'_> {
        BtfMesh {
            positions: &self.positions,
            normals: &self.normals,
            tangents: &self.tangents,
            uvs: &self.uvs,
            triangles: &self.triangles,
        }
    }
}

/// A UV sphere of radius 1 at the origin, `rings` × `segments` quads, the texture repeated
/// `repeat` times around and along it.
fn uv_sphere(rings: u32, segments: u32, repeat: f32) -> OwnedMesh {
    let (mut positions, mut normals, mut uvs, mut triangles) = (vec![], vec![], vec![], vec![]);
    for r in 0..=rings {
        let theta = std::f32::consts::PI * r as f32 / rings as f32;
        for s in 0..=segments {
            let phi = std::f32::consts::TAU * s as f32 / segments as f32;
            let n = Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                -theta.sin() * phi.sin(),
            );
            positions.push(n);
            normals.push(n);
            uvs.push(Vec2::new(
                repeat * s as f32 / segments as f32,
                0.5 * repeat * r as f32 / rings as f32,
            ));
        }
    }
    let row = segments + 1;
    for r in 0..rings {
        for s in 0..segments {
            let (a, b) = (r * row + s, r * row + s + 1);
            let (c, d) = (a + row, b + row);
            triangles.push([a, c, b]);
            triangles.push([b, c, d]);
        }
    }
    OwnedMesh::new(positions, normals, uvs, triangles)
}

/// A sheet bent like a wave, z = 0.3 sin(2x), over [−1, 1]², `n` × `n` quads.
fn bent_sheet(n: u32) -> OwnedMesh {
    let (mut positions, mut normals, mut uvs, mut triangles) = (vec![], vec![], vec![], vec![]);
    for i in 0..=n {
        for k in 0..=n {
            let (x, y) = (
                2.0 * k as f32 / n as f32 - 1.0,
                2.0 * i as f32 / n as f32 - 1.0,
            );
            positions.push(Vec3::new(x, y, 0.3 * (2.0 * x).sin()));
            normals.push(Vec3::new(-0.6 * (2.0 * x).cos(), 0.0, 1.0).normalize());
            uvs.push(Vec2::new(1.5 * (x + 1.0), 1.5 * (1.0 - y)));
        }
    }
    let row = n + 1;
    for i in 0..n {
        for k in 0..n {
            let (a, b) = (i * row + k, i * row + k + 1);
            let (c, d) = (a + row, b + row);
            triangles.push([a, b, d]);
            triangles.push([a, d, c]);
        }
    }
    OwnedMesh::new(positions, normals, uvs, triangles)
}

/// Number of distinct view slots with a non-zero weight ω at the vertices of `mesh` that face
/// the eye (computed as the renderer does, from the tangent frames).
#[cfg(feature = "gpu")]
fn view_slots_used(mesh: &OwnedMesh, eye: Vec3) -> usize {
    let mut used = [false; DIRECTIONS];
    for (v, p) in mesh.positions.iter().enumerate() {
        let (n, t) = (mesh.normals[v].normalize(), mesh.tangents[v]);
        let b = t.w * n.cross(t.truncate());
        let to_eye = eye - *p;
        if to_eye.dot(n) <= 0.0 {
            continue;
        }
        let dir = Vec3::new(to_eye.dot(t.truncate()), to_eye.dot(b), to_eye.dot(n));
        for (j, _) in SAMPLING.view_weights(dir).iter() {
            used[j] = true;
        }
    }
    used.iter().filter(|u| **u).count()
}

/// Mean absolute difference of two images after tone mapping, in 8-bit sRGB steps.
#[cfg(feature = "gpu")]
#[track_caller]
fn mean_abs_srgb8(a: &RenderedImage, b: &RenderedImage) -> f64 {
    let (pa, pb) = (a.to_srgb8(), b.to_srgb8());
    assert_eq!(pa.len(), pb.len());
    let sum: u64 = pa
        .iter()
        .zip(&pb)
        .flat_map(|(p, q)| (0..3).map(move |k| u64::from(p[k].abs_diff(q[k]))))
        .sum();
    sum as f64 / (3 * pa.len()) as f64
}

#[cfg(feature = "gpu")]
fn gpu() -> Option<gpu_context::GpuContext> {
    match gpu_context::GpuContext::new(&gpu_context::GpuOptions::default()) {
        Ok(g) => Some(g),
        Err(e) => test_data::skip(&format!("no GPU adapter: {e}")),
    }
}

/// GPU and CPU agree within 1/255 on average (8-bit sRGB) on curved meshes where many view
/// slots are used, for a directional and a point light; the only differences are float
/// rounding and the GPU's fixed-point rasterisation at silhouettes and texel borders.
/// Set `BTF_RENDER_DUMP=<folder>` to write both images of each case as PNG.
#[cfg(feature = "gpu")]
#[test]
fn gpu_matches_cpu_on_curved_meshes() {
    let Some(ctx) = gpu() else {
        return;
    };
    let pca = woven_pca();
    let renderer = btf::render::GpuBtfRenderer::new(&ctx.device, &ctx.queue, pca).unwrap();
    let sphere = uv_sphere(16, 24, 4.0);
    let sheet = bent_sheet(16);
    let params = RenderParams::default();
    let cases = [
        (
            "sphere, directional",
            &sphere,
            Light::Directional {
                dir_to_light_world: Vec3::new(0.4, 0.8, 0.6),
                radiance: Vec3::splat(2.5),
            },
            Camera::look_at(Vec3::new(0.5, 0.8, 3.0), Vec3::ZERO, Vec3::Y, 45.0, 96, 96),
        ),
        (
            "sheet, point",
            &sheet,
            Light::Point {
                position_world: Vec3::new(-0.5, 0.7, 1.5),
                radiance: Vec3::new(2.5, 2.2, 2.0),
            },
            Camera::look_at(
                Vec3::new(1.5, -2.0, 2.0),
                Vec3::ZERO,
                Vec3::Z,
                50.0,
                128,
                96,
            ),
        ),
        (
            "sphere, point",
            &sphere,
            Light::Point {
                position_world: Vec3::new(-2.0, 1.0, 2.0),
                radiance: Vec3::splat(3.0),
            },
            Camera::look_at(
                Vec3::new(-0.5, -0.3, 2.8),
                Vec3::ZERO,
                Vec3::Y,
                50.0,
                96,
                96,
            ),
        ),
    ];
    for (name, mesh, light, camera) in cases {
        let t0 = std::time::Instant::now();
        let cpu = render_cpu(pca, &mesh.mesh(), &light, &camera, &params).unwrap();
        let t_cpu = t0.elapsed();
        let t0 = std::time::Instant::now();
        let gpu = renderer
            .render(&mesh.mesh(), &light, &camera, &params)
            .unwrap();
        let t_gpu = t0.elapsed();
        let diff = mean_abs_srgb8(&cpu, &gpu);
        if let Ok(dir) = std::env::var("BTF_RENDER_DUMP") {
            let stem = name.replace([',', ' '], "_");
            cpu.write_png(&std::path::Path::new(&dir).join(format!("{stem}_cpu.png")))
                .unwrap();
            gpu.write_png(&std::path::Path::new(&dir).join(format!("{stem}_gpu.png")))
                .unwrap();
        }
        let covered = cpu.coverage().iter().filter(|c| **c).count();
        let max_linear = cpu
            .pixels()
            .iter()
            .zip(gpu.pixels())
            .zip(cpu.coverage().iter().zip(gpu.coverage()))
            .filter(|(_, (a, b))| **a && **b)
            .flat_map(|((p, q), _)| (0..3).map(move |k| (p[k] - q[k]).abs()))
            .fold(0.0f32, f32::max);
        let coverage_diff = cpu
            .coverage()
            .iter()
            .zip(gpu.coverage())
            .filter(|(a, b)| a != b)
            .count();
        let lit = cpu.pixels().iter().filter(|p| p[0] > 0.02).count();
        eprintln!(
            "{name}: mean |GPU − CPU| = {diff:.4} (8-bit), max {max_linear:e} (linear, pixels \
             both cover), coverage differs at {coverage_diff} of {covered} covered pixels, \
             {lit} lit; CPU {t_cpu:?}, GPU ({}) {t_gpu:?}",
            ctx.summary()
        );
        let slots = view_slots_used(mesh, camera.eye);
        eprintln!("{name}: {slots} view slots used by front-facing vertices");
        assert!(slots >= 12, "{name}: only {slots} view slots");
        assert!(
            covered > camera.width as usize * camera.height as usize / 8,
            "{name}"
        );
        assert!(lit > covered / 4, "{name}: the light reaches the mesh");
        assert!(diff <= 1.0, "{name}: mean difference {diff} > 1/255");
        assert!(
            coverage_diff <= covered / 50,
            "{name}: coverage differs at {coverage_diff}"
        );
    }
}

/// The thesis's eq. 5.4 at a measured view and light direction: every covered pixel of a quad
/// whose every vertex sees view slot j and light i exactly shows the texel of the stored
/// reconstruction N_ij = `BtfPca::image(j, i)` it maps to (× g).
///
/// To make the view direction the same at all four vertices, the camera sits at the origin
/// 2¹⁹ units in front of a 2 × 2 quad (the view directions differ by < 2·10⁻⁶ rad, below
/// `ANGLE_SNAP_DEG`) with a field of view that maps the quad onto the central 64 × 64 pixels
/// of a 96 × 96 image, 4 pixels per texel. The quad's shading frame is rotated so that the
/// direction to the eye is view slot j in it.
#[test]
fn quad_at_measured_directions_shows_the_stored_image() {
    let pca = woven_pca();
    let (w, quad_px) = (96u32, 64u32);
    let distance = 524_288.0f32;
    let half_fov = (1.0 / distance * w as f32 / quad_px as f32).atan();
    for (j, i) in [(0usize, 0usize), (12, 30), (40, 7), (70, 50)] {
        let view = SAMPLING.vector(j);
        let light = SAMPLING.vector(i);
        // world_from_tangent maps the view direction in tangent space to +z (toward the eye).
        let world_from_tangent = Mat3::from_quat(glam::Quat::from_rotation_arc(view, Vec3::Z));
        let (t, b, n) = (
            world_from_tangent.x_axis,
            world_from_tangent.y_axis,
            world_from_tangent.z_axis,
        );
        let positions = vec![
            Vec3::new(-1.0, -1.0, -distance),
            Vec3::new(1.0, -1.0, -distance),
            Vec3::new(1.0, 1.0, -distance),
            Vec3::new(-1.0, 1.0, -distance),
        ];
        // u along +x (image right), v along −y (image down).
        let uvs = vec![
            Vec2::new(0.0, 1.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(0.0, 0.0),
        ];
        let tangent = t.extend(if n.cross(t).dot(b) < 0.0 { -1.0 } else { 1.0 });
        let owned = OwnedMesh {
            positions,
            normals: vec![n; 4],
            tangents: vec![tangent; 4],
            uvs,
            triangles: vec![[0, 1, 2], [0, 2, 3]],
        };
        let camera = Camera {
            near: distance / 2.0,
            far: distance * 2.0,
            ..Camera::look_at(
                Vec3::ZERO,
                Vec3::new(0.0, 0.0, -1.0),
                Vec3::Y,
                2.0 * half_fov.to_degrees(),
                w,
                w,
            )
        };
        let g = Vec3::new(1.0, 0.8, 0.6);
        let light = Light::Directional {
            dir_to_light_world: world_from_tangent * light,
            radiance: g,
        };
        let image = render_cpu(
            pca,
            &owned.mesh(),
            &light,
            &camera,
            &RenderParams::default(),
        )
        .unwrap();
        let stored = pca.image(j, i);
        let lo = (w - quad_px) / 2;
        let per_texel = quad_px as usize / RES;
        for y in 0..w {
            for x in 0..w {
                let inside = (lo..lo + quad_px).contains(&x) && (lo..lo + quad_px).contains(&y);
                assert_eq!(image.covered(x, y), inside, "({j}, {i}) pixel ({x}, {y})");
                if !inside {
                    continue;
                }
                let tx = (x - lo) as usize / per_texel;
                let ty = (y - lo) as usize / per_texel;
                let want = stored[ty * RES + tx];
                let got = image.pixel(x, y);
                for k in 0..3 {
                    let expected = g[k] * want[k];
                    let tol = 4.0 * f32::EPSILON * (expected.abs() + 1e-3);
                    assert!(
                        (got[k] - expected).abs() <= tol,
                        "({j}, {i}) pixel ({x}, {y}) channel {k}: {} vs {expected}",
                        got[k]
                    );
                }
            }
        }
    }
}

/// A light at or below every vertex's horizon gives black (the normtextures include the
/// cosine falloff; τ = 0 below the horizon), on both paths; the background stays.
#[test]
fn light_below_the_horizon_is_black() {
    let pca = woven_pca();
    let sheet = bent_sheet(8);
    let camera = Camera::look_at(Vec3::new(0.3, -0.5, 3.0), Vec3::ZERO, Vec3::Y, 50.0, 48, 48);
    let mut params = RenderParams::default();
    params.background = Vec3::new(0.1, 0.2, 0.3);
    // Every normal of the sheet has n·z ≥ 0.85, so a light from −z is below all horizons.
    let light = Light::Directional {
        dir_to_light_world: Vec3::new(0.0, 0.1, -1.0),
        radiance: Vec3::splat(5.0),
    };
    let check = |image: &RenderedImage, what: &str| {
        let mut covered = 0;
        for (p, c) in image.pixels().iter().zip(image.coverage()) {
            if *c {
                covered += 1;
                assert_eq!(*p, [0.0; 3], "{what}");
            } else {
                assert_eq!(*p, [0.1, 0.2, 0.3], "{what}");
            }
        }
        assert!(covered > 100, "{what}: {covered} covered");
    };
    let cpu = render_cpu(pca, &sheet.mesh(), &light, &camera, &params).unwrap();
    check(&cpu, "CPU");
    #[cfg(feature = "gpu")]
    if let Some(ctx) = gpu() {
        let renderer = btf::render::GpuBtfRenderer::new(&ctx.device, &ctx.queue, pca).unwrap();
        let gpu = renderer
            .render(&sheet.mesh(), &light, &camera, &params)
            .unwrap();
        check(&gpu, "GPU");
    }
}

/// Invalid meshes, lights and cameras are errors naming the element, never panics.
#[test]
fn invalid_inputs_are_errors_naming_the_element() {
    let pca = woven_pca();
    let sheet = bent_sheet(2);
    let camera = Camera::look_at(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y, 45.0, 16, 16);
    let light = Light::Directional {
        dir_to_light_world: Vec3::Z,
        radiance: Vec3::ONE,
    };
    let params = RenderParams::default();
    let render = |mesh: BtfMesh<'_>| render_cpu(pca, &mesh, &light, &camera, &params);
    let message = |r: Result<RenderedImage, BtfError>| match r {
        Err(e) => e.to_string(),
        Ok(_) => panic!("expected an error"),
    };

    let no_uvs = BtfMesh {
        uvs: &[],
        ..sheet.mesh()
    };
    let e = render(no_uvs);
    assert!(matches!(
        e,
        Err(BtfError::LengthMismatch {
            what: "BtfMesh uvs",
            found: 0,
            ..
        })
    ));
    let no_tangents = BtfMesh {
        tangents: &[],
        ..sheet.mesh()
    };
    assert!(message(render(no_tangents)).contains("BtfMesh tangents"));
    let short_normals = BtfMesh {
        normals: &sheet.normals[1..],
        ..sheet.mesh()
    };
    assert!(message(render(short_normals)).contains("BtfMesh normals"));

    let mut bad_tangents = sheet.tangents.clone();
    bad_tangents[4] = sheet.normals[4].extend(1.0);
    let parallel = BtfMesh {
        tangents: &bad_tangents,
        ..sheet.mesh()
    };
    let m = message(render(parallel));
    assert!(m.contains("tangents") && m.contains("vertex 4"), "{m}");
    bad_tangents[4] = Vec4::ZERO;
    let zero = BtfMesh {
        tangents: &bad_tangents,
        ..sheet.mesh()
    };
    assert!(message(render(zero)).contains("vertex 4"));

    let mut bad_normals = sheet.normals.clone();
    bad_normals[2] = Vec3::ZERO;
    let zero_normal = BtfMesh {
        normals: &bad_normals,
        ..sheet.mesh()
    };
    let m = message(render(zero_normal));
    assert!(m.contains("normals") && m.contains("vertex 2"), "{m}");

    let bad_triangles = [[0, 1, 99]];
    let out_of_range = BtfMesh {
        triangles: &bad_triangles,
        ..sheet.mesh()
    };
    assert!(message(render(out_of_range)).contains("triangle 0"));

    let mut nan = sheet.positions.clone();
    nan[3].y = f32::NAN;
    let nan_mesh = BtfMesh {
        positions: &nan,
        ..sheet.mesh()
    };
    assert!(matches!(
        render(nan_mesh),
        Err(BtfError::NonFinite { index: 3, .. })
    ));

    let zero_light = Light::Directional {
        dir_to_light_world: Vec3::ZERO,
        radiance: Vec3::ONE,
    };
    let m = message(render_cpu(
        pca,
        &sheet.mesh(),
        &zero_light,
        &camera,
        &params,
    ));
    assert!(m.contains("dir_to_light_world"), "{m}");
    for bad in [
        Camera { width: 0, ..camera },
        Camera {
            fov_y_deg: 180.0,
            ..camera
        },
        Camera {
            target: camera.eye,
            ..camera
        },
        Camera {
            up: Vec3::Z,
            ..camera
        },
        Camera {
            near: 0.0,
            ..camera
        },
    ] {
        let m = message(render_cpu(pca, &sheet.mesh(), &light, &bad, &params));
        assert!(m.starts_with("Camera"), "{m}");
    }

    let e = tangent_frames(&sheet.positions, &sheet.normals, &[], &sheet.triangles);
    assert!(matches!(
        e,
        Err(BtfError::LengthMismatch {
            what: "tangent_frames uvs",
            ..
        })
    ));

    // An empty mesh is valid: only background.
    let empty = BtfMesh {
        positions: &[],
        normals: &[],
        tangents: &[],
        uvs: &[],
        triangles: &[],
    };
    let image = render(empty).unwrap();
    assert!(image.coverage().iter().all(|c| !c));
    #[cfg(feature = "gpu")]
    if let Some(ctx) = gpu() {
        let renderer = btf::render::GpuBtfRenderer::new(&ctx.device, &ctx.queue, pca).unwrap();
        assert_eq!(
            renderer.render(&empty, &light, &camera, &params).unwrap(),
            image
        );
        let no_uvs = BtfMesh {
            uvs: &[],
            ..sheet.mesh()
        };
        assert!(matches!(
            renderer.render(&no_uvs, &light, &camera, &params),
            Err(BtfError::LengthMismatch {
                what: "BtfMesh uvs",
                ..
            })
        ));
    }
}

/// Tangents follow ∂P/∂u, with w giving ∂P/∂v's side; mirrored UVs flip w; a vertex of only
/// UV-degenerate triangles gets some unit tangent perpendicular to its normal.
#[test]
fn tangent_frames_follow_the_uv_gradient() {
    let p = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(5.0, 5.0, 0.0)];
    let n = [Vec3::Z; 4];
    // u along +y, v along +x: t = +y, n × t = −x, opposite to ∂P/∂v: w = −1.
    let uv = [Vec2::ZERO, Vec2::Y, Vec2::X, Vec2::splat(0.5)];
    let t = tangent_frames(&p, &n, &uv, &[[0, 1, 2], [1, 3, 2]]).unwrap();
    for tk in &t[..3] {
        assert!(tk.truncate().abs_diff_eq(Vec3::Y, 1e-6), "{tk:?}");
        assert_eq!(tk.w, -1.0);
    }
    // Vertex 3 lies only in the second triangle, whose UVs are collinear (skipped); vertices
    // 1 and 2 keep the first triangle's tangent. Vertex 3's is arbitrary but valid.
    let t3 = t[3].truncate();
    assert!((t3.length() - 1.0).abs() < 1e-6 && t3.dot(Vec3::Z).abs() < 1e-6);

    // A curved mesh: every tangent is unit and perpendicular to its normal, w = ±1.
    let sphere = uv_sphere(8, 12, 1.0);
    for (t, n) in sphere.tangents.iter().zip(&sphere.normals) {
        assert!((t.truncate().length() - 1.0).abs() < 1e-5);
        assert!(t.truncate().dot(*n).abs() < 1e-5);
        assert!(t.w == 1.0 || t.w == -1.0);
    }
}

/// The PNG is the tone-mapped image (sRGB of the clamped linear values).
#[test]
fn png_holds_the_tone_mapped_image() {
    let pca = woven_pca();
    let sheet = bent_sheet(4);
    let camera = Camera::look_at(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y, 50.0, 40, 30);
    let light = Light::Point {
        position_world: Vec3::new(0.0, 0.0, 2.0),
        radiance: Vec3::splat(3.0),
    };
    let image = render_cpu(
        pca,
        &sheet.mesh(),
        &light,
        &camera,
        &RenderParams::default(),
    )
    .unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("render.png");
    image.write_png(&path).unwrap();
    let read = image::open(&path).unwrap().to_rgb8();
    assert_eq!(read.dimensions(), (40, 30));
    let want: Vec<u8> = image.to_srgb8().into_iter().flatten().collect();
    assert_eq!(read.into_raw(), want);
}
