//! A recovered camera response curve: `g(z) = ln f⁻¹(z)` per channel (the
//! log of relative exposure that produces code `z`), with its uncertainty,
//! CSV input/output and the log-RMS error metric against a known truth.

use std::fmt::Write as _;
use std::path::Path;

use super::HdrError;
use crate::camera::image::max_code;

/// Most nodes a curve has. 8-bit curves have one node per code; deeper ones
/// (12, 16 bits) are piecewise linear over this many evenly spaced nodes.
pub const MAX_NODES: usize = 1024;

/// One channel of a response curve.
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelCurve {
    /// `g` at each node: natural log of relative exposure (arbitrary offset;
    /// the solvers fix `g` at the middle node to 0).
    pub ln_exposure: Vec<f64>,
    /// 1σ standard error of `g` at each node, from the solver's covariance.
    pub ln_exposure_std: Vec<f64>,
    /// How many sample observations fell on (or next to) each node.
    pub support: Vec<u32>,
}

/// A per-channel response curve for `bits`-bit codes.
#[derive(Debug, Clone, PartialEq)]
pub struct ResponseCurve {
    /// Bit depth of the codes.
    pub bits: u8,
    /// Red, green, blue.
    pub channels: [ChannelCurve; 3],
}

/// Number of curve nodes for a bit depth: `min(2^bits, MAX_NODES)`.
pub fn node_count(bits: u8) -> usize {
    (usize::from(max_code(bits)) + 1).min(MAX_NODES)
}

/// The node interval of `code`: index `k` and fraction `α`, so that
/// `g(code) = (1 − α)·g[k] + α·g[k + 1]`.
pub fn node_position(bits: u8, code: f64) -> (usize, f64) {
    let nodes = node_count(bits);
    let p = (code * (nodes - 1) as f64 / f64::from(max_code(bits))).clamp(0.0, (nodes - 1) as f64);
    let k = (p.floor() as usize).min(nodes - 2);
    (k, p - k as f64)
}

/// The code at node `k`.
pub fn node_code(bits: u8, k: usize) -> f64 {
    k as f64 * f64::from(max_code(bits)) / (node_count(bits) - 1) as f64
}

impl ResponseCurve {
    /// Number of nodes per channel.
    pub fn nodes(&self) -> usize {
        self.channels[0].ln_exposure.len()
    }

    /// `g(code)` of channel `c`, interpolated between nodes.
    pub fn ln_exposure(&self, c: usize, code: f64) -> f64 {
        let (k, a) = node_position(self.bits, code);
        let g = &self.channels[c].ln_exposure;
        (1.0 - a) * g[k] + a * g[k + 1]
    }

    /// `exp(g(z))` for every code `z` of channel `c` (a lookup table, f64).
    pub fn exposure_lut(&self, c: usize) -> Vec<f64> {
        (0..=max_code(self.bits))
            .map(|z| self.ln_exposure(c, f64::from(z)).exp())
            .collect()
    }

    /// Log-RMS error of channel `c` against `truth(code) = ln f⁻¹(code)`
    /// over the codes `lo..=hi` (given in 8-bit units and scaled to the
    /// curve's depth), after removing the best constant offset (the curve's
    /// gauge): `sqrt(mean((g − truth − mean(g − truth))²))`.
    pub fn log_rms_error(&self, c: usize, truth: impl Fn(f64) -> f64, lo: u16, hi: u16) -> f64 {
        let scale = f64::from(max_code(self.bits)) / 255.0;
        let codes: Vec<f64> = (lo..=hi).map(|z| f64::from(z) * scale).collect();
        let d: Vec<f64> = codes.iter().map(|&z| self.ln_exposure(c, z) - truth(z)).collect();
        log_rms_of_differences(&d)
    }

    /// Writes the curve as CSV: comment lines `# key=value`, a header, then one
    /// row per node: `code, g_r, std_r, support_r, g_g, std_g, support_g, g_b, std_b, support_b`.
    pub fn to_csv(&self, method: &str) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "# campanile response curve: g(z) = ln(relative exposure), per channel"
        );
        let _ = writeln!(s, "# bits={}", self.bits);
        let _ = writeln!(s, "# method={method}");
        s.push_str(
            "code,ln_exposure_r,ln_std_r,support_r,ln_exposure_g,ln_std_g,support_g,ln_exposure_b,ln_std_b,support_b\n",
        );
        for k in 0..self.nodes() {
            let _ = write!(s, "{}", node_code(self.bits, k));
            for ch in &self.channels {
                let _ = write!(
                    s,
                    ",{:.9},{:.9},{}",
                    ch.ln_exposure[k], ch.ln_exposure_std[k], ch.support[k]
                );
            }
            s.push('\n');
        }
        s
    }

    /// Reads a curve written by [`Self::to_csv`]. `path` is for error messages.
    pub fn from_csv(text: &str, path: &Path) -> Result<Self, HdrError> {
        let perr = |line: usize, what: String| HdrError::Parse {
            path: path.to_path_buf(),
            line,
            what,
        };
        let mut bits = None;
        let mut chans: [ChannelCurve; 3] = std::array::from_fn(|_| ChannelCurve {
            ln_exposure: vec![],
            ln_exposure_std: vec![],
            support: vec![],
        });
        let mut header_seen = false;
        for (i, line) in text.lines().enumerate() {
            let n = i + 1;
            let line = line.trim();
            if line.is_empty() {
                continue;
            }
            if let Some(rest) = line.strip_prefix('#') {
                if let Some(v) = rest.trim().strip_prefix("bits=") {
                    let b: u8 = v
                        .trim()
                        .parse()
                        .map_err(|_| perr(n, format!("bits='{v}': expected 8 to 16")))?;
                    if !(8..=16).contains(&b) {
                        return Err(perr(n, format!("bits={b}: expected 8 to 16")));
                    }
                    bits = Some(b);
                }
                continue;
            }
            if !header_seen {
                if !line.starts_with("code,") {
                    return Err(perr(
                        n,
                        format!("'{line}': expected the header line 'code,ln_exposure_r,…'"),
                    ));
                }
                header_seen = true;
                continue;
            }
            let fields: Vec<&str> = line.split(',').map(str::trim).collect();
            if fields.len() != 10 {
                return Err(perr(
                    n,
                    format!("{} fields: expected 10 (code and 3 × g, std, support)", fields.len()),
                ));
            }
            for (c, ch) in chans.iter_mut().enumerate() {
                let f = |j: usize| -> Result<f64, HdrError> {
                    let v: f64 = fields[j]
                        .parse()
                        .map_err(|_| perr(n, format!("field {} = '{}': expected a number", j + 1, fields[j])))?;
                    // |v| ≤ 700 keeps exp(v) finite in the merge's tables.
                    if v.is_finite() && v.abs() <= 700.0 {
                        Ok(v)
                    } else {
                        Err(perr(
                            n,
                            format!("field {} = {v}: expected a finite log value within ±700", j + 1),
                        ))
                    }
                };
                ch.ln_exposure.push(f(1 + 3 * c)?);
                ch.ln_exposure_std.push(f(2 + 3 * c)?);
                let j = 3 + 3 * c;
                let support: u32 = fields[j].parse().map_err(|_| {
                    perr(
                        n,
                        format!(
                            "field {} = '{}': expected a sample count (a whole number ≥ 0)",
                            j + 1,
                            fields[j]
                        ),
                    )
                })?;
                ch.support.push(support);
            }
        }
        let bits = bits.ok_or_else(|| perr(1, "no '# bits=N' line: expected the bit depth of the codes".into()))?;
        let rows = chans[0].ln_exposure.len();
        if rows != node_count(bits) {
            return Err(perr(
                1,
                format!("{rows} rows: expected {} nodes for {bits}-bit codes", node_count(bits)),
            ));
        }
        for (c, ch) in chans.iter().enumerate() {
            if let Some(k) = ch.ln_exposure.windows(2).position(|w| w[1] < w[0]) {
                return Err(perr(
                    1,
                    format!(
                        "channel {c} decreases between nodes {k} and {}: expected a monotone curve",
                        k + 1
                    ),
                ));
            }
        }
        Ok(Self { bits, channels: chans })
    }
}

/// RMS of `d` after removing its mean.
pub fn log_rms_of_differences(d: &[f64]) -> f64 {
    if d.is_empty() {
        return 0.0;
    }
    let mean = d.iter().sum::<f64>() / d.len() as f64;
    (d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / d.len() as f64).sqrt()
}

/// Weighted isotonic regression (pool adjacent violators): the non-decreasing
/// sequence closest to `y` in weighted least squares. Returns how many values moved.
pub fn make_monotone(y: &mut [f64], weights: &[f64]) -> usize {
    // Blocks of (mean, weight, length).
    let mut blocks: Vec<(f64, f64, usize)> = Vec::with_capacity(y.len());
    for (&v, &w) in y.iter().zip(weights) {
        let w = w.max(1e-12);
        blocks.push((v, w, 1));
        while blocks.len() > 1 && blocks[blocks.len() - 2].0 > blocks[blocks.len() - 1].0 {
            let (m2, w2, n2) = blocks.pop().expect("len > 1");
            let (m1, w1, n1) = blocks.pop().expect("len > 1");
            blocks.push(((m1 * w1 + m2 * w2) / (w1 + w2), w1 + w2, n1 + n2));
        }
    }
    let mut moved = 0;
    let mut i = 0;
    for (m, _, n) in blocks {
        for v in &mut y[i..i + n] {
            if (*v - m).abs() > 1e-12 {
                moved += 1;
            }
            *v = m;
        }
        i += n;
    }
    moved
}

#[cfg(test)]
mod tests {
    use super::*;

    fn linear_curve(bits: u8) -> ResponseCurve {
        let n = node_count(bits);
        let ch = ChannelCurve {
            ln_exposure: (0..n).map(|k| ((k as f64 + 1.0) / n as f64).ln()).collect(),
            ln_exposure_std: vec![0.01; n],
            // Real supports run to thousands of samples per node.
            support: (0..n as u32).map(|k| 730 + 17 * k).collect(),
        };
        ResponseCurve {
            bits,
            channels: [ch.clone(), ch.clone(), ch],
        }
    }

    #[test]
    fn csv_round_trip_is_exact_to_1e_9() {
        let c = linear_curve(12);
        let back = ResponseCurve::from_csv(&c.to_csv("test"), Path::new("x.csv")).unwrap();
        assert_eq!(back.bits, 12);
        for (a, b) in c.channels[1].ln_exposure.iter().zip(&back.channels[1].ln_exposure) {
            assert!((a - b).abs() < 1e-9);
        }
        assert_eq!(back.channels[2].support, c.channels[2].support);
    }

    #[test]
    fn csv_refuses_log_values_that_would_overflow() {
        let text = "# bits=8\ncode,a\n0,1e9,0,0,0,0,0,0,0,0\n";
        let e = ResponseCurve::from_csv(text, Path::new("c.csv"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("c.csv:3: field 2 = 1000000000"), "{e}");
    }

    #[test]
    fn csv_errors_name_line() {
        let text = "# bits=8\ncode,a\n0,1,2\n";
        let e = ResponseCurve::from_csv(text, Path::new("c.csv"))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("c.csv:3:") && e.contains("expected 10"), "{e}");
    }

    #[test]
    fn node_positions_for_8_and_16_bits() {
        assert_eq!(node_position(8, 37.0), (37, 0.0));
        let (k, a) = node_position(16, 65535.0);
        assert_eq!((k, a), (1022, 1.0));
        let (k, a) = node_position(16, 32767.5);
        assert!(k == 511 && (a - 0.5).abs() < 1e-9);
    }

    #[test]
    fn log_rms_ignores_offset() {
        let c = linear_curve(8);
        let e = c.log_rms_error(0, |z| ((z + 1.0) / 256.0).ln() + 3.0, 5, 250);
        assert!(e < 1e-12, "{e}");
    }

    #[test]
    fn pav_gives_monotone_least_squares() {
        let mut y = vec![1.0, 3.0, 2.0, 4.0];
        let moved = make_monotone(&mut y, &[1.0; 4]);
        assert_eq!(y, vec![1.0, 2.5, 2.5, 4.0]);
        assert_eq!(moved, 2);
    }
}
