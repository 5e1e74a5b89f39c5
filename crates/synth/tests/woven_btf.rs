//! Properties of the procedural woven-cloth BTF, checked against the height field through
//! the public API and against brute-force ray marches written out here in f64 (not the
//! crate's marcher), so that a registration, masking or shadowing bug shows up.

use glam::{DVec2, DVec3, Vec3};
use rayon::prelude::*;
use synth::{SurfacePoint, SynthError, ViewHits, WovenBtf, WovenBtfParams, Yarn};

/// Brute-force march step, tile units (the crate's fine step is 20–40× longer).
const BRUTE_STEP: f64 = 2e-4;
/// A brute-force ray counts as blocked where the surface rises this far above it.
const BRUTE_BIAS: f64 = 1e-5;

/// d(θ, φ) = (sin θ cos φ, sin θ sin φ, cos θ), angles in degrees.
fn dir(theta_deg: f64, phi_deg: f64) -> Vec3 {
    let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
    DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos()).as_vec3()
}

fn small(res: usize) -> WovenBtfParams {
    WovenBtfParams {
        res,
        ..Default::default()
    }
}

fn btf(params: &WovenBtfParams) -> WovenBtf {
    WovenBtf::new(params).expect("valid parameters")
}

/// Where sub-sample `index` (in the order of [`ViewHits::hits`]) starts on the reference
/// plane: ((i + (a + ½)/n)/res, (j + (b + ½)/n)/res).
fn sample_origin(res: usize, n: usize, index: usize) -> DVec2 {
    let (texel, k) = (index / (n * n), index % (n * n));
    let (i, j, a, b) = (texel % res, texel / res, k % n, k / n);
    DVec2::new(
        (i as f64 + (a as f64 + 0.5) / n as f64) / res as f64,
        (j as f64 + (b as f64 + 0.5) / n as f64) / res as f64,
    )
}

fn height(btf: &WovenBtf, p: DVec2) -> f64 {
    f64::from(btf.surface(p.x as f32, p.y as f32).position.z)
}

/// Distance between two points of the periodic tile.
fn wrapped_distance(a: DVec2, b: DVec2) -> f64 {
    let d = a - b;
    (d - d.round()).length()
}

fn mean_abs_difference(a: &[[f32; 3]], b: &[[f32; 3]]) -> f64 {
    let sum: f64 = a
        .iter()
        .zip(b)
        .map(|(x, y)| (0..3).map(|c| f64::from((x[c] - y[c]).abs())).sum::<f64>())
        .sum();
    sum / (3 * a.len()) as f64
}

fn fraction(hits: &ViewHits, keep: impl Fn(&SurfacePoint) -> bool) -> f64 {
    hits.hits().iter().filter(|h| keep(h)).count() as f64 / hits.hits().len() as f64
}

/// Brute force: is the light blocked for the surface point `p`? March from `p` towards the
/// light in f64 with [`BRUTE_STEP`] until the ray clears the top of the tile.
fn brute_force_shadowed(btf: &WovenBtf, p: DVec3, light: DVec3) -> bool {
    let top = f64::from(btf.height_range().1);
    let horizontal = light.truncate().length();
    if horizontal < 1e-9 {
        return false;
    }
    let (dir, rise) = (light.truncate() / horizontal, light.z / horizontal);
    let end = ((top - p.z) / rise).min(4.0);
    let mut s = BRUTE_STEP;
    while s <= end {
        if height(btf, p.truncate() + dir * s) > p.z + rise * s + BRUTE_BIAS {
            return true;
        }
        s += BRUTE_STEP;
    }
    false
}

/// Brute force: the first point where the ray from `origin` on the plane z_ref along
/// −view meets the surface, marched in f64 with [`BRUTE_STEP`] and refined by bisection.
fn brute_force_hit(btf: &WovenBtf, origin: DVec2, view: DVec3) -> DVec2 {
    let (floor, top) = btf.height_range();
    let horizontal = view.truncate().length();
    let (dir, fall) = (-view.truncate() / horizontal, view.z / horizontal);
    let below = |s: f64| f64::from(top) - fall * s <= height(btf, origin + dir * s);
    let end = f64::from(top - floor) / fall;
    let mut s = BRUTE_STEP;
    while s < end && !below(s) {
        s += BRUTE_STEP;
    }
    let (mut lo, mut hi) = (s - BRUTE_STEP, s.min(end));
    for _ in 0..30 {
        let mid = 0.5 * (lo + hi);
        if below(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    origin + dir * hi
}

#[test]
fn the_height_field_is_a_periodic_plain_weave() {
    let params = WovenBtfParams {
        warp_count: 4,
        weft_count: 6,
        ..small(16)
    };
    let btf = btf(&params);
    let (floor, top) = btf.height_range();
    let mut mismatched = 0;
    let n = 4000;
    for k in 0..n {
        // A low-discrepancy walk over the tile.
        let (x, y) = ((k as f32 * 0.618_034) % 1.0, (k as f32 * 0.754_877_7) % 1.0);
        let p = btf.surface(x, y);
        assert!(p.position.z >= floor && p.position.z <= top + 1e-6);
        assert!((p.normal.length() - 1.0).abs() < 1e-5 && p.normal.z >= 0.0);
        for (dx, dy) in [(1.0, 0.0), (0.0, 1.0), (-3.0, 2.0)] {
            let q = btf.surface(x + dx, y + dy);
            if q.yarn != p.yarn {
                // Only f32 rounding of x + dx can move a point across a yarn's edge.
                mismatched += 1;
                continue;
            }
            assert!(
                (q.position.z - p.position.z).abs() < 1e-5,
                "h({x}, {y}) not periodic"
            );
            assert!(q.normal.dot(p.normal) > 0.9999, "n({x}, {y}) not periodic");
            assert!(q.position.truncate().distance(p.position.truncate()) < 1e-5);
        }
    }
    assert!(
        mismatched * 1000 < 3 * n,
        "{mismatched} points changed yarn"
    );

    // Crossing of warp k and weft m: the warp is on top exactly when k + m is even, the
    // crossing is a local maximum, the thicker warps' crossings are the tile's highest
    // points, and between four crossings lies a gap.
    let mut highest = f32::NEG_INFINITY;
    for k in 0..params.warp_count {
        for m in 0..params.weft_count {
            let y = (f64::from(k) + 0.5) / f64::from(params.warp_count);
            let x = (f64::from(m) + 0.5) / f64::from(params.weft_count);
            let p = btf.surface(x as f32, y as f32);
            let expected = if (k + m) % 2 == 0 {
                Yarn::Warp(k)
            } else {
                Yarn::Weft(m)
            };
            assert_eq!(p.yarn, expected, "crossing of warp {k} and weft {m}");
            let (dx, dy) = (
                0.3 / f64::from(params.weft_count),
                0.3 / f64::from(params.warp_count),
            );
            for (ox, oy) in [(dx, 0.0), (-dx, 0.0), (0.0, dy), (0.0, -dy)] {
                let q = btf.surface((x + ox) as f32, (y + oy) as f32);
                assert!(
                    q.position.z < p.position.z,
                    "crossing ({k}, {m}) is not a maximum"
                );
            }
            highest = highest.max(p.position.z);
            if (k + m) % 2 == 0 {
                assert!((p.position.z - top).abs() < 1e-6);
            }
            let gap_x = f64::from(m + 1) / f64::from(params.weft_count);
            let gap_y = f64::from(k + 1) / f64::from(params.warp_count);
            let gap = btf.surface(gap_x as f32, gap_y as f32);
            assert_eq!((gap.yarn, gap.position.z), (Yarn::Gap, floor));
        }
    }
    assert!((highest - top).abs() < 1e-6);
}

#[test]
fn normals_are_the_gradient_of_the_height() {
    let btf = btf(&small(16));
    let eps = 1e-4f64;
    let mut checked = 0;
    for k in 0..4000 {
        let p = DVec2::new((k as f64 * 0.618_034) % 1.0, (k as f64 * 0.754_877_7) % 1.0);
        let centre = btf.surface(p.x as f32, p.y as f32);
        let around = [(eps, 0.0), (-eps, 0.0), (0.0, eps), (0.0, -eps)]
            .map(|(dx, dy)| btf.surface((p.x + dx) as f32, (p.y + dy) as f32));
        // Only where the height is differentiable: one yarn, away from its steep edge.
        if around.iter().any(|q| q.yarn != centre.yarn) || centre.normal.z < 0.3 {
            continue;
        }
        let hx = f64::from(around[0].position.z - around[1].position.z) / (2.0 * eps);
        let hy = f64::from(around[2].position.z - around[3].position.z) / (2.0 * eps);
        let expected = DVec3::new(-hx, -hy, 1.0).normalize();
        let error = expected
            .dot(centre.normal.as_dvec3())
            .min(1.0)
            .acos()
            .to_degrees();
        assert!(error < 0.5, "normal at {p} off by {error}°");
        checked += 1;
    }
    assert!(checked > 2500, "only {checked} smooth points");
}

/// Frontal view and light: every sub-sample sees the surface straight below its origin,
/// nothing casts a shadow, and each texel is the mean of `k_d ρ n_z + k_s (e+8)/8 n_z^(e+1)`
/// over its sub-samples, evaluated here from the height field alone.
#[test]
fn frontal_view_and_light_are_the_direct_sum_over_the_height_field() {
    for glossy_weight in [0.0, 0.2] {
        let params = WovenBtfParams {
            glossy_weight,
            supersample: 3,
            ..small(24)
        };
        let (res, n) = (params.res, params.supersample);
        let btf = btf(&params);
        let hits = btf.view(Vec3::Z).expect("frontal view");
        assert!(hits.cast_shadows(Vec3::Z).iter().all(|&s| !s));
        let image = hits.shade(Vec3::Z);
        assert_eq!(image.len(), res * res);
        let e = f64::from(params.glossy_exponent);
        let mut max_error = 0.0f64;
        for (texel, value) in image.iter().enumerate() {
            let mut expected = DVec3::ZERO;
            for k in 0..n * n {
                let index = texel * n * n + k;
                let origin = sample_origin(res, n, index);
                let hit = hits.hits()[index];
                // Registration: the hit lies straight below the sub-sample's origin.
                assert!(wrapped_distance(hit.position.truncate().as_dvec2(), origin) < 1e-6);
                let p = btf.surface(origin.x as f32, origin.y as f32);
                assert_eq!(hit.yarn, p.yarn);
                assert!(hit.normal.dot(p.normal) > 1.0 - 1e-6);
                assert!((hit.position.z - p.position.z).abs() < 1e-6);
                let nz = f64::from(p.normal.z);
                let glossy = f64::from(glossy_weight) * (e + 8.0) / 8.0 * nz.powf(e);
                let albedo = f64::from(params.diffuse_weight)
                    * btf.albedo(p.yarn).expect("a yarn of this weave").as_dvec3();
                expected += nz * (albedo + DVec3::splat(glossy));
            }
            expected /= (n * n) as f64;
            let got = DVec3::from_array(value.map(f64::from));
            max_error = max_error.max((got - expected).abs().max_element());
        }
        // f32 shading against this f64 sum: a few ulps of values ≤ 1.
        assert!(
            max_error < 4e-6,
            "k_s {glossy_weight}: texels off by {max_error}"
        );
    }
}

#[test]
fn the_frontal_image_has_the_documented_scale() {
    let params = small(32);
    let image = btf(&params).view(Vec3::Z).expect("view").shade(Vec3::Z);
    let brightest = image.iter().flatten().copied().fold(0.0f32, f32::max);
    // The top of a yarn under frontal light: k_d ρ_max(1 + variation) + k_s (e + 8)/8.
    assert!(
        (0.6..=0.8).contains(&brightest),
        "brightest texel {brightest}"
    );
    let bound = params.diffuse_weight
        * params
            .warp_albedo
            .max_element()
            .max(params.weft_albedo.max_element())
        * (1.0 + params.albedo_variation)
        + params.glossy_weight * (params.glossy_exponent + 8.0) / 8.0;
    assert!(brightest <= bound + 1e-6);
}

/// Oblique views see different points than the frontal one: every hit lies on its
/// sub-sample's ray and is that ray's first intersection (checked by brute force), the gaps
/// disappear, and the yarns running across the view azimuth hide the others.
#[test]
fn oblique_views_show_parallax_and_masking() {
    let params = small(32);
    let (res, n) = (params.res, params.supersample);
    let btf = btf(&params);
    let top = f64::from(btf.height_range().1);
    let frontal = btf.view(Vec3::Z).expect("view");
    let gap = |h: &SurfacePoint| h.yarn == Yarn::Gap;
    let weft = |h: &SurfacePoint| matches!(h.yarn, Yarn::Weft(_));
    let gap_frontal = fraction(&frontal, gap);
    let weft_frontal = fraction(&frontal, weft);
    // The gaps cover (1 − 0.8)² of the tile (up to the sampling: 4 of the 16 sub-samples
    // per pitch fall into a gap 3.2 sub-samples wide).
    assert!(
        (gap_frontal - 0.04).abs() < 0.03,
        "frontal gap fraction {gap_frontal}"
    );

    for phi in [0.0, 90.0, 200.0] {
        let view = dir(75.0, phi);
        let hits = btf.view(view).expect("view");
        let v = view.as_dvec3();
        // Each hit lies on its ray: origin − (v_xy / v_z)(z_ref − z_hit), wrapped.
        for (index, hit) in hits.hits().iter().enumerate() {
            let origin = sample_origin(res, n, index);
            let z = f64::from(hit.position.z);
            let on_ray = origin - v.truncate() / v.z * (top - z);
            let off = wrapped_distance(hit.position.truncate().as_dvec2(), on_ray);
            assert!(off < 1e-4, "φ {phi}: hit {index} is {off} off its ray");
            // On the surface: at the height field, or below it on the face of a yarn's edge.
            let surface = btf.surface(hit.position.x, hit.position.y);
            assert_eq!((surface.yarn, surface.normal), (hit.yarn, hit.normal));
            assert!(hit.position.z <= surface.position.z + 1e-6);
            if hit.position.z < surface.position.z - 1e-3 {
                assert!(
                    hit.normal.z < 0.05,
                    "φ {phi}: hit {index} below a non-vertical face"
                );
            }
        }
        // ... and is the first intersection (brute force on every 7th sub-sample).
        let checked: Vec<usize> = (0..hits.hits().len()).step_by(7).collect();
        let far: usize = checked
            .par_iter()
            .filter(|&&index| {
                let expected = brute_force_hit(&btf, sample_origin(res, n, index), v);
                let got = hits.hits()[index].position.truncate().as_dvec2();
                wrapped_distance(got, expected) > 2e-3
            })
            .count();
        assert!(
            far * 100 <= checked.len(),
            "φ {phi}: {far} of {} hits are not the first intersection",
            checked.len()
        );

        let gap_oblique = fraction(&hits, gap);
        assert!(
            gap_oblique < 0.25 * gap_frontal,
            "φ {phi}: gaps {gap_oblique}"
        );
        let image = hits.shade(Vec3::Z);
        let difference = mean_abs_difference(&image, &frontal.shade(Vec3::Z));
        assert!(
            difference > 0.08,
            "φ {phi}: image barely changed ({difference})"
        );
    }
    // Seen along the warp (φ = 0) the wefts, which run across the view, hide the warps;
    // seen along the weft (φ = 90°) the other way round.
    let along_warp = fraction(&btf.view(dir(75.0, 0.0)).expect("view"), weft);
    let along_weft = fraction(&btf.view(dir(75.0, 90.0)).expect("view"), weft);
    assert!(
        along_warp > weft_frontal + 0.1 && along_weft < weft_frontal - 0.07,
        "weft fractions: frontal {weft_frontal}, along warp {along_warp}, along weft {along_weft}"
    );
}

/// Grazing light casts shadows; a light overhead or behind the viewer casts none that the
/// viewer sees; and the crate's shadow test (table plus traced rays) agrees with a
/// brute-force f64 march on ≥ 99% of the sub-samples.
#[test]
fn grazing_light_casts_shadows_that_brute_force_confirms() {
    let btf = btf(&small(32));
    for (view, light) in [
        (dir(0.0, 0.0), dir(80.0, 30.0)),
        (dir(0.0, 0.0), dir(85.0, 0.0)),
        (dir(51.0, 120.0), dir(80.0, 200.0)),
        (dir(34.0, 300.0), dir(75.0, 90.0)),
    ] {
        let hits = btf.view(view).expect("view");
        let shadows = hits.cast_shadows(light);
        let facing: Vec<usize> = (0..shadows.len())
            .filter(|&i| hits.hits()[i].normal.dot(light) > 0.0)
            .collect();
        let shadowed = shadows.iter().filter(|&&s| s).count();
        let fraction = shadowed as f64 / shadows.len() as f64;
        // Light 80–85° from the zenith: much of the surface is shadowed (75° along the weft
        // less so: the warp yarns' flanks face it).
        let least = if light.z < 0.2 { 0.15 } else { 0.03 };
        assert!(
            fraction > least,
            "{light}: only {fraction} of the hits in cast shadow"
        );
        let disagree = facing
            .par_iter()
            .filter(|&&i| {
                let p = hits.hits()[i].position.as_dvec3();
                brute_force_shadowed(&btf, p, light.as_dvec3()) != shadows[i]
            })
            .count();
        assert!(
            disagree * 100 <= facing.len(),
            "view {view}, light {light}: {disagree} of {} facing hits disagree with brute force",
            facing.len()
        );
    }
    for view in [dir(0.0, 0.0), dir(51.0, 40.0), dir(85.0, 15.0)] {
        let hits = btf.view(view).expect("view");
        // A height field never hides the zenith.
        assert!(hits.cast_shadows(Vec3::Z).iter().all(|&s| !s), "{view}");
        // Lit from the viewer's direction, every visible point is lit: its view ray is its
        // shadow ray, reversed (up to the march's sampling).
        let from_viewer = hits.cast_shadows(view).iter().filter(|&&s| s).count();
        assert!(
            from_viewer * 500 <= hits.hits().len(),
            "{view}: {from_viewer} shadowed"
        );
    }
}

#[test]
fn light_at_or_below_the_horizon_is_black() {
    let btf = btf(&small(16));
    for view in [dir(0.0, 0.0), dir(68.0, 72.0)] {
        let hits = btf.view(view).expect("view");
        let (c, s) = (0.5f32.sqrt(), 0.5f32.sqrt());
        for light in [
            dir(100.0, 10.0),
            dir(180.0, 0.0),
            Vec3::new(c, s, 0.0),
            Vec3::new(1.0, 0.0, -0.0),
        ] {
            assert!(hits.shade(light).iter().all(|t| *t == [0.0; 3]), "{light}");
            assert!(hits.cast_shadows(light).iter().all(|&s| !s));
        }
        // Not a direction at all: black too (documented), not a panic.
        for light in [Vec3::ZERO, Vec3::NAN, Vec3::new(0.0, f32::INFINITY, 1.0)] {
            assert!(hits.shade(light).iter().all(|t| *t == [0.0; 3]));
        }
        // Just above the horizon: finite and nearly black (n·l is tiny on the tops, and
        // the flanks that face the light are shadowed by their neighbours).
        let image = hits.shade(dir(89.99, 33.0));
        assert!(image.iter().flatten().all(|c| c.is_finite() && *c >= 0.0));
        let mean =
            image.iter().flatten().map(|&c| f64::from(c)).sum::<f64>() / (3 * image.len()) as f64;
        assert!(mean < 0.01, "{view}: mean {mean} just above the horizon");
    }
}

#[test]
fn views_below_or_along_the_horizon_are_rejected() {
    let btf = btf(&small(8));
    for view in [
        dir(90.0, 0.0),
        dir(120.0, 30.0),
        dir(89.5, 0.0),
        Vec3::ZERO,
        Vec3::new(f32::NAN, 0.0, 1.0),
    ] {
        match btf.view(view) {
            Err(SynthError::InvalidParameter { field, .. }) => {
                assert!(field.starts_with("view_dir_in_tangent"), "{field}");
            }
            other => panic!("{view}: expected InvalidParameter, got {other:?}"),
        }
    }
    // 1.5° above the surface is a valid (extreme) view.
    let hits = btf.view(dir(88.5, 10.0)).expect("valid view");
    assert!(
        hits.shade(dir(30.0, 0.0))
            .iter()
            .flatten()
            .all(|c| c.is_finite())
    );
}

#[test]
fn images_are_deterministic_and_independent_of_the_order_of_calls() {
    let params = small(24);
    let views = [dir(0.0, 0.0), dir(51.0, 100.0), dir(85.0, 345.0)];
    let lights = [dir(17.0, 60.0), dir(68.0, 18.0), dir(85.0, 195.0)];
    let first = btf(&params);
    let second = btf(&params);
    for view in views {
        let a = first.view(view).expect("view");
        let b = second.view(view).expect("view");
        assert_eq!(a.hits(), b.hits());
        // Forward on one, backwards and in parallel on the other.
        let forward: Vec<_> = lights.iter().map(|&l| a.shade(l)).collect();
        let mut backward: Vec<_> = lights.iter().rev().map(|&l| b.shade(l)).collect();
        backward.reverse();
        let parallel: Vec<_> = lights.par_iter().map(|&l| b.shade(l)).collect();
        assert_eq!(forward, backward);
        assert_eq!(forward, parallel);
    }
    // Views in parallel, all asking for the same not-yet-built shadow tables at once (as a
    // caller that runs its views on rayon does): the same images as one after the other.
    let fresh = btf(&params);
    let together: Vec<Vec<Vec<[f32; 3]>>> = views
        .par_iter()
        .map(|&view| {
            let hits = fresh.view(view).expect("view");
            lights.iter().map(|&l| hits.shade(l)).collect()
        })
        .collect();
    for (view, images) in views.iter().zip(&together) {
        let hits = first.view(*view).expect("view");
        for (light, image) in lights.iter().zip(images) {
            assert_eq!(&hits.shade(*light), image);
        }
    }
    fn send_sync<T: Send + Sync>() {}
    send_sync::<WovenBtf>();
    send_sync::<ViewHits>();

    // The seed changes the per-yarn colours, not the geometry.
    let reseeded = btf(&WovenBtfParams { seed: 99, ..params });
    let (a, b) = (
        first.view(views[1]).expect("view"),
        reseeded.view(views[1]).expect("view"),
    );
    assert_eq!(a.hits(), b.hits());
    assert_ne!(a.shade(lights[0]), b.shade(lights[0]));
    assert_ne!(first.albedo(Yarn::Warp(0)), first.albedo(Yarn::Warp(1)));
    assert_eq!(first.albedo(Yarn::Gap), Some(params.gap_albedo));
    assert_eq!(first.albedo(Yarn::Warp(params.warp_count)), None);
    assert_eq!(first.albedo(Yarn::Weft(params.weft_count)), None);
}

#[test]
fn every_texel_stays_in_the_documented_range() {
    let params = WovenBtfParams {
        glossy_weight: 0.1,
        glossy_exponent: 12.0,
        ..small(16)
    };
    let btf = btf(&params);
    let max_albedo = (0..params.warp_count)
        .map(Yarn::Warp)
        .chain((0..params.weft_count).map(Yarn::Weft))
        .filter_map(|yarn| btf.albedo(yarn))
        .map(|a| a.max_element())
        .fold(params.gap_albedo.max_element(), f32::max);
    let bound = params.diffuse_weight * max_albedo
        + params.glossy_weight * (params.glossy_exponent + 8.0) / 8.0;
    for theta_v in [0.0, 34.0, 68.0, 85.0] {
        let hits = btf.view(dir(theta_v, 25.0 * theta_v)).expect("view");
        for theta_l in [0.0, 17.0, 51.0, 85.0] {
            for phi_l in [0.0, 100.0, 250.0] {
                for texel in hits.shade(dir(theta_l, phi_l)) {
                    for c in texel {
                        assert!(
                            (0.0..=bound + 1e-6).contains(&c),
                            "{c} outside [0, {bound}]"
                        );
                    }
                }
            }
        }
    }
    // Highlights: the half vector on a yarn top gives the glossy peak on top of the diffuse.
    let peak = btf
        .view(dir(20.0, 0.0))
        .expect("view")
        .shade(dir(20.0, 180.0));
    let brightest = peak.iter().flatten().copied().fold(0.0f32, f32::max);
    assert!(
        brightest > 0.5 * bound,
        "no highlight: {brightest} vs bound {bound}"
    );
}

#[test]
fn invalid_parameters_name_the_field() {
    let cases = [
        (WovenBtfParams { res: 0, ..small(8) }, "WovenBtfParams::res"),
        (
            WovenBtfParams {
                supersample: 0,
                ..small(8)
            },
            "WovenBtfParams::supersample",
        ),
        (
            WovenBtfParams {
                supersample: 9,
                ..small(8)
            },
            "WovenBtfParams::supersample",
        ),
        (
            WovenBtfParams {
                warp_count: 3,
                ..small(8)
            },
            "WovenBtfParams::warp_count",
        ),
        (
            WovenBtfParams {
                weft_count: 0,
                ..small(8)
            },
            "WovenBtfParams::weft_count",
        ),
        (
            WovenBtfParams {
                weft_count: 258,
                ..small(8)
            },
            "WovenBtfParams::weft_count",
        ),
        (
            WovenBtfParams {
                yarn_width: 0.0,
                ..small(8)
            },
            "WovenBtfParams::yarn_width",
        ),
        (
            WovenBtfParams {
                yarn_width: 1.2,
                ..small(8)
            },
            "WovenBtfParams::yarn_width",
        ),
        (
            WovenBtfParams {
                yarn_height: f32::NAN,
                ..small(8)
            },
            "WovenBtfParams::yarn_height",
        ),
        (
            WovenBtfParams {
                crimp: -0.1,
                ..small(8)
            },
            "WovenBtfParams::crimp",
        ),
        (
            WovenBtfParams {
                albedo_variation: 0.9,
                ..small(8)
            },
            "WovenBtfParams::albedo_variation",
        ),
        (
            WovenBtfParams {
                diffuse_weight: 2.0,
                ..small(8)
            },
            "WovenBtfParams::diffuse_weight",
        ),
        (
            WovenBtfParams {
                glossy_weight: -1.0,
                ..small(8)
            },
            "WovenBtfParams::glossy_weight",
        ),
        (
            WovenBtfParams {
                glossy_exponent: 0.5,
                ..small(8)
            },
            "WovenBtfParams::glossy_exponent",
        ),
        (
            WovenBtfParams {
                warp_albedo: Vec3::new(0.5, 1.5, 0.5),
                ..small(8)
            },
            "WovenBtfParams::warp_albedo.y",
        ),
        (
            WovenBtfParams {
                gap_albedo: Vec3::new(0.0, 0.0, -0.1),
                ..small(8)
            },
            "WovenBtfParams::gap_albedo.z",
        ),
    ];
    for (params, field) in cases {
        match WovenBtf::new(&params) {
            Err(SynthError::InvalidParameter { field: f, .. }) => assert_eq!(f, field),
            other => panic!("{field}: expected InvalidParameter, got {other:?}"),
        }
    }
    let error = WovenBtf::new(&WovenBtfParams {
        res: 4096,
        supersample: 2,
        ..Default::default()
    })
    .expect_err("too large");
    assert!(
        matches!(error, SynthError::TooLarge { .. }) && error.to_string().contains("sub-samples"),
        "{error}"
    );
}
