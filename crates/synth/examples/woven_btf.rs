//! Renders a full procedural woven-cloth BTF in the UBO2003 sampling H1 (thesis Tab. 5.1:
//! 81 view × 81 light directions), reports the time, and writes a few of the images:
//!
//! ```text
//! cargo run --release -p synth --example woven_btf -- OUT_DIR [RES] [SUPERSAMPLE]
//! ```
//!
//! * `OUT_DIR/woven_tv{θv}_pv{φv}_tl{θl}_pl{φl}.ppm`: 8-bit sRGB-encoded binary PPM (no image
//!   dependency in this crate) for a frontal, an oblique and a grazing view under a frontal
//!   and a grazing light;
//! * stdout: the time for the 81 primary passes and the 6,561 images, and the mean radiance.
//!
//! Measured on the shared 2-core development machine (load average 5–6 from other jobs,
//! so about one core for this run), default parameters: RES 64, SUPERSAMPLE 2: 6.4 s;
//! RES 256, SUPERSAMPLE 1: 24 s; RES 256, SUPERSAMPLE 2: 96 s.

use glam::Vec3;
use std::error::Error;
use std::path::{Path, PathBuf};
use std::time::Instant;
use synth::{WovenBtf, WovenBtfParams};

/// (θ in degrees, number of azimuths) of the UBO2003 sampling H1 (thesis Tab. 5.1).
const H1_RINGS: [(f32, u32); 6] = [
    (0.0, 1),
    (17.0, 6),
    (34.0, 12),
    (51.0, 18),
    (68.0, 20),
    (85.0, 24),
];

/// The 81 directions of H1 as (θ°, φ°).
fn h1_directions() -> Vec<(f32, f32)> {
    H1_RINGS
        .iter()
        .flat_map(|&(theta, count)| {
            (0..count).map(move |k| (theta, 360.0 * k as f32 / count as f32))
        })
        .collect()
}

fn direction(theta_deg: f32, phi_deg: f32) -> Vec3 {
    let (theta, phi) = (theta_deg.to_radians(), phi_deg.to_radians());
    Vec3::new(
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    )
}

fn main() -> Result<(), Box<dyn Error>> {
    atomic_out::remove_temporaries_on_signal()?;
    let mut args = std::env::args_os().skip(1);
    let Some(out_dir) = args.next().map(PathBuf::from) else {
        return Err("usage: woven_btf OUT_DIR [RES] [SUPERSAMPLE]".into());
    };
    let mut number = |default: usize| -> Result<usize, Box<dyn Error>> {
        match args.next() {
            Some(arg) => Ok(arg.to_str().ok_or("argument is not UTF-8")?.parse()?),
            None => Ok(default),
        }
    };
    let params = WovenBtfParams {
        res: number(64)?,
        supersample: number(2)?,
        ..Default::default()
    };
    std::fs::create_dir_all(&out_dir)?;
    let btf = WovenBtf::new(&params)?;
    let directions = h1_directions();
    assert_eq!(directions.len(), 81);

    let start = Instant::now();
    let mut view_time = 0.0;
    let mut sum = 0.0f64;
    for &(theta_v, phi_v) in &directions {
        let view_start = Instant::now();
        let hits = btf.view(direction(theta_v, phi_v))?;
        view_time += view_start.elapsed().as_secs_f64();
        for &(theta_l, phi_l) in &directions {
            let image = hits.shade(direction(theta_l, phi_l));
            sum += image
                .iter()
                .map(|t| f64::from(t[0] + t[1] + t[2]))
                .sum::<f64>();
            let wanted = [0.0, 51.0, 85.0].contains(&theta_v) && phi_v == 0.0;
            if wanted && [0.0, 85.0].contains(&theta_l) && phi_l == 0.0 {
                let name =
                    format!("woven_tv{theta_v:03}_pv{phi_v:03}_tl{theta_l:03}_pl{phi_l:03}.ppm");
                write_ppm(&out_dir.join(name), btf.res(), &image)?;
            }
        }
    }
    let total = start.elapsed().as_secs_f64();
    let res = btf.res();
    println!(
        "{res}² × {n}² sub-samples, 81 × 81 images: {total:.2} s ({view_time:.2} s primary rays, {:.2} s shading); mean radiance {:.4}",
        total - view_time,
        sum / (81.0 * 81.0 * (res * res) as f64 * 3.0),
        n = params.supersample,
    );
    Ok(())
}

/// sRGB transfer function of a linear value, clamped to [0, 1].
fn srgb(linear: f32) -> u8 {
    let c = linear.clamp(0.0, 1.0);
    let encoded = if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (encoded * 255.0).round() as u8
}

/// Binary PPM, written atomically so no partial file is left behind.
fn write_ppm(path: &Path, res: usize, image: &[[f32; 3]]) -> Result<(), atomic_out::WriteError> {
    let mut bytes = format!("P6\n{res} {res}\n255\n").into_bytes();
    bytes.extend(image.iter().flat_map(|t| t.map(srgb)));
    atomic_out::write_bytes(path, &bytes)
}
