//! The two environment look-ups of the hemicube's runtime radiance (thesis §4.3.6) measured
//! side by side: the seed's cube map (power-conserving here) and exact per-pixel look-ups.
//!
//! For HC 16², 32², 64² maps of the dress under `venice_sunset_1k.hdr` (a low sun), the white
//! vertex radiance L_o = Σ_p V_p ΔF_p L(dir_p) by both look-ups: the time of one relight (maps
//! built, the cube map built inside the cube row: it is what a rotated environment costs) and
//! the relative RMS error over the vertices against a fine reference, HC 128² maps read through
//! a power-conserving 512² cube map.

use std::fmt::Write as _;
use std::sync::Arc;
use std::time::Instant;

use glam::Vec3;
use hemicube::lighting::{CubeMap, environment_radiance, radiance_from};
use hemicube::{BuildParams, EnvLookup, FormFactorRule, Model, PixelLayout};
use occlusion_gpu::RayCaster;

/// The environment, relative to the shared data root.
const ENV: &str = "env/venice_sunset_1k.hdr";

fn luminance(c: Vec3) -> f64 {
    f64::from(0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z)
}

/// Relative RMS of the luminance of `a` against `b` over finite vertices.
fn relative_rms(a: &[Vec3], b: &[Vec3]) -> f64 {
    let (mut num, mut den) = (0.0f64, 0.0f64);
    for (x, y) in a.iter().zip(b) {
        if x.is_finite() && y.is_finite() {
            let (lx, ly) = (luminance(*x), luminance(*y));
            num += (lx - ly).powi(2);
            den += ly * ly;
        }
    }
    (num / den.max(f64::MIN_POSITIVE)).sqrt()
}

fn maps(caster: &RayCaster, res: u32) -> anyhow::Result<hemicube::VisibilityMaps> {
    let layout = Arc::new(PixelLayout::new(
        Model::Hemicube { res },
        FormFactorRule::Exact,
    )?);
    Ok(hemicube::build_with_caster(caster, layout, &BuildParams::default()).0)
}

/// The section's markdown (empty with a note when the environment is missing).
pub fn section(caster: &RayCaster) -> anyhow::Result<String> {
    let mut md = String::new();
    let w = &mut md;
    writeln!(
        w,
        "## 6. Environment look-ups: cube map against exact directions\n"
    )?;
    let Some(path) = test_data::shared_file(ENV) else {
        writeln!(w, "Skipped: {ENV} is missing.")?;
        return Ok(md);
    };
    let env = lightsphere::Environment::load(&path)?;
    let fine = CubeMap::from_environment(&env, 512);
    let reference = radiance_from(&maps(caster, 128)?, Vec3::ONE, |d| fine.lookup(d));
    writeln!(
        w,
        "`{ENV}`; reference: HC 128² maps read through a power-conserving 512² cube map. Times \
         are one relight of every vertex (the cube row includes building its cube map, which is \
         what rotating or exchanging the environment costs).\n"
    )?;
    writeln!(
        w,
        "| maps | look-up | relight (ms) | relative RMS of luminance vs reference |"
    )?;
    writeln!(w, "|---|---|---:|---:|")?;
    for res in [16, 32, 64] {
        let m = maps(caster, res)?;
        for (name, lookup) in [
            ("cube map, side n/2 (the default)", EnvLookup::CubeMap),
            ("exact", EnvLookup::Exact),
        ] {
            let t = Instant::now();
            let c = environment_radiance(&m, &env, Vec3::ONE, lookup);
            let ms = t.elapsed().as_secs_f64() * 1e3;
            writeln!(
                w,
                "| HC {res}² | {name} | {ms:.1} | {:.2e} |",
                relative_rms(&c, &reference)
            )?;
        }
        // Other cube sides than the matched one, for the default's choice.
        for (name, side) in [
            ("cube map, side n/4", res / 4),
            ("cube map, side n (the seed's 1 texel per pixel)", res),
            ("cube map, side 2n", 2 * res),
        ] {
            let t = Instant::now();
            let cube = CubeMap::from_environment(&env, side as usize);
            let c = radiance_from(&m, Vec3::ONE, |d| cube.lookup(d));
            let ms = t.elapsed().as_secs_f64() * 1e3;
            writeln!(
                w,
                "| HC {res}² | {name} | {ms:.1} | {:.2e} |",
                relative_rms(&c, &reference)
            )?;
        }
    }
    writeln!(
        w,
        "\nThe cube map spreads each texel's power over the pixels that see it; exact look-ups \
         read the bilinear radiance at pixel centres only, so a source smaller than a pixel is \
         hit or missed (`hard_cases::environment_with_a_10e4_sun` holds the cube map to 3 % \
         under a 10⁴× sun).\n"
    )?;
    Ok(md)
}
