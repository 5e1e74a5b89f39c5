//! `anim jumpmap --maps DIR`: the analysis matrices D, D*, P, P*, P̂ as PNG heat maps (the
//! thesis's Fig. 3.3).

use std::path::Path;

use anim_pca::JumpMap;
use cloth_vis::Error;
use figures::strip::write_png;

/// The five matrices of the analysis as heat maps, one pixel per entry (scaled up to at least
/// 256 pixels a side): distances linearly from 0 to their maximum, probabilities on a log
/// scale over six decades below the matrix's maximum (as the thesis's Fig. 3.3 shows them,
/// black = 0).
pub(super) fn write_maps(
    dir: &Path,
    existing: atomic_out::ExistingFolder,
    map: &JumpMap,
) -> Result<(), Error> {
    atomic_out::write_dir(dir, existing, |tmp| write_map_files(tmp, map)).map_err(Error::from)
}

fn write_map_files(dir: &Path, map: &JumpMap) -> Result<(), Error> {
    let maps: [(&str, &anim_pca::SquareMatrix, bool); 5] = [
        ("D.png", map.distances(), false),
        ("D_velocity.png", map.velocity_distances(), false),
        ("P.png", map.position_probabilities(), true),
        ("P_velocity.png", map.velocity_probabilities(), true),
        ("P_hat.png", map.jump_map(), true),
    ];
    for (name, matrix, log) in maps {
        write_heat_map(&dir.join(name), matrix, log)?;
    }
    Ok(())
}

/// Decades below the maximum shown by a log-scale heat map.
const LOG_DECADES: f64 = 6.0;

/// Value in [0, 1] → a dark-blue … yellow ramp (a simple perceptual map, black at 0).
fn ramp(t: f64) -> [u8; 3] {
    let t = t.clamp(0.0, 1.0);
    let stops = [
        [0.0, 0.0, 0.0],
        [0.15, 0.10, 0.45],
        [0.75, 0.20, 0.45],
        [0.98, 0.60, 0.15],
        [1.0, 1.0, 0.6],
    ];
    let x = t * (stops.len() - 1) as f64;
    let i = (x.floor() as usize).min(stops.len() - 2);
    let f = x - i as f64;
    let c = |k: usize| stops[i][k] * (1.0 - f) + stops[i + 1][k] * f;
    [0, 1, 2].map(|k| (c(k) * 255.0 + 0.5) as u8)
}

fn write_heat_map(path: &Path, matrix: &anim_pca::SquareMatrix, log: bool) -> Result<(), Error> {
    let n = matrix.n();
    let max = matrix.max();
    let scale = (256usize.div_ceil(n.max(1))).max(1);
    let side = (n * scale) as u32;
    let value = |i: usize, j: usize| {
        let v = matrix.get(i, j);
        if !(v.is_finite() && max.is_finite() && max > 0.0) {
            return 0.0;
        }
        if log {
            if v <= 0.0 {
                0.0
            } else {
                1.0 + (v / max).log10() / LOG_DECADES
            }
        } else {
            v / max
        }
    };
    let image = image::RgbaImage::from_fn(side, side, |x, y| {
        let [r, g, b] = ramp(value(y as usize / scale, x as usize / scale));
        image::Rgba([r, g, b, 255])
    });
    Ok(write_png(path, &image)?)
}
