//! The day's plots (SVG): sky parameters against time, solar irradiance
//! against time, and ln E against air mass with each channel's Langley line.

use super::day::SkySeries;
use crate::report::{ReportError, Series, line_plot_svg};

const COLOURS: [(u8, u8, u8); 3] = [(200, 40, 40), (40, 150, 40), (40, 70, 200)];
const NAMES: [&str; 3] = ["r", "g", "b"];

/// A plotted sky parameter: its name, how to read it, its colour.
type Parameter = (&'static str, fn(&crate::sky::SkyModel) -> f64, (u8, u8, u8));

/// Hours since 00:00 UTC of the first scan's date (may pass 24).
fn hours(series: &SkySeries) -> Vec<f64> {
    let Some(first) = series.scans.first() else {
        return Vec::new();
    };
    let midnight = first.time_utc.date_naive().and_hms_opt(0, 0, 0).map(|t| t.and_utc());
    series
        .scans
        .iter()
        .map(|s| midnight.map_or(f64::NAN, |m| (s.time_utc - m).num_milliseconds() as f64 / 3.6e6))
        .collect()
}

/// Lz per channel against time.
pub fn zenith_scale_svg(series: &SkySeries) -> Result<String, ReportError> {
    let t = hours(series);
    let lines: Vec<Series> = (0..3)
        .map(|c| Series {
            label: format!("Lz {}", NAMES[c]),
            points: series
                .scans
                .iter()
                .zip(&t)
                .filter_map(|(s, &h)| s.models().map(|m| (h, m[c].lz)))
                .collect(),
            colour: COLOURS[c],
            markers: true,
        })
        .collect();
    line_plot_svg("sky scale Lz (eq. 5.9) per channel", "hours UTC", "W·m⁻²·sr⁻¹", &lines)
}

/// The shape parameters a, b, c, d, e of the green channel against time.
pub fn shape_parameters_svg(series: &SkySeries) -> Result<String, ReportError> {
    let t = hours(series);
    let params: [Parameter; 5] = [
        ("a", |m| m.a, (200, 40, 40)),
        ("b", |m| m.b, (230, 140, 0)),
        ("c", |m| m.c, (40, 150, 40)),
        ("d", |m| m.d, (40, 70, 200)),
        ("e", |m| m.e, (140, 40, 160)),
    ];
    let lines: Vec<Series> = params
        .iter()
        .map(|(name, f, colour)| Series {
            label: (*name).to_owned(),
            points: series
                .scans
                .iter()
                .zip(&t)
                .filter_map(|(s, &h)| s.models().map(|m| (h, f(&m[1]))))
                .collect(),
            colour: *colour,
            markers: false,
        })
        .collect();
    line_plot_svg(
        "sky shape (eq. 5.9), green channel",
        "hours UTC",
        "parameter value",
        &lines,
    )
}

/// Direct normal irradiance per channel against time.
pub fn irradiance_svg(series: &SkySeries) -> Result<String, ReportError> {
    let t = hours(series);
    let lines: Vec<Series> = (0..3)
        .map(|c| Series {
            label: format!("E {}", NAMES[c]),
            points: series
                .scans
                .iter()
                .zip(&t)
                .filter_map(|(s, &h)| s.sun.as_ref().map(|m| (h, m.irradiance_w_m2[c])))
                .collect(),
            colour: COLOURS[c],
            markers: true,
        })
        .collect();
    line_plot_svg("direct normal solar irradiance", "hours UTC", "W·m⁻²", &lines)
}

/// The sky conditions against time: the sky's and the sun's clear-sky
/// index and the cloud cover (scans whose figure could not be computed
/// have no point).
pub fn conditions_svg(series: &SkySeries) -> Result<String, ReportError> {
    let t = hours(series);
    type Figure = fn(&super::condition::SkyCondition) -> Option<f64>;
    let figures: [(&str, Figure, (u8, u8, u8)); 3] = [
        ("clear-sky index (sky)", |c| c.clear_sky_index, (40, 70, 200)),
        ("clear-sky index (sun)", |c| c.direct_clear_sky_index, (230, 140, 0)),
        ("cloud cover", |c| c.cloud_cover, (90, 90, 90)),
    ];
    let lines: Vec<Series> = figures
        .iter()
        .map(|(label, f, colour)| Series {
            label: (*label).to_owned(),
            points: series
                .conditions
                .iter()
                .zip(&t)
                .filter_map(|(c, &h)| f(c).filter(|v| v.is_finite()).map(|v| (h, v)))
                .collect(),
            colour: *colour,
            markers: true,
        })
        .collect();
    line_plot_svg(
        "sky conditions: clear-sky indices and cloud cover",
        "hours UTC",
        "ratio / fraction",
        &lines,
    )
}

/// ln E against air mass for every day, with each channel's fitted line.
pub fn langley_svg(series: &SkySeries) -> Result<String, ReportError> {
    let mut lines = Vec::new();
    for day in &series.days {
        for c in 0..3 {
            lines.push(Series {
                label: format!("{} {}", day.date, NAMES[c]),
                points: day.points.iter().map(|(m, e)| (*m, e[c].ln())).collect(),
                colour: COLOURS[c],
                markers: true,
            });
            if let Ok(fit) = &day.fit[c] {
                let (lo, hi) = day
                    .points
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                        (lo.min(p.0), hi.max(p.0))
                    });
                lines.push(Series {
                    label: format!("β {} = {:.4}", NAMES[c], fit.beta),
                    points: [0.0, lo, hi]
                        .iter()
                        .filter(|m| m.is_finite())
                        .map(|&m| (m, fit.e0.ln() - fit.beta * m))
                        .collect(),
                    colour: COLOURS[c],
                    markers: false,
                });
            }
        }
    }
    line_plot_svg("Langley: ln E against air mass", "air mass m", "ln E (W·m⁻²)", &lines)
}
