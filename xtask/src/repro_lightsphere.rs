//! `cargo xtask repro lightsphere`: for each lightsphere level and each way of computing I_j,
//! the time it costs and the error it leaves, against exact references:
//!
//! - power: Σ_j I_j ω_j against ∫L dω (the map's texel sum in f64);
//! - irradiance: E(n) = Σ_j I_j ω_j max(0, n·l_j) against the exact texel sum
//!   Σ_t L_t Ω_t max(0, n·d_t) for 64 normals spread over the sphere (worst case, relative to
//!   the largest E).
//!
//! Maps: every `.hdr` in `../shared/data/env` (when present) and the procedural sky.

use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

use glam::{DVec3, Vec3};
use lightsphere::{Environment, Lightsphere, RadianceMethod};
use rayon::prelude::*;

use figures::chart::{Series, log_log_svg};

/// Normals on a Fibonacci sphere.
fn normals(count: usize) -> Vec<DVec3> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..count)
        .map(|i| {
            let y = 1.0 - 2.0 * (i as f64 + 0.5) / count as f64;
            let r = (1.0 - y * y).sqrt();
            let phi = golden * i as f64;
            DVec3::new(r * phi.cos(), y, r * phi.sin())
        })
        .collect()
}

fn luminance(c: DVec3) -> f64 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// Exact irradiance (luminance) of the piecewise-constant map for each normal, f64.
fn exact_irradiance(env: &Environment, normals: &[DVec3]) -> Vec<f64> {
    let (w, h) = (env.width(), env.height());
    normals
        .par_iter()
        .map(|n| {
            let mut e = 0.0;
            for r in 0..h {
                let omega = lightsphere::latlong::texel_solid_angle(r, w, h);
                for c in 0..w {
                    let d = lightsphere::latlong::texel_direction(r, c, w, h);
                    let cos = n.dot(d);
                    if cos > 0.0 {
                        let t = env.texel(r, c);
                        e += luminance(DVec3::new(t[0].into(), t[1].into(), t[2].into()))
                            * cos
                            * omega;
                    }
                }
            }
            e
        })
        .collect()
}

struct Row {
    map: String,
    level: u32,
    k: usize,
    method: String,
    millis: f64,
    power_error: f64,
    irradiance_error: f64,
}

fn evaluate(
    map: &str,
    env: &Environment,
    max_level: u32,
    rows: &mut Vec<Row>,
) -> anyhow::Result<()> {
    let normals = normals(64);
    let exact = exact_irradiance(env, &normals);
    let e_max = exact
        .iter()
        .copied()
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE);
    let total = env.total_power();
    let total_lum = luminance(DVec3::from_array(total));
    for level in 0..=max_level {
        let sphere = Lightsphere::new(level)?;
        for method in [
            RadianceMethod::CellMean,
            RadianceMethod::PrefilteredLookup {
                sigma_deg: lightsphere::matched_sigma_deg(sphere.len()),
            },
        ] {
            let start = Instant::now();
            let radiance = env.radiance_per_direction(&sphere, method)?;
            let millis = start.elapsed().as_secs_f64() * 1e3;
            let weighted: Vec<(DVec3, f64)> = sphere
                .directions()
                .iter()
                .zip(sphere.solid_angles())
                .zip(&radiance)
                .map(|((l, w), i): ((&Vec3, &f64), &Vec3)| {
                    (l.as_dvec3(), luminance(i.as_dvec3()) * w)
                })
                .collect();
            let power: f64 = weighted.iter().map(|(_, p)| p).sum();
            let irradiance_error = normals
                .iter()
                .zip(&exact)
                .map(|(n, e)| {
                    let approx: f64 = weighted.iter().map(|(l, p)| p * n.dot(*l).max(0.0)).sum();
                    (approx - e).abs() / e_max
                })
                .fold(0.0, f64::max);
            let label = match method {
                RadianceMethod::CellMean => "cell mean".to_owned(),
                RadianceMethod::PrefilteredLookup { sigma_deg } => {
                    format!("prefiltered look-up (σ {sigma_deg:.2}°)")
                }
            };
            rows.push(Row {
                map: map.to_owned(),
                level,
                k: sphere.len(),
                method: label,
                millis,
                power_error: (power - total_lum) / total_lum,
                irradiance_error,
            });
            eprintln!(
                "{map} level {level} {}: {millis:.1} ms",
                rows.last().map_or("", |r| r.method.as_str())
            );
        }
    }
    Ok(())
}

/// Run the report.
pub fn run(out: &Path, max_level: u32) -> anyhow::Result<()> {
    let mut maps: Vec<(String, Environment)> = Vec::new();
    let sky = synth::sky(&synth::SkyParams::default())?;
    maps.push((
        "synth sky".to_owned(),
        Environment::from_latlong(sky.width, sky.height, sky.texels)?,
    ));
    for name in [
        "studio_small_03_1k",
        "st_fagans_interior_1k",
        "venice_sunset_1k",
        "kiara_1_dawn_1k",
    ] {
        if let Some(path) = test_data::shared_file(&format!("env/{name}.hdr")) {
            maps.push((name.to_owned(), Environment::load(&path)?));
        }
    }
    let mut rows = Vec::new();
    for (name, env) in &maps {
        evaluate(name, env, max_level, &mut rows)?;
    }

    let mut md = String::new();
    let _ = writeln!(
        md,
        "# Lightsphere: what each level and I_j method costs and buys\n"
    );
    let _ = writeln!(
        md,
        "Generated by `cargo xtask repro lightsphere`. Power error: (Σ_j I_j ω_j − ∫L dω) / ∫L dω \
         on luminance. Irradiance error: worst |E_k(n) − E(n)| / max E over 64 normals, against \
         the exact sum over every texel (f64). Time: computing I_j for all k directions \
         (the prefiltered method includes the spherical Gaussian prefilter with σ = √(2/k) rad).\n"
    );
    let _ = writeln!(
        md,
        "| map | level | k | I_j method | time (ms) | power error | irradiance error |"
    );
    let _ = writeln!(md, "|---|---:|---:|---|---:|---:|---:|");
    for r in &rows {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {:.1} | {:+.2e} | {:.3e} |",
            r.map, r.level, r.k, r.method, r.millis, r.power_error, r.irradiance_error
        );
    }
    let mut series = Vec::new();
    for (name, _) in &maps {
        for method in ["cell mean", "prefiltered"] {
            series.push(Series {
                label: format!("{name}, {method}"),
                points: rows
                    .iter()
                    .filter(|r| &r.map == name && r.method.starts_with(method))
                    .map(|r| (r.k as f64, r.irradiance_error))
                    .collect(),
            });
        }
    }
    let svg = log_log_svg(
        "Irradiance error against k",
        "directions k",
        "worst irradiance error",
        &series,
    );
    atomic_out::write_bytes(&out.join("lightsphere.md"), md.as_bytes())?;
    atomic_out::write_bytes(&out.join("lightsphere.svg"), svg.as_bytes())?;
    println!(
        "wrote {} and lightsphere.svg",
        out.join("lightsphere.md").display()
    );
    Ok(())
}
