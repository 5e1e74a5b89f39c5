//! Minimal SVG line charts for reports and pictures (no fonts or system libraries needed,
//! viewable in any browser): linear or logarithmic axes, one polyline with dots per series
//! and a legend.

use std::fmt::Write as _;

/// One line of a chart.
pub struct Series {
    /// Legend label.
    pub label: String,
    /// (x, y) points; non-positive values are skipped on log axes, non-finite ones always.
    pub points: Vec<(f64, f64)>,
}

/// How an axis maps values to positions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Axis {
    /// Evenly spaced values, ticks at a round step.
    Linear,
    /// log10 scale, ticks at powers of ten.
    Log,
}

const PALETTE: [&str; 12] = [
    "#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf", "#8c564b", "#e377c2",
    "#bcbd22", "#7f7f7f", "#393b79", "#ad494a",
];

/// Most ticks on one axis (about; see `Scale::ticks`).
const MAX_TICKS: usize = 12;

/// A series with more points than this is drawn as a line without dots.
const MAX_DOTS: usize = 60;

/// Renders `series` as an SVG chart with log10 axes.
pub fn log_log_svg(title: &str, x_label: &str, y_label: &str, series: &[Series]) -> String {
    chart_svg(title, [x_label, y_label], [Axis::Log, Axis::Log], series)
}

/// One axis: the transformed range and the ticks (position value, label).
struct Scale {
    axis: Axis,
    lo: f64,
    hi: f64,
}

impl Scale {
    fn fit(axis: Axis, values: impl Iterator<Item = f64>) -> Self {
        let t = |v: f64| match axis {
            Axis::Linear => v,
            Axis::Log => v.log10(),
        };
        let (mut lo, mut hi) = (f64::MAX, f64::MIN);
        for v in values.filter(|v| v.is_finite() && (axis == Axis::Linear || *v > 0.0)) {
            lo = lo.min(t(v));
            hi = hi.max(t(v));
        }
        if lo > hi {
            (lo, hi) = (0.0, 1.0);
        }
        match axis {
            Axis::Log => Self {
                axis,
                lo: lo.floor(),
                hi: hi.ceil().max(lo.floor() + 1.0),
            },
            Axis::Linear => {
                let step = nice_step(hi - lo);
                let lo = (lo / step).floor() * step;
                let hi = ((hi / step).ceil() * step).max(lo + step);
                Self { axis, lo, hi }
            }
        }
    }

    fn keeps(&self, v: f64) -> bool {
        v.is_finite() && (self.axis == Axis::Linear || v > 0.0)
    }

    /// Position in [0, 1] along the axis.
    fn unit(&self, v: f64) -> f64 {
        let t = match self.axis {
            Axis::Linear => v,
            Axis::Log => v.log10(),
        };
        // Halved so that an axis spanning ±f64::MAX does not overflow to ∞ (and NaN).
        (0.5 * t - 0.5 * self.lo) / (0.5 * self.hi - 0.5 * self.lo)
    }

    /// At most about [`MAX_TICKS`] ticks: decades thinned to every n-th power of ten on a
    /// wide log axis; on a linear axis whose span overflows f64 only the two ends.
    fn ticks(&self) -> Vec<(f64, String)> {
        match self.axis {
            Axis::Log => {
                let (lo, hi) = (self.lo as i32, self.hi as i32);
                let stride = ((hi - lo) as usize).div_ceil(MAX_TICKS).max(1);
                (lo..=hi)
                    .step_by(stride)
                    .map(|e| (10f64.powi(e), format!("1e{e}")))
                    .collect()
            }
            Axis::Linear => {
                let span = self.hi - self.lo;
                let step = nice_step(span);
                let n = span / step;
                if !(n.is_finite() && n <= 2.0 * MAX_TICKS as f64) {
                    return [self.lo, self.hi]
                        .into_iter()
                        .map(|v| (v, format!("{v:e}")))
                        .collect();
                }
                (0..=n.round() as i64)
                    .map(|i| {
                        let v = self.lo + i as f64 * step;
                        (v, format!("{}", (v * 1e6).round() / 1e6))
                    })
                    .collect()
            }
        }
    }
}

/// A round tick step (1, 2 or 5 × 10ⁿ) giving about 5–10 ticks over `span`.
fn nice_step(span: f64) -> f64 {
    if !(span.is_finite() && span > 0.0) {
        return 1.0;
    }
    let raw = span / 6.0;
    let p = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * p)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * p)
}

/// `text` with the five XML special characters escaped, so that a label such as `d_f < 1%`
/// or `R&D` keeps the SVG well-formed.
fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '&' => out.push_str("&amp;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            other => out.push(other),
        }
    }
    out
}

/// Renders `series` as an SVG chart with the given axes (`labels` and `axes` are x then y).
pub fn chart_svg(title: &str, labels: [&str; 2], axes: [Axis; 2], series: &[Series]) -> String {
    let title = escape(title);
    let [x_label, y_label] = labels.map(escape);
    let (w, h, left, right, top, bottom) = (760.0, 480.0, 80.0, 220.0, 40.0, 60.0);
    let xs = Scale::fit(
        axes[0],
        series.iter().flat_map(|s| s.points.iter().map(|p| p.0)),
    );
    let ys = Scale::fit(
        axes[1],
        series.iter().flat_map(|s| s.points.iter().map(|p| p.1)),
    );
    let px = |x: f64| left + xs.unit(x) * (w - left - right);
    let py = |y: f64| top + (1.0 - ys.unit(y)) * (h - top - bottom);
    let mut svg = String::new();
    let _ = write!(
        svg,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" font-family="sans-serif" font-size="12"><rect width="100%" height="100%" fill="white"/><text x="{}" y="22" font-size="15" text-anchor="middle">{title}</text>"#,
        (w - right + left) / 2.0
    );
    for (v, label) in xs.ticks() {
        let x = px(v);
        let _ = write!(
            svg,
            r##"<line x1="{x}" y1="{top}" x2="{x}" y2="{}" stroke="#ddd"/><text x="{x}" y="{}" text-anchor="middle">{label}</text>"##,
            h - bottom,
            h - bottom + 16.0
        );
    }
    for (v, label) in ys.ticks() {
        let y = py(v);
        let _ = write!(
            svg,
            r##"<line x1="{left}" y1="{y}" x2="{}" y2="{y}" stroke="#ddd"/><text x="{}" y="{}" text-anchor="end">{label}</text>"##,
            w - right,
            left - 6.0,
            y + 4.0
        );
    }
    let _ = write!(
        svg,
        r#"<text x="{}" y="{}" text-anchor="middle">{x_label}</text><text transform="translate(18,{}) rotate(-90)" text-anchor="middle">{y_label}</text>"#,
        (w - right + left) / 2.0,
        h - 18.0,
        (h - bottom + top) / 2.0
    );
    for (i, s) in series.iter().enumerate() {
        let colour = PALETTE[i % PALETTE.len()];
        let path: Vec<String> = s
            .points
            .iter()
            .filter(|(x, y)| xs.keeps(*x) && ys.keeps(*y))
            .map(|(x, y)| format!("{:.1},{:.1}", px(*x), py(*y)))
            .collect();
        let _ = write!(
            svg,
            r#"<polyline fill="none" stroke="{colour}" stroke-width="2" points="{}"/>"#,
            path.join(" ")
        );
        // Dots only where they can be told apart.
        for p in path.iter().filter(|_| path.len() <= MAX_DOTS) {
            let (cx, cy) = p.split_once(',').unwrap_or(("0", "0"));
            let _ = write!(
                svg,
                r#"<circle cx="{cx}" cy="{cy}" r="3" fill="{colour}"/>"#
            );
        }
        let ly = top + 18.0 * i as f64 + 10.0;
        let _ = write!(
            svg,
            r#"<line x1="{}" y1="{ly}" x2="{}" y2="{ly}" stroke="{colour}" stroke-width="2"/><text x="{}" y="{}">{}</text>"#,
            w - right + 10.0,
            w - right + 30.0,
            w - right + 36.0,
            ly + 4.0,
            escape(&s.label)
        );
    }
    svg.push_str("</svg>\n");
    svg
}
