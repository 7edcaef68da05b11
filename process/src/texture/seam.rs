//! How visible the patch borders are, and the verdict on a texture.
//!
//! Without the truth, a seam shows where the photographs disagree: a
//! misregistered photograph paints the neighbouring surface (or the sky)
//! along a face's edge, and an occluder's silhouette does the same. So the
//! figure is the photographs' weighted relative spread
//! ([`super::synthesis::PatchTexture::spread`]) at the texels along each
//! face's border (on the face, with an 8-neighbour off it) against the same
//! spread inside the faces; a ratio near 1 means the borders are as
//! consistent as the interiors.
//!
//! The verdict (DESIGN.md, "Verdicts"): `failed` when less than
//! [`QualityLimits::min_coverage_poor`] of the texels on the faces were seen
//! (or no photograph contributed), `poor` below
//! [`QualityLimits::min_coverage_ok`], with a border spread over
//! [`QualityLimits::max_seam_ratio`] times the interior's, or with a
//! photograph that agrees best with the others when moved by more than
//! [`QualityLimits::max_shift_px`] (the registration check of
//! [`super::synthesis`]), else `ok`.
//!
//! Mixed pixels: along a face's outline in a photograph, a pixel whose
//! centre is on the face still integrates the sky or the surface beyond
//! over part of its area. Where one photograph sees a corner against the
//! sky and another against the next face, those pixels disagree although
//! the poses are exact: on the simulator's tower (0.125 m texels, three
//! exact 640 × 480 photographs) the border spread was 0.137 against 0.032
//! inside, 4.3×; the 25 worst of the 256 border texels seen twice all lay
//! on the tower's vertical corners, one photograph's value up to 2× the
//! other's, and with the margin below none of the 256 is seen twice.
//! Synthesis therefore uses only pixels whose neighbours show the same face
//! ([`super::synthesis::SynthesisSettings::edge_margin_px`]).

use serde::{Deserialize, Serialize};

use super::patch::Patch;
use super::synthesis::{PatchTexture, SynthesisReport, TexelStatus};

/// The seam figures.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct SeamFigures {
    /// RMS relative spread of the photographs at border texels seen by two or more.
    pub border_spread: f64,
    /// The same inside the faces.
    pub interior_spread: f64,
    /// Border texels counted.
    pub border_texels: usize,
    /// Interior texels counted.
    pub interior_texels: usize,
}

impl SeamFigures {
    /// `border_spread / interior_spread` (1 when either is missing or the interior is exact).
    pub fn ratio(&self) -> f64 {
        if self.border_texels == 0 || self.interior_texels == 0 || self.interior_spread <= 0.0 {
            1.0
        } else {
            self.border_spread / self.interior_spread
        }
    }
}

/// Whether texel `(i, j)` of `patch` is on its face's border.
pub fn on_border(patch: &Patch, i: usize, j: usize) -> bool {
    for dj in -1i64..=1 {
        for di in -1i64..=1 {
            let (ii, jj) = (i as i64 + di, j as i64 + dj);
            if ii < 0 || jj < 0 || ii >= patch.cols as i64 || jj >= patch.rows as i64 {
                return true;
            }
            if patch.texel_triangle[jj as usize * patch.cols + ii as usize].is_none() {
                return true;
            }
        }
    }
    false
}

/// The seam figures of `textures` on `patches`.
pub fn seam_figures(patches: &[Patch], textures: &[PatchTexture]) -> SeamFigures {
    let (mut b, mut nb, mut i_sum, mut ni) = (0.0, 0usize, 0.0, 0usize);
    for (patch, tex) in patches.iter().zip(textures) {
        for j in 0..patch.rows {
            for i in 0..patch.cols {
                let k = j * patch.cols + i;
                if tex.status[k] != TexelStatus::Seen || tex.photos[k] < 2 {
                    continue;
                }
                let s = f64::from(tex.spread[k]);
                if on_border(patch, i, j) {
                    b += s * s;
                    nb += 1;
                } else {
                    i_sum += s * s;
                    ni += 1;
                }
            }
        }
    }
    let rms = |sum: f64, n: usize| if n == 0 { 0.0 } else { (sum / n as f64).sqrt() };
    SeamFigures {
        border_spread: rms(b, nb),
        interior_spread: rms(i_sum, ni),
        border_texels: nb,
        interior_texels: ni,
    }
}

/// The thresholds of the verdict.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct QualityLimits {
    /// Seen fraction of the texels on the faces for `ok`.
    pub min_coverage_ok: f64,
    /// Below this seen fraction the texture `failed`.
    pub min_coverage_poor: f64,
    /// Largest border-to-interior spread ratio for `ok`.
    pub max_seam_ratio: f64,
    /// Largest image shift, pixels, at which a photograph agrees best with
    /// the others ([`super::synthesis::PhotoOffset`]) for `ok`.
    #[serde(default = "default_max_shift_px")]
    pub max_shift_px: f64,
}

fn default_max_shift_px() -> f64 {
    QualityLimits::default().max_shift_px
}

impl Default for QualityLimits {
    fn default() -> Self {
        QualityLimits {
            min_coverage_ok: 0.95,
            min_coverage_poor: 0.5,
            max_seam_ratio: 2.0,
            max_shift_px: 0.3,
        }
    }
}

/// The verdict with its figures and reasons.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Quality {
    /// `ok`, `poor` or `failed`.
    pub verdict: String,
    /// Seen fraction of the texels on the faces.
    pub coverage: f64,
    /// Texels on the faces.
    pub texels_on_faces: usize,
    /// Of those, unseen (filled from neighbours).
    pub unseen: usize,
    /// The seam figures.
    pub seams: SeamFigures,
    /// Why the verdict is not `ok`.
    pub reasons: Vec<String>,
    /// The limits applied.
    pub limits: QualityLimits,
}

/// The verdict on a synthesis.
pub fn judge(report: &SynthesisReport, seams: &SeamFigures, limits: &QualityLimits) -> Quality {
    let coverage = report.coverage();
    let mut reasons = Vec::new();
    let mut verdict = "ok";
    if report.used.iter().all(|&u| u == 0) {
        reasons.push("no photograph sees any texel of the surfaces".to_string());
        verdict = "failed";
    } else if coverage < limits.min_coverage_poor {
        reasons.push(format!(
            "coverage {:.1}% below {:.0}%",
            100.0 * coverage,
            100.0 * limits.min_coverage_poor
        ));
        verdict = "failed";
    } else if coverage < limits.min_coverage_ok {
        reasons.push(format!(
            "coverage {:.1}% below {:.0}%: {} texels seen by no photograph were filled from their neighbours",
            100.0 * coverage,
            100.0 * limits.min_coverage_ok,
            report.unseen
        ));
        verdict = "poor";
    }
    for (k, offset) in report.offsets.iter().enumerate() {
        if let Some(o) = offset
            && o.length_px() > limits.max_shift_px
        {
            reasons.push(format!(
                "photograph {} agrees best with the photographs sharing its texels when its image is moved ({:.2}, {:.2}) px ({:.2} px, limit {:.2} px, over {} texels): its pose or theirs is off",
                k + 1,
                o.shift_px[0],
                o.shift_px[1],
                o.length_px(),
                limits.max_shift_px,
                o.texels
            ));
            if verdict == "ok" {
                verdict = "poor";
            }
        }
    }
    if seams.ratio() > limits.max_seam_ratio {
        reasons.push(format!(
            "the photographs disagree {:.1}× more along face borders than inside (limit {:.1}×): check the poses",
            seams.ratio(),
            limits.max_seam_ratio
        ));
        if verdict == "ok" {
            verdict = "poor";
        }
    }
    Quality {
        verdict: verdict.to_string(),
        coverage,
        texels_on_faces: report.texels_on_faces,
        unseen: report.unseen,
        seams: *seams,
        reasons,
        limits: *limits,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn report(on: usize, unseen: usize, used: usize) -> SynthesisReport {
        SynthesisReport {
            texels_on_faces: on,
            unseen,
            per_patch: vec![(on, unseen)],
            used: vec![used],
            occluded: vec![0],
            grazing: vec![0],
            offsets: vec![None],
        }
    }

    #[test]
    fn the_verdict_follows_coverage_and_seams() {
        let l = QualityLimits::default();
        let quiet = SeamFigures {
            border_spread: 0.02,
            interior_spread: 0.02,
            border_texels: 10,
            interior_texels: 10,
        };
        assert_eq!(judge(&report(100, 2, 98), &quiet, &l).verdict, "ok");
        let q = judge(&report(100, 20, 80), &quiet, &l);
        assert_eq!(q.verdict, "poor");
        assert!(q.reasons[0].contains("80.0%"), "{:?}", q.reasons);
        assert_eq!(judge(&report(100, 60, 40), &quiet, &l).verdict, "failed");
        assert_eq!(judge(&report(100, 100, 0), &quiet, &l).verdict, "failed");
        let loud = SeamFigures {
            border_spread: 0.1,
            ..quiet
        };
        assert!((loud.ratio() - 5.0).abs() < 1e-12);
        assert_eq!(judge(&report(100, 0, 100), &loud, &l).verdict, "poor");
        // A photograph that agrees best when moved 0.5 px: poor, named; 0.2 px: ok.
        let shifted = |d: f64| SynthesisReport {
            offsets: vec![Some(crate::texture::synthesis::PhotoOffset {
                shift_px: [0.3 * d, 0.4 * d],
                texels: 500,
            })],
            ..report(100, 0, 100)
        };
        let q = judge(&shifted(1.0), &quiet, &l);
        assert_eq!(q.verdict, "poor");
        assert!(
            q.reasons[0].contains("photograph 1") && q.reasons[0].contains("0.50 px"),
            "{:?}",
            q.reasons
        );
        assert_eq!(judge(&shifted(0.4), &quiet, &l).verdict, "ok");
    }
}
