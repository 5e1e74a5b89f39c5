//! Prints what the lightsphere costs and how accurate it is, as markdown tables:
//! build time per level, solid-angle statistics, nearest-query candidates, prefilter times,
//! I_j times and power errors of both radiance methods on lat-long HDR maps.
//!
//! ```text
//! cargo run --release -p lightsphere --example lightsphere_report -- [MAP.hdr|MAP.exr ...]
//! ```
//! Without arguments it uses the four maps of `../shared/data/env` when present.

use lightsphere::{
    CellMeanParams, Environment, Lightsphere, RadianceMethod, direction_count, matched_sigma_deg,
};
use std::path::PathBuf;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut maps: Vec<PathBuf> = std::env::args().skip(1).map(PathBuf::from).collect();
    if maps.is_empty() {
        for name in [
            "venice_sunset_1k.hdr",
            "studio_small_03_1k.hdr",
            "st_fagans_interior_1k.hdr",
            "kiara_1_dawn_1k.hdr",
        ] {
            if let Some(p) = test_data::shared_file(&format!("env/{name}")) {
                maps.push(p);
            }
        }
    }

    println!(
        "| level | k | build (ms, first) | Delaunay flips | min ω / mean | max ω / mean | Σω − 4π | candidates/query |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for level in 0..=lightsphere::MAX_LEVEL {
        let start = Instant::now();
        let sphere = Lightsphere::new(level)?;
        let ms = start.elapsed().as_secs_f64() * 1e3;
        let w = sphere.solid_angles();
        let mean = 4.0 * std::f64::consts::PI / w.len() as f64;
        let min = w.iter().copied().fold(f64::INFINITY, f64::min);
        let max = w.iter().copied().fold(0.0, f64::max);
        let sum: f64 = w.iter().sum();
        println!(
            "| {level} | {} | {ms:.2} | {} | {:.4} | {:.4} | {:.1e} | {:.2} |",
            direction_count(level),
            sphere.delaunay_flips(),
            min / mean,
            max / mean,
            sum - 4.0 * std::f64::consts::PI,
            sphere.mean_candidates_per_query()
        );
    }

    for path in &maps {
        let env = Environment::load(path)?;
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        println!("\n### {name} ({}×{})\n", env.width(), env.height());
        println!("| σ (deg) | prefilter (ms) | output | power error |");
        println!("|---|---|---|---|");
        let exact = env.total_power();
        for sigma in [2.0, 5.0, 10.0] {
            let start = Instant::now();
            let filtered = env.prefiltered(sigma)?;
            let ms = start.elapsed().as_secs_f64() * 1e3;
            let p = filtered.total_power();
            println!(
                "| {sigma} | {ms:.0} | {}×{} | {:+.2e} |",
                filtered.width(),
                filtered.height(),
                (p[0] + p[1] + p[2]) / (exact[0] + exact[1] + exact[2]) - 1.0
            );
        }
        println!(
            "\n| level | k | CellMean (ms) | s | max abs(sampled area/ω − 1) | CellMean power err (max ch) | σ_matched (deg) | PrefilteredLookup (ms) | PrefilteredLookup power err (R, G, B) | Σω·abs(ΔI)/Σω·I |"
        );
        println!("|---|---|---|---|---|---|---|---|---|---|");
        for level in 0..=6 {
            let sphere = Lightsphere::new(level)?;
            let start = Instant::now();
            let cell = env.cell_mean(&sphere, &CellMeanParams::default())?;
            let ms = start.elapsed().as_secs_f64() * 1e3;
            let e_cell = env.relative_power_error(&sphere, &cell.radiance)?;
            let area_error = cell
                .sampled_solid_angle
                .iter()
                .zip(sphere.solid_angles())
                .map(|(a, w)| (a / w - 1.0).abs())
                .fold(0.0, f64::max);
            let sigma = matched_sigma_deg(sphere.len());
            let start = Instant::now();
            let lookup = env.radiance_per_direction(
                &sphere,
                RadianceMethod::PrefilteredLookup { sigma_deg: sigma },
            )?;
            let lookup_ms = start.elapsed().as_secs_f64() * 1e3;
            let e_look = env.relative_power_error(&sphere, &lookup)?;
            let lum = |v: glam::Vec3| f64::from(v.x + v.y + v.z);
            let diff: f64 = cell
                .radiance
                .iter()
                .zip(&lookup)
                .zip(sphere.solid_angles())
                .map(|((a, b), w)| (lum(*a) - lum(*b)).abs() * w)
                .sum::<f64>()
                / cell
                    .radiance
                    .iter()
                    .zip(sphere.solid_angles())
                    .map(|(a, w)| lum(*a) * w)
                    .sum::<f64>();
            println!(
                "| {level} | {} | {ms:.1} | {} | {area_error:.3} | {:.1e} | {sigma:.2} | {lookup_ms:.0} | {:+.3}, {:+.3}, {:+.3} | {diff:.3} |",
                sphere.len(),
                cell.supersampling,
                e_cell.iter().fold(0.0f64, |m, e| m.max(e.abs())),
                e_look[0],
                e_look[1],
                e_look[2],
            );
        }
    }
    Ok(())
}
