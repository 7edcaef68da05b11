//! Report sections for the first stages of `process`: the response, the
//! sky per time, the sun's extinction, the environment map, and the speed
//! of each stage. With a [`Truth`] (the simulator's), every figure stands
//! beside its true value.

use campanile_process::camera::sensor::CameraModel;
use campanile_process::hdr::curve_plot::curve_plot_svg;
use campanile_process::pipeline::sky_fisheye;
use campanile_process::report::{
    ColourScale, Figure, ReportError, Section, Series, Table, false_colour_png, line_plot_svg, tonemapped_png,
};
use campanile_process::sky::angle_between;
use campanile_process::sun::{air_mass, fit_extinction};
use campanile_sim::world::World;

use super::Processed;

/// The simulator's truth, for the demo.
pub struct Truth<'a> {
    /// The simulated camera's photographic model.
    pub camera: CameraModel,
    /// The simulated world.
    pub world: &'a World,
}

const SKY_MAP_PX: usize = 160;

fn pct(x: f64) -> String {
    format!("{:.2}%", 100.0 * x)
}

/// The response curve section.
pub fn response(p: &Processed, truth: Option<&Truth>) -> Result<Section, ReportError> {
    let curve = &p.calibration.curve;
    let svg = curve_plot_svg(curve, "recovered response, ±2σ").map_err(|e| ReportError::Encode {
        what: "response plot".into(),
        message: e.to_string(),
    })?;
    let mut table = Table {
        caption: "Per channel".into(),
        header: vec![
            "channel".into(),
            "data residual (ln X, RMS)".into(),
            "condition estimate".into(),
        ],
        rows: Vec::new(),
    };
    if truth.is_some() {
        table
            .header
            .push("shape error vs truth (log-RMS, codes 400–3800 of 4095)".into());
        table.header.push("gauge error vs truth".into());
    }
    for (c, name) in ["red", "green", "blue"].iter().enumerate() {
        let d = &p.calibration.channels[c];
        let mut row = vec![
            (*name).to_owned(),
            format!("{:.4}", d.residual_rms),
            format!("{:.1e}", d.condition_estimate),
        ];
        if let Some(t) = truth {
            let max = f64::from((1u32 << curve.bits) - 1);
            let codes: Vec<f64> = (0..=34).map(|k| max * (0.1 + 0.8 * f64::from(k) / 34.0)).collect();
            let diff: Vec<f64> = codes
                .iter()
                .map(|&z| curve.ln_exposure(c, z) - t.camera.true_ln_exposure(z, c))
                .collect();
            let mean = diff.iter().sum::<f64>() / diff.len() as f64;
            let shape = (diff.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / diff.len() as f64).sqrt();
            row.push(format!("{shape:.4}"));
            row.push(format!("{:+.2}%", 100.0 * (mean.exp() - 1.0)));
        }
        table.rows.push(row);
    }
    Ok(Section {
        title: "Camera response".into(),
        paragraphs: vec![format!(
            "Debevec–Malik from the session's own frames: {} ({}). Radiance is in W·m⁻²·sr⁻¹ under the full-well gauge (the top code is full well).",
            p.summary.response.bracket, p.summary.response.reason
        )],
        tables: vec![table],
        figures: vec![Figure::Svg {
            svg,
            caption: "code against ln relative exposure, per channel, with the ±2σ band".into(),
        }],
    })
}

/// The sky section: per time, the model chosen and why, the residual map,
/// and (with truth) the error against the true sky.
pub fn sky(p: &Processed, truth: Option<&Truth>) -> Result<Section, ReportError> {
    let mut table = Table {
        caption: "Sky fits per time (green channel's model; residuals per channel r/g/b)".into(),
        header: vec![
            "occurrence".into(),
            "sun zenith".into(),
            "model".into(),
            "why".into(),
            "fit residual RMS".into(),
            "masked".into(),
        ],
        rows: Vec::new(),
    };
    if truth.is_some() {
        table.header.push("vs true sky, RMS".into());
    }
    let mut figures = Vec::new();
    for l in &p.light {
        let Some(fits) = &l.sky else { continue };
        let sun = l.sun.direction();
        let mut row = vec![
            l.occurrence.clone(),
            format!("{:.1}°", l.sun.zenith_rad.to_degrees()),
            format!("{:?}", fits[1].fit.kind),
            fits[1].fit.reason.clone(),
            fits.iter()
                .map(|f| pct(f.fit.rms_relative))
                .collect::<Vec<_>>()
                .join(" / "),
            pct(fits[1].masked_fraction),
        ];
        let model = &fits[1].fit.model;
        let residual = sky_fisheye(&p.merged, &p.optics, &l.occurrence, 1, SKY_MAP_PX, |d, measured| {
            measured / model.radiance(d[2].acos(), angle_between(d, sun)) - 1.0
        });
        figures.push(Figure::Map {
            bytes: false_colour_png("sky residual", SKY_MAP_PX, SKY_MAP_PX, &residual, (-0.1, 0.1))?,
            caption: format!(
                "{}: measured / fitted − 1, green channel; fisheye, zenith at the centre, north up, east right",
                l.occurrence
            ),
            scale: ColourScale::Diverging {
                low: -0.1,
                high: 0.1,
                unit: "relative residual".into(),
            },
        });
        if let Some(t) = truth
            && let Ok(Some(daylight)) = t.world.daylight(l.time)
        {
            let errs: Vec<String> = (0..3)
                .map(|c| {
                    let m = &fits[c].fit.model;
                    let mut sum = 0.0;
                    let mut n = 0.0;
                    for i in 0..27 {
                        for j in 0..72 {
                            let d = campanile_process::sky::direction(
                                (3.0 * f64::from(i)).to_radians(),
                                (5.0 * f64::from(j)).to_radians(),
                            );
                            if d[2] > 10f64.to_radians().sin() && angle_between(d, sun) > 10f64.to_radians() {
                                let r = m.radiance(d[2].acos(), angle_between(d, sun)) / daylight.sky_radiance(d)[c];
                                sum += (r - 1.0).powi(2);
                                n += 1.0;
                            }
                        }
                    }
                    pct((sum / n).sqrt())
                })
                .collect();
            row.push(errs.join(" / "));
        }
        table.rows.push(row);
    }
    Ok(Section {
        title: "Sky".into(),
        paragraphs: vec![
            "The eq. 5.9 sky fitted per channel to each sky scan (§5.3.2): the smallest model the samples support, chosen by BIC; samples that are not sky (the tower, glare) masked by robust reweighting. The truth column compares with the simulator's sky over elevations above 10° and more than 10° from the sun.".into(),
        ],
        tables: vec![table],
        figures,
    })
}

/// The sun section: irradiance per time and the Langley extinction fit.
pub fn sun(p: &Processed, truth: Option<&Truth>) -> Result<Section, ReportError> {
    let mut table = Table {
        caption: "Sun irradiance normal to the sun, r/g/b, in W·m⁻² of the camera's full-well gauge (the top code is full well): not calibrated W·m⁻², which would need the camera's absolute calibration; the true column is the simulator's sun in the same gauge".into(),
        header: vec![
            "occurrence".into(),
            "air mass".into(),
            "measured".into(),
            "triplet spread".into(),
        ],
        rows: Vec::new(),
    };
    if truth.is_some() {
        table.header.push("true".into());
    }
    let mut points: [Vec<(f64, f64)>; 3] = Default::default();
    for l in &p.light {
        let Some(s) = &l.sun_irradiance else { continue };
        let zenith = l.sun.zenith_rad;
        let mut row = vec![
            l.occurrence.clone(),
            format!("{:.2}", air_mass(zenith)),
            s.irradiance
                .iter()
                .map(|e| format!("{e:.1}"))
                .collect::<Vec<_>>()
                .join(" / "),
            s.spread.iter().map(|&x| pct(x)).collect::<Vec<_>>().join(" / "),
        ];
        if let Some(t) = truth
            && let Ok(Some(d)) = t.world.daylight(s.time)
        {
            row.push(
                d.sun_irradiance()
                    .iter()
                    .map(|e| format!("{e:.1}"))
                    .collect::<Vec<_>>()
                    .join(" / "),
            );
        }
        table.rows.push(row);
        for (pts, e) in points.iter_mut().zip(s.irradiance) {
            pts.push((zenith, e));
        }
    }
    let mut paragraphs = vec![
        "The sun measured in its filtered frames (§5.3.1): the disc integrated over its pixels with the filter undone; the triplet's spread is AERONET's agreement check.".to_owned(),
    ];
    let mut figures = Vec::new();
    let colours = [(200, 40, 40), (40, 150, 40), (40, 40, 200)];
    let mut series = Vec::new();
    let mut fit_table = Table {
        caption: "Langley extinction fit, ln E = ln E₀ − β m".into(),
        header: vec![
            "channel".into(),
            "β".into(),
            "E₀ (W·m⁻²)".into(),
            "air mass span".into(),
        ],
        rows: Vec::new(),
    };
    if truth.is_some() {
        fit_table.header.push("true β".into());
    }
    for c in 0..3 {
        let name = ["red", "green", "blue"][c];
        series.push(Series {
            label: format!("{name} measured"),
            points: points[c].iter().map(|&(z, e)| (air_mass(z), e.ln())).collect(),
            colour: colours[c],
            markers: true,
        });
        match fit_extinction(&points[c]) {
            Ok(f) => {
                let (lo, hi) = points[c]
                    .iter()
                    .map(|&(z, _)| air_mass(z))
                    .fold((f64::INFINITY, 0.0f64), |(lo, hi), m| (lo.min(m), hi.max(m)));
                series.push(Series {
                    label: format!("{name} fit β = {:.3}", f.beta),
                    points: vec![(lo, f.e0.ln() - f.beta * lo), (hi, f.e0.ln() - f.beta * hi)],
                    colour: colours[c],
                    markers: false,
                });
                let mut row = vec![
                    name.to_owned(),
                    format!("{:.4}", f.beta),
                    format!("{:.0}", f.e0),
                    format!("{:.2}", f.air_mass_span),
                ];
                if let Some(t) = truth {
                    row.push(format!("{:.4}", t.world.atmosphere.beta[c]));
                }
                fit_table.rows.push(row);
            }
            Err(e) => paragraphs.push(format!("{name}: no extinction fit: {e}")),
        }
    }
    if let Ok(svg) = line_plot_svg("Langley plot", "air mass", "ln E (W·m⁻²)", &series) {
        figures.push(Figure::Svg {
            svg,
            caption: "ln of the sun's irradiance against air mass, with the fitted extinction lines".into(),
        });
    }
    Ok(Section {
        title: "Sun and extinction".into(),
        paragraphs,
        tables: vec![table, fit_table],
        figures,
    })
}

/// The environment map section (the first occurrence with tiles).
pub fn environment(p: &Processed) -> Result<Section, ReportError> {
    let mut figures = Vec::new();
    for l in &p.light {
        let Some(map) = &l.environment else { continue };
        // Rows from the top (elevation +90°) down, upscaled 8×.
        let k = 8;
        let (w, h) = (map.cols * k, map.rows * k);
        let mut rgb = vec![0f32; w * h * 3];
        let mut values: Vec<f64> = map.regions.iter().filter(|r| r.count > 0).map(|r| r.mean[1]).collect();
        values.sort_by(f64::total_cmp);
        let white = values.get(values.len() * 95 / 100).copied().unwrap_or(1.0).max(1e-9);
        for y in 0..h {
            let row = map.rows - 1 - y / k;
            for x in 0..w {
                let r = &map.regions[row * map.cols + x / k];
                for c in 0..3 {
                    rgb[(y * w + x) * 3 + c] = if r.count > 0 { r.mean[c] as f32 } else { f32::NAN };
                }
            }
        }
        figures.push(Figure::Map {
            bytes: tonemapped_png("environment", w, h, &rgb, 1.0 / white)?,
            caption: format!(
                "{}: environment regions ({}×{}, elevation 90° at the top to −90° at the bottom, azimuth 0° north at the left, east next); black where no tile looked",
                l.occurrence, map.rows, map.cols
            ),
            scale: ColourScale::Radiance {
                white,
                unit: "mean radiance, W·m⁻²·sr⁻¹ (full-well gauge)".into(),
            },
        });
    }
    Ok(Section {
        title: "Environment".into(),
        paragraphs: vec![
            "Mean radiance per lat-long region from the environment tiles (§5.3.3), the input of the eq. 5.15 region models.".into(),
        ],
        tables: Vec::new(),
        figures,
    })
}

/// The speed table of the stages.
pub fn speed(p: &Processed) -> Section {
    Section {
        title: "Speed".into(),
        paragraphs: vec![format!(
            "{} frames in {} groups. Wall times on this machine.",
            p.summary.frames, p.summary.groups
        )],
        tables: vec![Table {
            caption: "Stages".into(),
            header: vec!["stage".into(), "seconds".into()],
            rows: p
                .summary
                .stage_seconds
                .iter()
                .map(|(s, t)| vec![s.clone(), format!("{t:.2}")])
                .collect(),
        }],
        figures: Vec::new(),
    }
}
