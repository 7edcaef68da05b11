//! A plot of a recovered response curve with its uncertainty band (SVG).

use plotters::prelude::*;

use super::HdrError;
use super::curve::{ResponseCurve, node_code};
use crate::camera::image::max_code;

/// Renders `curve` as an SVG: code (vertical) against `g = ln` relative
/// exposure (horizontal) per channel, each with its ±2σ band (shaded).
pub fn curve_plot_svg(curve: &ResponseCurve, title: &str) -> Result<String, HdrError> {
    let mut svg = String::new();
    let n = curve.nodes();
    let (mut xmin, mut xmax) = (f64::MAX, f64::MIN);
    for ch in &curve.channels {
        for (g, s) in ch.ln_exposure.iter().zip(&ch.ln_exposure_std) {
            xmin = xmin.min(g - 2.0 * s);
            xmax = xmax.max(g + 2.0 * s);
        }
    }
    if !(xmin.is_finite() && xmax.is_finite() && xmax > xmin) {
        return Err(HdrError::BadOption {
            name: "curve",
            value: format!("g range {xmin}..{xmax}"),
            expected: "a finite, non-constant curve",
        });
    }
    let ymax = f64::from(max_code(curve.bits));
    let err = |e: String| HdrError::BadOption {
        name: "plot",
        value: e,
        expected: "a drawable curve",
    };
    {
        let root = SVGBackend::with_string(&mut svg, (800, 600)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| err(e.to_string()))?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin(16)
            .x_label_area_size(48)
            .y_label_area_size(80)
            .build_cartesian_2d(xmin..xmax, 0.0..ymax)
            .map_err(|e| err(e.to_string()))?;
        chart
            .configure_mesh()
            .x_desc("g(z) = ln relative exposure")
            .y_desc("code z")
            // Readable in the report at 100 % zoom (crate::report::LABEL_PX).
            .label_style(("sans-serif", crate::report::LABEL_PX))
            .axis_desc_style(("sans-serif", crate::report::LABEL_PX + 1))
            .draw()
            .map_err(|e| err(e.to_string()))?;
        let colours = [RED, GREEN, BLUE];
        for (c, ch) in curve.channels.iter().enumerate() {
            let colour = colours[c];
            let mut band: Vec<(f64, f64)> = (0..n)
                .map(|k| {
                    (
                        ch.ln_exposure[k] - 2.0 * ch.ln_exposure_std[k],
                        node_code(curve.bits, k),
                    )
                })
                .collect();
            band.extend((0..n).rev().map(|k| {
                (
                    ch.ln_exposure[k] + 2.0 * ch.ln_exposure_std[k],
                    node_code(curve.bits, k),
                )
            }));
            chart
                .draw_series(std::iter::once(Polygon::new(band, colour.mix(0.2))))
                .map_err(|e| err(e.to_string()))?;
            chart
                .draw_series(LineSeries::new(
                    (0..n).map(|k| (ch.ln_exposure[k], node_code(curve.bits, k))),
                    &colour,
                ))
                .map_err(|e| err(e.to_string()))?
                .label(["red", "green", "blue"][c])
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour));
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .label_font(("sans-serif", crate::report::LABEL_PX))
            .draw()
            .map_err(|e| err(e.to_string()))?;
        root.present().map_err(|e| err(e.to_string()))?;
    }
    Ok(svg)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hdr::curve::{ChannelCurve, node_count};

    #[test]
    fn svg_has_three_curves_and_bands() {
        let n = node_count(8);
        let ch = ChannelCurve {
            ln_exposure: (0..n).map(|k| 2.2 * ((k as f64 + 1.0) / 128.0).ln()).collect(),
            ln_exposure_std: vec![0.05; n],
            support: vec![1; n],
        };
        let curve = ResponseCurve {
            bits: 8,
            channels: [ch.clone(), ch.clone(), ch],
        };
        let svg = curve_plot_svg(&curve, "test").unwrap();
        assert!(svg.starts_with("<svg"));
        assert!(
            svg.matches("<polyline").count() >= 6,
            "3 curves + 3 legend lines (+ grid)"
        );
        assert_eq!(svg.matches("<polygon").count(), 3, "three ±2σ bands");
        for label in ["red", "green", "blue", "code z"] {
            assert!(svg.contains(label), "{label}");
        }
        // Every text readable at the plot's natural size (at least 11 px;
        // the report showed its tick labels at about 8 px).
        let smallest = svg
            .split("font-size=\"")
            .skip(1)
            .map(|rest| {
                rest.split('"')
                    .next()
                    .unwrap()
                    .trim_end_matches("px")
                    .parse::<f64>()
                    .unwrap()
            })
            .fold(f64::INFINITY, f64::min);
        assert!(smallest >= 11.0, "smallest text {smallest} px");
    }
}
