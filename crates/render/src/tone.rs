//! From linear radiance to display values: exposure in EV, a filmic tone curve, the sRGB
//! transfer function, luminance and automatic exposure. One home for all of them in the
//! workspace.
//!
//! **The curve.** [`ToneCurve::AcesFitted`] (the default) is Krzysztof Narkowicz's fit of the
//! ACES reference rendering transform,
//! f(x) = x(2.51x + 0.03) / (x(2.43x + 0.59) + 0.14), applied per channel to
//! x = 2^EV · linear and clamped to [0, 1]. It is monotone on x ≥ 0 (the numerator of f′ is
//! 1.408x² + 0.703x + 0.0042 > 0), maps 0 to 0 and reaches 1 at x ≈ 7.24, so an HDR sun 10⁴×
//! the sky ends white, finite, instead of turning the sky to a flat clamp.
//! [`ToneCurve::Clamp`] is the seed's "standard gamma correction" (paper 000 §5):
//! clamp(x) then x^(1/γ), kept for comparison.
//!
//! **Encoding.** After the curve, values are encoded with the sRGB transfer function (PNG's
//! default colour space), except under [`ToneCurve::Clamp`], which applies its own gamma.

/// Rec. 709 / sRGB luminance of linear RGB.
pub fn luminance(rgb: [f32; 3]) -> f32 {
    0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]
}

/// The sRGB transfer function (IEC 61966-2-1) of a linear value in [0, 1] (clamped; NaN → 0).
pub fn srgb_encode(linear: f32) -> f32 {
    let v = if linear.is_nan() {
        0.0
    } else {
        linear.clamp(0.0, 1.0)
    };
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// A display value in [0, 1] to 8 bits, rounded.
pub fn to_u8(display: f32) -> u8 {
    (display.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
}

/// Narkowicz's ACES fit, clamped to [0, 1]; NaN and negative inputs give 0.
pub fn aces_fitted(x: f32) -> f32 {
    if x.is_nan() || x <= 0.0 {
        return 0.0;
    }
    if x == f32::INFINITY {
        return 1.0;
    }
    // In f64: x² overflows f32 above 1.8e19, and such radiance must still map to white.
    let x = f64::from(x);
    let y = x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14);
    y.clamp(0.0, 1.0) as f32
}

/// The tone curve applied after exposure.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum ToneCurve {
    /// Narkowicz's ACES fit, then sRGB encoding (the default).
    #[default]
    AcesFitted,
    /// Clamp to [0, 1], then x^(1/gamma) (the seed's display mapping).
    Clamp {
        /// Display gamma (2.2 in the seed).
        gamma: f32,
    },
    /// Clamp to [0, 1], then the sRGB encoding: for renders of measured sRGB data (BTF
    /// normtextures), so that a unit light shows the material as it was photographed.
    ClampSrgb,
}

/// Exposure and tone curve: linear radiance to display values.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Display {
    /// Exposure in stops: linear radiance is multiplied by 2^EV before the curve.
    pub exposure_ev: f32,
    /// The curve.
    pub curve: ToneCurve,
}

impl Display {
    /// The linear multiplier 2^EV.
    pub fn scale(&self) -> f32 {
        self.exposure_ev.exp2()
    }

    /// One linear channel to a display value in [0, 1] (NaN → 0).
    pub fn map(&self, linear: f32) -> f32 {
        let x = linear * self.scale();
        match self.curve {
            ToneCurve::AcesFitted => srgb_encode(aces_fitted(x)),
            ToneCurve::Clamp { gamma } => {
                let v = if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) };
                v.powf(1.0 / gamma)
            }
            ToneCurve::ClampSrgb => srgb_encode(if x.is_nan() { 0.0 } else { x }),
        }
    }

    /// One linear channel to 8 bits.
    pub fn map_u8(&self, linear: f32) -> u8 {
        to_u8(self.map(linear))
    }
}

/// Where automatic exposure puts the chosen percentile of the objects' brightest channel
/// ([`peak`]; after exposure, before the curve): ACES maps 0.8 to 0.75, bright but clear of
/// the shoulder — every channel, so a saturated colour keeps its hue.
pub const AUTO_EXPOSURE_KEY: f32 = 0.8;
/// The percentile automatic exposure reads: the 90th, so highlights and not the mean decide
/// (a mostly shadowed object is not pushed into white).
pub const AUTO_EXPOSURE_PERCENTILE: f64 = 0.9;

/// The brightest of three linear channels: what automatic exposure keys on. Luminance would
/// let a saturated colour's strongest channel run past the key (red of albedo (0.9, 0.3, 0.2)
/// sits at 2.1× its luminance) into the curve's shoulder, where the hue washes out.
pub fn peak(rgb: [f32; 3]) -> f32 {
    rgb[0].max(rgb[1]).max(rgb[2])
}

/// The exposure (EV) that puts the `percentile` of `levels` (per-pixel [`peak`]s, as
/// [`crate::output::auto_exposure`] passes them) at `key`; `None` when no level is finite and
/// positive. Non-finite and non-positive values are ignored.
pub fn auto_exposure_ev(
    levels: impl IntoIterator<Item = f32>,
    percentile: f64,
    key: f32,
) -> Option<f32> {
    let mut lum: Vec<f32> = levels
        .into_iter()
        .filter(|l| l.is_finite() && *l > 0.0)
        .collect();
    if lum.is_empty() {
        return None;
    }
    let k = ((lum.len() - 1) as f64 * percentile.clamp(0.0, 1.0)).round() as usize;
    let (_, value, _) = lum.select_nth_unstable_by(k, f32::total_cmp);
    Some((key / *value).log2())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn aces_is_monotone_bounded_and_keeps_a_sun_finite() {
        let mut previous = 0.0f32;
        let mut x = 1e-6f32;
        while x < 1e30 {
            let y = aces_fitted(x);
            assert!(y.is_finite() && (0.0..=1.0).contains(&y), "{x}: {y}");
            assert!(y >= previous, "not monotone at {x}: {y} < {previous}");
            previous = y;
            x *= 1.01;
        }
        assert_eq!(aces_fitted(0.0), 0.0);
        assert_eq!(aces_fitted(-3.0), 0.0);
        assert_eq!(aces_fitted(f32::NAN), 0.0);
        assert_eq!(aces_fitted(f32::INFINITY), 1.0);
        // A sun 10⁴× a unit sky after exposure: white and finite; the sky itself is not.
        assert_eq!(aces_fitted(1e4), 1.0);
        assert!(aces_fitted(1.0) < 0.85);
        // The closed form at 1: 2.54 / 3.16.
        assert!((aces_fitted(1.0) - 2.54 / 3.16).abs() < 1e-6);
    }

    #[test]
    fn exposure_is_a_power_of_two_per_stop() {
        let d0 = Display::default();
        let d1 = Display {
            exposure_ev: 1.0,
            ..d0
        };
        for v in [0.01f32, 0.1, 0.3, 2.0] {
            assert_eq!(d1.map(v), d0.map(2.0 * v), "{v}");
        }
        assert_eq!(
            Display {
                exposure_ev: -2.0,
                ..d0
            }
            .scale(),
            0.25
        );
    }

    #[test]
    fn srgb_matches_its_definition_and_the_clamp_curve_the_seed() {
        assert_eq!(srgb_encode(0.0), 0.0);
        assert!((srgb_encode(1.0) - 1.0).abs() < 1e-6);
        assert!((srgb_encode(0.002) - 0.02584).abs() < 1e-5);
        assert!((srgb_encode(0.5) - 0.735_357).abs() < 1e-5);
        let seed = Display {
            exposure_ev: 0.0,
            curve: ToneCurve::Clamp { gamma: 2.2 },
        };
        assert_eq!(seed.map_u8(0.5), 186);
        assert_eq!(seed.map_u8(1e9), 255);
        assert_eq!(seed.map_u8(f32::NAN), 0);
        // The BTF display: the sRGB code of the clamped value, NaN black.
        let srgb = Display {
            exposure_ev: 0.0,
            curve: ToneCurve::ClampSrgb,
        };
        assert_eq!(srgb.map_u8(0.5), 188); // 0.735357 · 255 = 187.5 → 188
        assert_eq!(srgb.map_u8(0.002), 7); // 12.92 · 0.002 · 255 = 6.59 → 7
        assert_eq!(srgb.map_u8(1e9), 255);
        assert_eq!(srgb.map_u8(-1.0), 0);
        assert_eq!(srgb.map_u8(f32::NAN), 0);
    }

    #[test]
    fn auto_exposure_reads_the_percentile_and_ignores_junk() {
        let lum = (1..=100)
            .map(|i| i as f32 / 100.0)
            .chain([f32::NAN, -1.0, 0.0]);
        // 90th percentile of 0.01..1.00 is 0.90 (index 89.1 rounds to 89).
        let ev = auto_exposure_ev(lum, 0.9, 0.8).unwrap();
        assert!((ev - (0.8f32 / 0.90).log2()).abs() < 1e-6, "{ev}");
        assert_eq!(auto_exposure_ev([f32::NAN, 0.0], 0.9, 0.8), None);
    }
}
