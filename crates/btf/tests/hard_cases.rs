//! Named adversarial cases of light/view interpolation and per-view PCA (DESIGN.md, "Hard
//! cases stay numerically stable"), and of the BTF folder reader (issue #12): image headers
//! that claim more pixels than their files hold, and a FIFO named like an image; fin geometry
//! (no silhouette, border, crease, offset 1e5) and the fin BTF (black and constant image sets,
//! the alpha cut, a 10⁴× light); under environment light (§5.5.2), a seam in the tangent frame
//! and a view at θ = 0 (the others — every direction occluded, a light exactly at a measured
//! direction, a 10⁴× sun — are in `env_light.rs`).

mod common;
#[path = "common/env.rs"]
mod env_common;

use btf::{BtfPca, BtfPcaParams, DIRECTIONS, Sampling, Storage, ViewSlot};
use common::{analytic, analytic_pca, analytic_slot, assert_close};
use glam::Vec3;

const RES: usize = 16;

fn exact_params(components: usize) -> BtfPcaParams {
    BtfPcaParams {
        components,
        storage: Storage::F32,
        mean_storage: Storage::F32,
        ..Default::default()
    }
}

#[test]
fn light_exactly_at_a_measured_direction() {
    for s in Sampling::ALL {
        for i in 0..DIRECTIONS {
            let w = s.light_weights(s.vector(i));
            assert_eq!(w.len(), 1, "{s} light {i}: {w:?}");
            assert_eq!((w.indices[0], w.weights[0]), (i, 1.0), "{s} light {i}");
            let (t, p) = s.dir(i);
            let w = s.light_weights_deg(f64::from(t), f64::from(p) + 360.0);
            assert_eq!((w.len(), w.indices[0]), (1, i), "{s} light {i} (φ + 360°)");
            let v = s.view_weights(s.vector(i));
            assert_eq!((v.len(), v.indices[0], v.weights[0]), (1, i, 1.0));
        }
    }
    // The reconstruction equals the stored image, and the stored image its input.
    let s = Sampling::H1;
    let pca = analytic_pca(s, RES, &exact_params(80));
    for (j, i) in [(0, 0), (5, 17), (40, 80), (80, 36)] {
        let from_dir = pca.image_from_gamma(j, &pca.gamma(j, s.vector(i)));
        assert_eq!(from_dir, pca.image(j, i), "slot {j}, light {i}");
        for (t, rgb) in from_dir.iter().enumerate() {
            let want = analytic(s, j, i, t % RES, t / RES, RES);
            for c in 0..3 {
                assert_close(f64::from(rgb[c]), f64::from(want[c]), 1e-4, "texel");
            }
        }
        // eval at a texel centre of view slot j and light i gives the same texel.
        let (u, v) = ((3.5 / RES as f32), (7.5 / RES as f32));
        assert_eq!(
            pca.eval(s.vector(j), s.vector(i), u, v),
            from_dir[7 * RES + 3]
        );
    }
}

#[test]
fn light_at_the_horizon_and_below() {
    for s in Sampling::ALL {
        let last = f64::from(s.ring_thetas()[5]);
        for phi in [0.0, 7.5, 100.0, 359.9] {
            assert!(s.light_weights_deg(90.0, phi).is_empty());
            assert!(s.light_weights_deg(120.0, phi).is_empty());
            assert!(s.light_weights_deg(180.0, phi).is_empty());
            assert_close(
                f64::from(s.light_weights_deg(last, phi).sum()),
                1.0,
                1e-6,
                "last ring",
            );
            // Linear fade between the last ring and the horizon.
            let theta = 0.5 * (last + 90.0);
            let w = s.light_weights_deg(theta, phi);
            assert_close(f64::from(w.sum()), 0.5, 1e-6, "half-way to the horizon");
            assert!(w.iter().all(|(i, _)| s.ring_of(i) == 5));
        }
        for dir in [
            Vec3::X,
            Vec3::new(0.3, -0.7, 0.0),
            Vec3::new(1.0, 0.0, -1e-6),
            -Vec3::Z,
            Vec3::ZERO,
            Vec3::new(f32::NAN, 0.0, 1.0),
        ] {
            assert!(s.light_weights(dir).is_empty(), "{s} {dir}");
        }
    }
    let s = Sampling::H2;
    let pca = analytic_pca(s, 4, &BtfPcaParams::default());
    for light in [Vec3::X, Vec3::new(0.2, 0.1, -0.5), -Vec3::Z] {
        assert!(pca.gamma(3, light).iter().all(|&g| g == 0.0));
        assert_eq!(pca.eval(Vec3::Z, light, 0.5, 0.5), [0.0; 3]);
    }
}

#[test]
fn view_at_theta_zero_phi_undefined() {
    for s in Sampling::ALL {
        for dir in [
            Vec3::Z,
            Vec3::new(-0.0, 0.0, 1.0),
            Vec3::new(0.0, -0.0, 2.5),
        ] {
            let w = s.view_weights(dir);
            assert_eq!((w.len(), w.indices[0], w.weights[0]), (1, 0, 1.0), "{dir}");
            let l = s.light_weights(dir);
            assert_eq!((l.len(), l.indices[0], l.weights[0]), (1, 0, 1.0), "{dir}");
        }
        for phi in [0.0, 123.0, f64::NAN] {
            let w = s.view_weights_deg(0.0, phi);
            assert_eq!((w.indices[0], w.weights[0]), (0, 1.0), "φ = {phi}");
        }
        // Tiny tilts in any azimuth: finite weights near the pole, summing to 1.
        for k in 0..16 {
            let a = k as f32 * 0.4;
            let dir = Vec3::new(1e-7 * a.cos(), 1e-7 * a.sin(), 1.0);
            let w = s.view_weights(dir);
            assert!(w.weights.iter().all(|x| x.is_finite()));
            assert_close(f64::from(w.sum()), 1.0, 1e-6, "near-pole sum");
            assert!(w.weights[0] > 0.999 && w.indices[0] == 0);
        }
        // Degenerate view directions count as the normal; grazing views clamp to the last ring.
        assert_eq!(s.view_weights(Vec3::ZERO).indices[0], 0);
        let g = s.view_weights(Vec3::new(0.0, 1.0, -0.3));
        assert_close(f64::from(g.sum()), 1.0, 1e-6, "view below the horizon");
        assert!(g.iter().all(|(i, _)| s.ring_of(i) == 5));
    }
    let s = Sampling::H1;
    let pca = analytic_pca(s, 4, &BtfPcaParams::default());
    let rgb = pca.eval(Vec3::Z, Vec3::new(0.3, 0.2, 0.9), 0.1, 0.9);
    assert!(rgb.iter().all(|c| c.is_finite() && *c > 0.0), "{rgb:?}");
}

#[test]
fn components_larger_than_81() {
    let s = Sampling::H2;
    let params = BtfPcaParams {
        components: 500,
        ..Default::default()
    };
    let (pca, report) =
        BtfPca::compress_with(s, 8, 8, &params, |j| Ok(analytic_slot(s, j, 8)), None)
            .expect("c > 81 is clamped, not an error");
    assert!(report.clamped());
    assert_eq!(report.requested, 500);
    for (j, slot) in pca.slots().iter().enumerate() {
        assert!(slot.components() <= btf::MAX_COMPONENTS);
        assert_eq!(slot.components(), slot.rank(), "slot {j} keeps all it has");
        assert_eq!(report.slots[j].components, slot.components());
    }
    assert_eq!(BtfPca::from_bytes(&pca.to_bytes()).unwrap(), pca);
}

#[test]
fn view_slot_whose_images_are_all_identical() {
    let s = Sampling::H1;
    let res = 8;
    let constant = |j: usize| {
        let one: Vec<f32> = (0..3 * res * res).map(|t| (t % 7) as f32 * 0.1).collect();
        ViewSlot::new(j, res, res, one.repeat(DIRECTIONS))
    };
    let load = |j: usize| {
        if j == 7 {
            constant(j)
        } else {
            Ok(analytic_slot(s, j, res))
        }
    };
    let (pca, report) =
        BtfPca::compress_with(s, res, res, &BtfPcaParams::default(), load, None).unwrap();
    let slot = pca.slot(7);
    assert_eq!((slot.components(), slot.rank()), (0, 0));
    assert!(slot.eigenvalues().is_empty() && slot.weights().is_empty());
    assert_eq!(report.slots[7].components, 0);
    assert!(pca.slot(6).components() > 0);
    let want = constant(7).unwrap();
    for i in [0, 40, 80] {
        for (t, rgb) in pca.image(7, i).iter().enumerate() {
            for (c, &value) in rgb.iter().enumerate() {
                // Mean stored in 16 bits over [0, 0.6].
                assert_close(
                    f64::from(value),
                    f64::from(want.image(i)[3 * t + c]),
                    1e-5,
                    "mean",
                );
            }
        }
    }
    let g = pca.gamma(7, Vec3::new(0.1, 0.2, 0.8));
    assert_eq!(g.len(), 1);
    assert!(
        pca.eval(s.vector(7), Vec3::Z, 0.3, 0.3)
            .iter()
            .all(|c| c.is_finite())
    );
    assert_eq!(BtfPca::from_bytes(&pca.to_bytes()).unwrap(), pca);
}

/// A deterministic stream of numbers in [0, 1).
fn uniform(seed: u64) -> impl FnMut() -> f64 {
    let mut state = seed;
    move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[test]
fn weights_sum_to_one_and_reproduce_linear_functions_in_a_ring_cell() {
    let mut rnd = uniform(7);
    for s in Sampling::ALL {
        let thetas = s.ring_thetas().map(f64::from);
        for _ in 0..2000 {
            // Inside the rings (not the pole cell, where φ is undefined) and away from the φ
            // wrap at 360°, which is not linear in φ.
            let theta = thetas[1] + rnd() * (thetas[5] - thetas[1]);
            let phi = rnd() * 300.0;
            let (a, b, c) = (rnd() - 0.5, rnd() - 0.5, rnd());
            let f = |t: f64, p: f64| a * t + b * p + c;
            for (what, w) in [
                ("light", s.light_weights_deg(theta, phi)),
                ("view", s.view_weights_deg(theta, phi)),
            ] {
                assert_close(f64::from(w.sum()), 1.0, 1e-6, what);
                assert!(w.len() <= 4 && w.weights.iter().all(|&x| x >= 0.0));
                let interp: f64 = w
                    .iter()
                    .map(|(i, x)| {
                        let (t, p) = s.dir(i);
                        f64::from(x) * f(f64::from(t), f64::from(p))
                    })
                    .sum();
                // Exact up to f32 weights and the snap onto measured angles (≤ 0.001°).
                let tol = (a.abs() + b.abs()) * btf::ANGLE_SNAP_DEG + 1e-6 * 360.0;
                assert_close(interp, f(theta, phi), tol, what);
            }
        }
        // Everywhere on the hemisphere (pole cell and wrap included) the sum is 1.
        for _ in 0..2000 {
            let theta = rnd() * thetas[5];
            let w = s.light_weights_deg(theta, rnd() * 720.0 - 360.0);
            assert_close(f64::from(w.sum()), 1.0, 1e-6, "sum");
        }
    }
}

#[test]
fn pca_with_all_components_reconstructs_within_the_8_bit_quantization_bound() {
    let s = Sampling::H1;
    let res = 12;
    let params = BtfPcaParams {
        components: 80,
        storage: Storage::U8,
        mean_storage: Storage::U8,
        ..Default::default()
    };
    let pca = analytic_pca(s, res, &params);
    let exact = analytic_pca(s, res, &exact_params(80));
    for j in [0, 9, 44, 80] {
        let slot = pca.slot(j);
        let input = analytic_slot(s, j, res);
        assert_eq!(slot.components(), slot.rank(), "all components kept");
        for i in 0..DIRECTIONS {
            // |error| ≤ Δ_0/2 + Σ_k |p_ik| Δ_k/2 (+ f32 rounding), per value.
            let p = slot.light_weights(i);
            let bound = 0.5 * slot.texture(0).step()
                + p.iter()
                    .enumerate()
                    .map(|(k, w)| 0.5 * w.abs() * slot.texture(k + 1).step())
                    .sum::<f32>()
                + 1e-5;
            let got = pca.image(j, i);
            let got_exact = exact.image(j, i);
            for (t, (q, e)) in got.iter().zip(&got_exact).enumerate() {
                for c in 0..3 {
                    let want = input.image(i)[3 * t + c];
                    assert!(
                        (q[c] - want).abs() <= bound,
                        "slot {j} light {i}: {} > {bound}",
                        (q[c] - want).abs()
                    );
                    assert_close(
                        f64::from(e[c]),
                        f64::from(want),
                        2e-5,
                        "f32 storage, all components",
                    );
                }
            }
        }
    }
}

#[test]
fn texel_reconstruction_equals_direct_f64_evaluation_of_the_stored_pca() {
    let s = Sampling::H2;
    let res = 8;
    let pca = analytic_pca(
        s,
        res,
        &BtfPcaParams {
            components: 6,
            ..Default::default()
        },
    );
    let mut rnd = uniform(3);
    for _ in 0..200 {
        let j = (rnd() * 81.0) as usize;
        let light = Vec3::new(rnd() as f32 - 0.5, rnd() as f32 - 0.5, rnd() as f32 + 0.05);
        let (x, y) = ((rnd() * res as f64) as usize, (rnd() * res as f64) as usize);
        let gamma = pca.gamma(j, light);
        // γ in f64 from the weights and τ (eq. 5.3).
        let tau = s.light_weights(light);
        let slot = pca.slot(j);
        let mut gamma64 = vec![0.0f64; slot.components() + 1];
        for (i, w) in tau.iter() {
            gamma64[0] += f64::from(w);
            for (k, p) in slot.light_weights(i).iter().enumerate() {
                gamma64[k + 1] += f64::from(w) * f64::from(*p);
            }
        }
        let got = pca.texel(j, &gamma, x, y);
        let t = 3 * (y * res + x);
        for (c, &got_c) in got.iter().enumerate() {
            let mut want = 0.0f64;
            let mut scale = 0.0f64;
            for (k, g) in gamma64.iter().enumerate() {
                let v = f64::from(slot.texture(k).get(t + c));
                want += g * v;
                scale += (g * v).abs();
            }
            assert_close(f64::from(got_c), want, 1e-5 * scale.max(1.0), "texel");
        }
        // The whole-image path gives the same texel, bit for bit.
        assert_eq!(pca.image_from_gamma(j, &gamma)[y * res + x], got);
    }
}

/// `png` with the IHDR width and height replaced (CRC recomputed): a valid header that claims
/// pixels the file does not hold.
fn png_claiming(png: &[u8], width: u32, height: u32) -> Vec<u8> {
    let mut out = png.to_vec();
    // Signature (8), IHDR length (4), "IHDR" (4), width (4), height (4), … CRC after 13 bytes.
    out[16..20].copy_from_slice(&width.to_be_bytes());
    out[20..24].copy_from_slice(&height.to_be_bytes());
    let crc = crc32fast::hash(&out[12..29]);
    out[29..33].copy_from_slice(&crc.to_be_bytes());
    out
}

#[test]
fn image_headers_that_claim_more_than_the_file_holds() {
    // Issue #12, C3: every image replaced by a 70-byte PNG whose header claims 8192 × 8192,
    // and `btf compress` allocated 65 GB from the header sizes. Now the sizes are checked
    // before anything is allocated: beyond btf::MAX_NORMTEXTURE_SIDE, or (PNG) more pixels
    // than deflate can pack into the file's bytes.
    let tiny = common::png_bytes(1, 1);
    for (w, h, name, why) in [
        (8192, 8192, "huge", "at most 1024"),
        (1024, 1024, "packed", "deflate cannot compress"),
    ] {
        let dir = tempfile::tempdir().unwrap();
        common::write_tiny_dir(dir.path(), Sampling::H1, 1, 1);
        let victim = dir
            .path()
            .join(btf::image_file_name(Sampling::H1, 0, 0, "png"));
        let claiming = png_claiming(&tiny, w, h);
        assert!(
            claiming.len() < 100,
            "{name}: a {}-byte file",
            claiming.len()
        );
        std::fs::write(&victim, &claiming).unwrap();
        let err = btf::BtfDir::open(dir.path()).unwrap_err();
        let message = err.to_string();
        assert!(
            matches!(err, btf::BtfError::ImageTooLarge { .. }),
            "{name}: {err:?}"
        );
        assert!(
            message.contains(&format!("{w} × {h}")) && message.contains(why),
            "{message}"
        );
        assert!(
            message.contains(victim.file_name().unwrap().to_str().unwrap()),
            "{message}"
        );
    }
}

#[cfg(unix)]
#[test]
fn a_fifo_named_like_an_image_is_refused_not_waited_on() {
    let dir = tempfile::tempdir().unwrap();
    common::write_tiny_dir(dir.path(), Sampling::H1, 1, 1);
    let victim = dir
        .path()
        .join(btf::image_file_name(Sampling::H1, 3, 5, "png"));
    std::fs::remove_file(&victim).unwrap();
    test_data::make_fifo(&victim);
    let message = btf::BtfDir::open(dir.path()).unwrap_err().to_string();
    assert!(message.contains("FIFO"), "{message}");
    assert!(
        message.contains(victim.file_name().unwrap().to_str().unwrap()),
        "{message}"
    );
}

#[path = "common/fin_meshes.rs"]
mod fin_meshes;

mod fins {
    use super::fin_meshes::*;
    use btf::fins::{FinBuilder, FinMesh, FinParams, Viewer};
    use glam::Vec3;

    fn build(mesh: &Mesh, viewer: Viewer) -> FinMesh {
        let mut builder = FinBuilder::new(&mesh.triangles, mesh.positions.len()).unwrap();
        let mut fins = FinMesh::default();
        builder.build(
            &mesh.positions,
            &mesh.normals,
            viewer,
            &FinParams::default(),
            &mut fins,
        );
        fins
    }

    /// An eye inside a closed cylinder, on its axis: every triangle faces away, no silhouette,
    /// no fin. Looking down the axis from outside (orthographic), the sides are exactly edge-on
    /// (back-facing by the rule): the outline is the near cap's rim, one loop of 24 fins.
    #[test]
    fn no_silhouette_from_inside_a_closed_cylinder_on_its_axis() {
        let mesh = closed_cylinder(24);
        let inside = build(&mesh, Viewer::Eye(Vec3::new(0.0, 0.0, 0.5)));
        assert!(inside.is_empty(), "{} fins", inside.len());
        assert_eq!(inside.chains(), 0);
        let along = build(&mesh, Viewer::Direction(Vec3::Z));
        assert_eq!((along.len(), along.chains()), (24, 1));
        assert!(
            along.ends.iter().flatten().all(|&v| (24..48).contains(&v)),
            "near rim only"
        );
    }

    /// The border of an open sheet is its silhouette from above and from below, run the other
    /// way round from the other side.
    #[test]
    fn a_silhouette_through_a_border_edge() {
        let mesh = sheet(4, 0.0);
        let above = build(&mesh, Viewer::Direction(Vec3::Y));
        let below = build(&mesh, Viewer::Direction(-Vec3::Y));
        assert_eq!((above.len(), below.len()), (16, 16));
        assert_eq!((above.chains(), below.chains()), (1, 1));
        let mut reversed: Vec<[u32; 2]> = below.ends.iter().map(|&[a, b]| [b, a]).collect();
        let mut forward = above.ends.clone();
        reversed.sort_unstable();
        forward.sort_unstable();
        assert_eq!(forward, reversed);
    }

    /// Two triangles folded into a sharp ridge along x: seen from one side and from exactly
    /// the opposite side, one triangle faces the viewer and the other does not, so the ridge
    /// is a silhouette both times, oriented oppositely.
    #[test]
    fn a_crease_that_is_a_silhouette_for_two_opposite_views() {
        let positions = vec![
            Vec3::ZERO,
            Vec3::X,
            Vec3::new(0.5, -0.2, 1.0),
            Vec3::new(0.5, 0.2, 1.0),
        ];
        let triangles = vec![[0, 1, 2], [1, 0, 3]];
        let mut builder = FinBuilder::new(&triangles, 4).unwrap();
        let view = Vec3::new(0.0, 1.0, 0.05).normalize();
        let one = builder.silhouette_edges(&positions, Viewer::Direction(view));
        let other = builder.silhouette_edges(&positions, Viewer::Direction(-view));
        let ridge = |edges: &[[u32; 2]]| {
            edges
                .iter()
                .copied()
                .find(|e| e.contains(&0) && e.contains(&1))
        };
        let (a, b) = (ridge(&one).unwrap(), ridge(&other).unwrap());
        assert_eq!(a, [b[1], b[0]], "opposite orientation");
    }

    /// A sphere of radius 10 moved by 1e5 on every axis (f32 positions 0.0078 apart there):
    /// the silhouette equals the brute-force f64 test on the same positions, the fins are
    /// finite and their height is kept to the positions' resolution.
    #[test]
    fn fins_on_a_mesh_offset_by_1e5() {
        let offset = Vec3::splat(1e5);
        let mesh = sphere(10.0, 12, 18).offset(offset);
        let eye = offset + Vec3::new(30.0, 12.0, -20.0);
        let mut builder = FinBuilder::new(&mesh.triangles, mesh.positions.len()).unwrap();
        let found = builder.silhouette_edges(&mesh.positions, Viewer::Eye(eye));
        let expected = brute_force_silhouette(&mesh, |p| eye.as_dvec3() - p);
        assert_eq!(unordered(&found), expected);
        let params = FinParams {
            material_size: 1.0,
            height: 0.5,
            offset: 0.0,
        };
        let mut fins = FinMesh::default();
        builder.build(
            &mesh.positions,
            &mesh.normals,
            Viewer::Eye(eye),
            &params,
            &mut fins,
        );
        assert!(!fins.is_empty());
        for f in 0..fins.len() {
            let rise = fins.positions[4 * f + 2].distance(fins.positions[4 * f]);
            assert!((rise - 0.5).abs() < 0.02, "fin {f} rises {rise}");
            assert!(
                fins.texcoords[4 * f..4 * f + 4]
                    .iter()
                    .all(|t| t.is_finite())
            );
        }
    }
}

/// The fin BTF (§5.7.2): degenerate image sets and the alpha cut.
mod fin_btf {
    use btf::fin_pca::{ALPHA_CUT, FIN_SAMPLING, FinPca, fin_alpha};
    use btf::render::{FinShading, fin_fragment};
    use btf::{BtfPcaParams, DIRECTIONS, ViewSlot};
    use glam::Vec3;

    #[test]
    fn a_bald_material_whose_81_images_are_black() {
        let images = ViewSlot::new(0, 4, 4, vec![0.0; DIRECTIONS * 48]).unwrap();
        let fins = FinPca::from_images(&images, &BtfPcaParams::default()).unwrap();
        // Rank 0: only the mean, and every fragment is fully transparent.
        assert_eq!(fins.slot().components(), 0);
        let g = fins.gamma(Vec3::new(0.3, 0.2, 0.9));
        let f = fin_fragment(
            &fins,
            [&g, &g],
            Vec3::splat(1e4),
            [0.3, 0.5],
            0.5,
            &Default::default(),
        );
        assert_eq!(f, [0.0; 4]);
        assert_eq!(FinPca::from_bytes(&fins.to_bytes()).unwrap(), fins);
    }

    #[test]
    fn identical_images_under_every_light() {
        let data: Vec<f32> = (0..DIRECTIONS)
            .flat_map(|_| (0..12).map(|v| v as f32 / 24.0))
            .collect();
        let images = ViewSlot::new(0, 2, 2, data).unwrap();
        let fins = FinPca::from_images(&images, &BtfPcaParams::default()).unwrap();
        assert_eq!(fins.slot().components(), 0);
        // Any light between measured directions: the τ sum to 1, so the image itself.
        let g = fins.gamma(Vec3::new(0.41, -0.33, 0.6).normalize());
        let t = fins.texel(&g, 1, 1);
        for (c, want) in t.iter().zip([9.0 / 24.0, 10.0 / 24.0, 11.0 / 24.0]) {
            assert!((c - want).abs() < 1e-4, "{t:?}");
        }
    }

    #[test]
    fn alpha_exactly_at_the_cut_and_a_sun_far_above_one() {
        // r + g + b exactly at the cut is kept (Listing 5.1: alpha >= 0.04); just below, cut.
        assert_eq!(fin_alpha([0.02, 0.01, 0.01], ALPHA_CUT), 0.04);
        assert_eq!(fin_alpha([0.02, 0.01, 0.0099], ALPHA_CUT), 0.0);
        // A light 10⁴ times brighter than the images' scale: alpha clamps to 1, colour stays
        // finite (premultiplied colour may exceed 1: HDR, tone-mapped later).
        let data: Vec<f32> = (0..DIRECTIONS)
            .flat_map(|i| [0.2 * FIN_SAMPLING.vector(i).z; 3])
            .collect();
        let fins = FinPca::from_images(
            &ViewSlot::new(0, 1, 1, data).unwrap(),
            &BtfPcaParams::default(),
        )
        .unwrap();
        let g = fins.gamma(Vec3::Z);
        let f = fin_fragment(
            &fins,
            [&g, &g],
            Vec3::splat(1e4),
            [0.0, 0.5],
            0.0,
            &FinShading::default(),
        );
        assert_eq!(f[3], 1.0);
        assert!(
            f.iter().all(|c| c.is_finite()) && (f[0] - 2e3).abs() < 2.0,
            "{f:?}"
        );
    }
}

/// Two copies of one vertex at a UV seam: same position and normal, the tangent turned and the
/// bitangent mirrored on one side. Each bins the same sky onto its own measured directions, so
/// W differs, but an isotropic (Lambertian) BTF must show the same radiance on both sides: the
/// seam does not show. An anisotropic W pattern proves the frames were really different.
#[test]
fn env_seam_in_the_tangent_frame() {
    use btf::env::{EnvLightWeights, EnvTransfer};
    let s = Sampling::H1;
    let (pca, lam) = env_common::lambertian(s);
    let (dirs, omega) = env_common::sphere_directions(20_000);
    let omegas = vec![omega; dirs.len()];
    let n = Vec3::new(0.3, 0.8, 0.52).normalize();
    let t = n.any_orthonormal_vector();
    let a = 1.1f32;
    let t2 = t * a.cos() + n.cross(t) * a.sin();
    let frames = [[t, n.cross(t), n], [t2, -n.cross(t2), n]];
    // A coloured sky with a sun, half hidden by a wall.
    let sun = Vec3::new(0.5, 0.7, -0.2).normalize();
    let sky = |d: Vec3| {
        Vec3::new(0.4 + d.y.max(0.0), 0.5, 0.6 - 0.3 * d.x)
            + 50.0 * Vec3::ONE * d.dot(sun).max(0.0).powf(64.0)
    };
    let visible = |_: usize, d: usize| dirs[d].x + 0.3 * dirs[d].z < 0.2;
    let transfer = EnvTransfer::build(s, &frames, &dirs, &omegas, visible);
    let l: Vec<Vec3> = dirs.iter().map(|&d| sky(d)).collect();
    let mut w: Vec<EnvLightWeights> = Vec::new();
    transfer.update(&l, &mut w);
    let differ = (0..DIRECTIONS)
        .filter(|&m| (w[0].weights[m] - w[1].weights[m]).abs().max_element() > 1e-3)
        .count();
    assert!(
        differ > 10,
        "the two frames bin the sky alike ({differ} directions differ)"
    );
    for view in [
        n,
        (n + 0.6 * t).normalize(),
        (n - 0.5 * t2 + 0.3 * n.cross(t)).normalize(),
    ] {
        let rgb: Vec<[f32; 3]> = frames
            .iter()
            .zip(&w)
            .map(|(f, wi)| {
                let local = Vec3::new(view.dot(f[0]), view.dot(f[1]), view.dot(f[2]));
                pca.eval_env(local, wi, 0.1, 0.1)
            })
            .collect();
        let want = lam.albedo(0, 0);
        for c in 0..3 {
            assert!(
                (rgb[0][c] - rgb[1][c]).abs() <= 0.01 * rgb[0][c].abs().max(1e-3),
                "view {view}: {rgb:?} (albedo {want})"
            );
        }
    }
}

/// A view along the normal under an environment uses view slot 0 alone, and the result is
/// finite for every azimuth the tangent frame could give it.
#[test]
fn env_view_at_theta_zero() {
    use btf::env::EnvLightWeights;
    let s = Sampling::H2;
    let pca = analytic_pca(s, 4, &BtfPcaParams::default());
    let mut w = EnvLightWeights::default();
    let dirs: Vec<Vec3> = (0..DIRECTIONS).map(|i| s.vector(i)).collect();
    let l: Vec<Vec3> = (0..DIRECTIONS)
        .map(|i| Vec3::splat(0.1 + 0.01 * i as f32))
        .collect();
    w.add_samples(s, [Vec3::X, Vec3::Y, Vec3::Z], &dirs, &l, |_| true);
    let mut gamma = vec![Vec3::ZERO; pca.gamma_len(0)];
    pca.env_gamma(0, &w, &mut gamma);
    let slot0 = pca.texel_rgb(0, &gamma, 1, 2);
    for view in [
        Vec3::Z,
        Vec3::new(-0.0, 0.0, 1.0),
        Vec3::new(0.0, -0.0, 3.0),
    ] {
        let u = (1.0 + 0.5) / pca.width() as f32;
        let v = (2.0 + 0.5) / pca.height() as f32;
        let rgb = pca.eval_env(view, &w, u, v);
        assert!(rgb.iter().all(|c| c.is_finite()), "{rgb:?}");
        for c in 0..3 {
            assert_close(f64::from(rgb[c]), f64::from(slot0[c]), 1e-6, "slot 0 alone");
        }
    }
}
