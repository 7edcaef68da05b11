//! The calibration's report in words: the verdict and its reasons, the
//! residual, each parameter with its σ, the strongest correlation and the
//! shots left out.

use std::fmt::Write as _;

use super::fit::SkyCameraCalibration;

/// A few lines for a person: verdict, residual, parameters with σ,
/// identifiability and rejections.
pub fn calibration_report(c: &SkyCameraCalibration) -> String {
    let mut o = String::new();
    let _ = writeln!(o, "verdict: {}", c.verdict);
    for r in &c.reasons {
        let _ = writeln!(o, "  {r}");
    }
    if !c.fitted {
        let _ = writeln!(o, "no fit: {} sun shots given, {} left out", c.shots, c.rejected.len());
    } else {
        let _ = writeln!(
            o,
            "residual: {:.4}° RMS, {:.4}° largest ({:.3} px RMS) over {} of {} sun shots",
            c.rms_residual_deg, c.max_residual_deg, c.rms_residual_px, c.used, c.shots
        );
        let _ = writeln!(
            o,
            "track: the sun moved {:.1}°, {:.1}° to {:.1}° off the camera's axis",
            c.track_span_deg, c.off_axis_range_deg.0, c.off_axis_range_deg.1
        );
        let _ = writeln!(o, "parameters (fitted ± σ, nominal):");
        for p in &c.parameters {
            let _ = writeln!(
                o,
                "  {:<22} {:>14.6} ± {:<10.3e} (nominal {:.6})",
                p.name, p.value, p.sigma, p.nominal
            );
        }
        let (a, b, r) = c.strongest_correlation;
        let _ = writeln!(o, "strongest correlation: {a} and {b}, {r:.4}");
        let _ = writeln!(
            o,
            "Levenberg–Marquardt: {} iterations, {}",
            c.iterations,
            if c.converged { "converged" } else { "not converged" }
        );
    }
    for r in &c.rejected {
        let _ = writeln!(
            o,
            "rejected shot {} at {}: {} ({:.3}°)",
            r.index,
            r.time.to_rfc3339(),
            r.reason,
            r.residual_deg
        );
    }
    o
}
