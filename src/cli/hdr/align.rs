//! `--align` and `--deghost` of `hdr calibrate|merge`: register a hand-held
//! bracket to its middle exposure and print what was found. The science is in
//! `campanile_process::hdr::{align, deghost}`.

use anyhow::{Context, Result};
use campanile_process::hdr::align::{AlignOptions, align_bracket, warp_bracket};
use campanile_process::hdr::bracket::Bracket;
use campanile_process::hdr::deghost::DeghostStats;

/// Aligns `bracket` to its middle exposure, prints one line per image
/// (`image X: dx +3.25 px, dy -1.50 px, rotation +0.00°, disagreement 2.1%`)
/// and a warning for each doubtful one, and returns the warped bracket.
pub(super) fn aligned(bracket: &Bracket) -> Result<Bracket> {
    let al = align_bracket(bracket, &AlignOptions::default()).context("aligning the bracket")?;
    for (img, a) in bracket.images().iter().zip(&al.images) {
        let t = a.transform;
        outln!(
            "image {}: dx {:+.2} px, dy {:+.2} px, rotation {:+.2}°, disagreement {:.1}% ({})",
            img.label,
            t.dx,
            t.dy,
            t.angle_rad.to_degrees(),
            100.0 * a.disagreement,
            a.verdict.describe()
        )?;
        if !a.verdict.is_trusted() {
            eprintln!(
                "warning: image {}: alignment {} ({:.1}% of pixels informative, shift uncertainty {:.3} px)",
                img.label,
                a.verdict.describe(),
                100.0 * a.informative_fraction,
                a.std_px
            );
        }
    }
    warp_bracket(bracket, &al.transforms()).context("resampling the aligned bracket")
}

/// Prints what deghosting excluded.
pub(super) fn report_deghost(s: &DeghostStats) -> Result<()> {
    outln!(
        "deghost: {} samples excluded at {} of {} pixels ({:.2}%)",
        s.samples_excluded,
        s.pixels_affected,
        s.pixels,
        100.0 * s.pixels_affected as f64 / s.pixels.max(1) as f64
    )?;
    Ok(())
}
