//! The sky time series as sections of the process report.

use super::day::SkySeries;
use super::keogram::{RESIDUAL_RANGE, keogram_png, keogram_residual_png};
use super::plots::{conditions_svg, irradiance_svg, langley_svg, shape_parameters_svg, zenith_scale_svg};
use crate::report::{ColourScale, Figure, ReportError, Section, Table};

fn opt(v: Option<f64>, scale: f64, digits: usize) -> String {
    v.map_or("–".into(), |v| format!("{:.*}", digits, v * scale))
}

/// The report's sections: the scans table, the sky and sun plots, the
/// keogram, and the extinction per day.
pub fn sky_series_sections(series: &SkySeries) -> Result<Vec<Section>, ReportError> {
    let rows: Vec<Vec<String>> = series
        .scans
        .iter()
        .zip(&series.conditions)
        .map(|(s, cond)| {
            let sun = s.sun.as_ref();
            let sky = s.sky.as_ref().filter(|k| k.len() == 3);
            vec![
                s.occurrence.clone(),
                s.time_utc.format("%H:%M:%S").to_string(),
                format!("{:.1}", 90.0 - s.sun_zenith_deg),
                sun.map_or("–".into(), |m| {
                    format!(
                        "{:.1} / {:.1} / {:.1}",
                        m.irradiance_w_m2[0], m.irradiance_w_m2[1], m.irradiance_w_m2[2]
                    )
                }),
                opt(s.quality.triplet_spread, 100.0, 2),
                sky.map_or("–".into(), |k| k[1].chosen.clone()),
                sky.map_or("–".into(), |k| k[1].reason.clone()),
                opt(s.quality.worst_rms_relative, 100.0, 2),
                opt(s.quality.masked_fraction, 100.0, 1),
                s.quality.names(),
                cond.condition
                    .map_or_else(|| format!("– ({})", cond.note), |c| c.as_str().to_owned()),
                opt(cond.cloud_cover, 100.0, 0),
                format!(
                    "{} / {}",
                    opt(cond.clear_sky_index, 1.0, 2),
                    opt(cond.direct_clear_sky_index, 1.0, 2)
                ),
                cond.clouds_near_sun_region
                    .map_or("–".into(), |b| if b { "yes" } else { "no" }.to_owned()),
            ]
        })
        .collect();
    let scans = Section {
        title: "Sky time series: scans".into(),
        paragraphs: vec![format!(
            "{} scans. Per scan: the sun's direct normal irradiance (mean of its filtered frames, §5.3.1), \
             the sky per channel fitted to eq. (5.9) with the model chosen by BIC (§5.3.2), and the quality \
             flags; the sky condition: the cloud cover over 24 regions of the dome, each compared with the \
             day's clear sky at that sun position (a region departing by more than 0.2 in |ln ratio| is cloudy), \
             the clear-sky indices of the sky and of the sun (over the day's Langley fit) and clouds in the sun's \
             neighbourhood by the sky image. The full record of each scan is in scans/*.ron; every column is in sky-series.csv.",
            series.scans.len()
        )],
        tables: vec![Table {
            caption: "per scan (sky model and reason: green channel)".into(),
            header: [
                "occurrence",
                "UTC",
                "sun elevation °",
                "E r/g/b W·m⁻²",
                "triplet spread %",
                "sky model",
                "why",
                "worst fit RMS %",
                "masked %",
                "flags",
                "sky condition",
                "cloud cover %",
                "clear-sky index sky / sun",
                "clouds near the sun (image)",
            ]
            .map(String::from)
            .to_vec(),
            rows,
        }],
        figures: Vec::new(),
    };
    let mut figures = Vec::new();
    let mut paragraphs = Vec::new();
    if !series.scans.is_empty() {
        let fitted = series.scans.iter().any(|s| s.models().is_some());
        let measured = series.scans.iter().any(|s| s.sun.is_some());
        let mut plots = Vec::new();
        if fitted {
            plots.push((zenith_scale_svg(series)?, "sky scale Lz per channel against time"));
            plots.push((
                shape_parameters_svg(series)?,
                "sky shape parameters (green) against time",
            ));
        } else {
            paragraphs.push("No scan's sky could be fitted: no sky plots.".to_owned());
        }
        if measured {
            plots.push((irradiance_svg(series)?, "direct normal solar irradiance against time"));
        }
        if series.conditions.iter().any(|c| c.cloud_cover.is_some()) {
            plots.push((
                conditions_svg(series)?,
                "sky conditions: clear-sky index of the sky and of the sun, cloud cover",
            ));
        }
        if !measured {
            paragraphs
                .push("No scan's sun could be measured (see the notes in scans/*.ron): no irradiance plot.".to_owned());
        }
        for (svg, caption) in plots {
            figures.push(Figure::Svg {
                svg,
                caption: caption.into(),
            });
        }
        figures.push(Figure::Png {
            bytes: keogram_png(&series.scans)?,
            caption: "keogram: profiles in the sun's vertical plane, one column per scan (sun-side horizon at the top, zenith in the middle); measured above, fitted below".into(),
        });
        figures.push(Figure::Map {
            bytes: keogram_residual_png(&series.scans)?,
            caption: "fitted / measured − 1 (green) per scan and profile bin; grey: no pixel".into(),
            scale: ColourScale::Diverging {
                low: -RESIDUAL_RANGE,
                high: RESIDUAL_RANGE,
                unit: "relative residual".into(),
            },
        });
    }
    let plots = Section {
        title: "Sky time series: plots".into(),
        paragraphs,
        tables: Vec::new(),
        figures,
    };
    let mut ext_rows = Vec::new();
    for d in &series.days {
        for (c, name) in ["r", "g", "b"].iter().enumerate() {
            ext_rows.push(match &d.fit[c] {
                Ok(e) => vec![
                    d.date.clone(),
                    (*name).into(),
                    format!("{:.4}", e.beta),
                    format!("{:.1}", e.e0),
                    format!("{:.4}", e.rms_log),
                    format!("{:.2}", e.air_mass_span),
                    format!("{} ({} left out)", d.points.len(), d.left_out),
                ],
                Err(why) => vec![
                    d.date.clone(),
                    (*name).into(),
                    format!("no fit: {why}"),
                    String::new(),
                    String::new(),
                    String::new(),
                    format!("{} ({} left out)", d.points.len(), d.left_out),
                ],
            });
        }
    }
    let mut ext_figures = Vec::new();
    if series.days.iter().any(|d| !d.points.is_empty()) {
        ext_figures.push(Figure::Svg {
            svg: langley_svg(series)?,
            caption: "ln E against Kasten–Young air mass; lines: the Langley fit per channel".into(),
        });
    }
    let extinction = Section {
        title: "Sky time series: extinction".into(),
        paragraphs: vec![
            "β per channel from the Langley fit ln E = ln E₀ − β m over the day's scans whose sun triplet agreed (§5.5.1)."
                .into(),
        ],
        tables: vec![Table {
            caption: "per day and channel".into(),
            header: ["date", "channel", "β", "E₀ W·m⁻²", "RMS ln E", "air-mass span", "scans"]
                .map(String::from)
                .to_vec(),
            rows: ext_rows,
        }],
        figures: ext_figures,
    };
    Ok(vec![scans, plots, extinction])
}
