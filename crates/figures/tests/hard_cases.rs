//! Hard cases of the figures: labels that are XML, axes whose values span the whole f64
//! range or collapse to one value, series with nothing to draw, and strip requests at and
//! beyond their limits (checked before any GPU work).

use std::path::Path;

use figures::chart::{Axis, Series, chart_svg, log_log_svg};
use figures::strip::{
    DEFAULT_PANEL_SIZE, MAX_PANEL_SIDE, MAX_STRIP_FRAMES, check_strip, label_colours,
    strip_frame_indices,
};

fn series(points: Vec<(f64, f64)>) -> Vec<Series> {
    vec![Series {
        label: "s".into(),
        points,
    }]
}

/// Counts `<text` elements, i.e. the title, tick labels, axis labels and legend.
fn texts(svg: &str) -> usize {
    svg.matches("<text").count()
}

#[test]
fn xml_special_characters_in_labels_are_escaped() {
    let s = vec![Series {
        label: "d_f < 1% & \"worst\"".into(),
        points: vec![(1.0, 1.0), (2.0, 4.0)],
    }];
    let svg = chart_svg("R&D <title>", ["x<y", "y>x"], [Axis::Linear; 2], &s);
    assert!(svg.contains("R&amp;D &lt;title&gt;"), "{svg}");
    assert!(svg.contains("d_f &lt; 1% &amp; &quot;worst&quot;"));
    assert!(svg.contains("x&lt;y") && svg.contains("y&gt;x"));
    // No raw special character survives inside text content.
    for text in svg.split("<text").skip(1) {
        let content = &text[text.find('>').unwrap() + 1..text.find("</text>").unwrap()];
        assert!(!content.contains(['<', '>', '"']), "{content}");
        assert!(content.matches('&').count() == content.matches(';').count());
    }
}

#[test]
fn a_linear_axis_spanning_all_of_f64_keeps_a_bounded_number_of_ticks() {
    let svg = chart_svg(
        "wide",
        ["x", "y"],
        [Axis::Linear; 2],
        &series(vec![(-f64::MAX, -f64::MAX), (f64::MAX, f64::MAX)]),
    );
    // Title + 2 axis labels + legend + at most a few ticks per axis.
    assert!(texts(&svg) <= 4 + 2 * 26, "{} texts", texts(&svg));
    assert!(!svg.contains("NaN") && !svg.contains("inf"), "{svg}");
}

#[test]
fn a_log_axis_over_six_hundred_decades_is_thinned() {
    let svg = log_log_svg(
        "decades",
        "x",
        "y",
        &series(vec![(1e-300, 1e-300), (1e300, 1e300)]),
    );
    let decade_labels = svg.matches(">1e").count();
    assert!((2..=2 * 13).contains(&decade_labels), "{decade_labels}");
}

#[test]
fn one_repeated_value_gives_a_unit_wide_axis() {
    let svg = chart_svg(
        "flat",
        ["x", "y"],
        [Axis::Linear; 2],
        &series(vec![(3.0, 7.0), (3.0, 7.0)]),
    );
    assert!(!svg.contains("NaN"), "{svg}");
    assert!(svg.contains("<polyline"));
}

#[test]
fn non_finite_and_non_positive_log_values_are_skipped_not_drawn() {
    let svg = log_log_svg(
        "skips",
        "x",
        "y",
        &series(vec![
            (f64::NAN, 1.0),
            (1.0, f64::INFINITY),
            (0.0, 1.0),
            (-1.0, 2.0),
            (10.0, 100.0),
        ]),
    );
    assert!(!svg.contains("NaN") && !svg.contains("inf"), "{svg}");
    // Exactly one drawable point: one dot.
    assert_eq!(svg.matches("<circle").count(), 1, "{svg}");
}

#[test]
fn a_chart_with_no_series_or_no_points_is_still_a_valid_document() {
    for s in [Vec::new(), series(Vec::new())] {
        let svg = chart_svg("empty", ["x", "y"], [Axis::Log, Axis::Linear], &s);
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        assert!(!svg.contains("NaN"), "{svg}");
    }
}

#[test]
fn strip_limits_are_inclusive_and_one_beyond_is_refused() {
    let p = Path::new("strip.png");
    assert!(check_strip(MAX_STRIP_FRAMES, MAX_STRIP_FRAMES, DEFAULT_PANEL_SIZE, p).is_ok());
    assert!(check_strip(1000, MAX_STRIP_FRAMES + 1, DEFAULT_PANEL_SIZE, p).is_err());
    assert!(check_strip(10, 1, [MAX_PANEL_SIDE, 1], p).is_ok());
    let e = check_strip(10, 1, [MAX_PANEL_SIDE + 1, 1], p).unwrap_err();
    assert!(e.to_string().contains("strip.png"), "{e}");
    let e = check_strip(0, 1, DEFAULT_PANEL_SIZE, p).unwrap_err();
    assert!(e.to_string().contains("at least one frame"), "{e}");
}

#[test]
fn one_panel_of_one_frame_and_every_frame_of_a_short_clip() {
    assert_eq!(strip_frame_indices(1, 1), vec![0]);
    assert_eq!(strip_frame_indices(2, 2), vec![0, 1]);
    // Evenly spaced, strictly increasing, first and last included.
    let idx = strip_frame_indices(1_000_000, MAX_STRIP_FRAMES);
    assert_eq!((idx[0], *idx.last().unwrap()), (0, 999_999));
    assert!(idx.windows(2).all(|w| w[0] < w[1]));
}

#[test]
fn many_label_colours_stay_distinct_and_in_gamut() {
    let c = label_colours(256);
    for (i, a) in c.iter().enumerate() {
        assert!(a.min_element() >= 0.0 && a.max_element() <= 1.0, "{a}");
        if let Some(b) = c.get(i + 1) {
            assert!(
                (*a - *b).abs().max_element() > 0.05,
                "labels {i} and {} alike",
                i + 1
            );
        }
    }
}
