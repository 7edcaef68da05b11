//! Quality verdicts: every product is `ok`, `poor` or `failed`, with the
//! figures behind it and the threshold each was held to.
//!
//! A [`Check`] holds one figure to a [`Gate`] (the thresholds live in
//! `campanile_config::quality`, with their documented defaults). A
//! [`ProductQuality`] is one product's checks, its worst verdict, and what
//! it inherited: a product made from a `poor` or `failed` one is at least
//! as bad, and says which ([`ProductQuality::inherit`]), so nothing that
//! failed is used downstream in silence. A [`QualityReport`] is a run's
//! products, written as `quality.json` beside them.
//!
//! The gates of each product are in [`gates`].

pub mod gates;

use std::fmt;

use serde::{Deserialize, Serialize};

pub use campanile_config::quality::{Better, Gate, Quality};

/// A product's quality.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Verdict {
    /// Every figure within its `poor` bound.
    Ok,
    /// Usable, with a figure past its `poor` bound: look before trusting it.
    Poor,
    /// A figure past its `failed` bound, or the product could not be made.
    Failed,
}

impl fmt::Display for Verdict {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Verdict::Ok => "ok",
            Verdict::Poor => "poor",
            Verdict::Failed => "failed",
        })
    }
}

/// One figure against its gate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Check {
    /// What the figure is, in words.
    pub figure: String,
    /// Its value (`null` in JSON when it is not a number, which fails).
    pub value: f64,
    /// Which way it is better.
    pub better: Better,
    /// The bound past which it is `poor`.
    pub poor: f64,
    /// The bound past which it is `failed`.
    pub failed: f64,
    /// The verdict of this figure alone.
    pub verdict: Verdict,
}

impl Check {
    /// Holds `value` to `gate`. A value that is not a number fails.
    pub fn new(figure: impl Into<String>, value: f64, gate: Gate, better: Better) -> Check {
        let past = |bound: f64| match better {
            Better::Lower => value > bound,
            Better::Higher => value < bound,
        };
        let verdict = if value.is_nan() || past(gate.failed) {
            Verdict::Failed
        } else if past(gate.poor) {
            Verdict::Poor
        } else {
            Verdict::Ok
        };
        Check {
            figure: figure.into(),
            value,
            better,
            poor: gate.poor,
            failed: gate.failed,
            verdict,
        }
    }

    /// "condition estimate 1.2e9 > 1e8 (failed)": the figure against the bound it passed.
    pub fn describe(&self) -> String {
        let (op, bound) = match (self.verdict, self.better) {
            (Verdict::Failed, Better::Lower) => (">", self.failed),
            (Verdict::Failed, Better::Higher) => ("<", self.failed),
            (Verdict::Poor, Better::Lower) => (">", self.poor),
            (Verdict::Poor, Better::Higher) => ("<", self.poor),
            (Verdict::Ok, Better::Lower) => ("≤", self.poor),
            (Verdict::Ok, Better::Higher) => ("≥", self.poor),
        };
        format!("{} {} {op} {}", self.figure, number(self.value), number(bound))
    }
}

/// A figure as a person reads it: up to four significant digits, in
/// scientific notation when very large or small.
pub fn number(x: f64) -> String {
    if !x.is_finite() {
        return format!("{x}");
    }
    let a = x.abs();
    if a != 0.0 && !(1e-3..1e5).contains(&a) {
        let s = format!("{x:.2e}");
        // 1.00e9 → 1e9
        match s.split_once('e') {
            Some((m, e)) => format!("{}e{e}", m.trim_end_matches('0').trim_end_matches('.')),
            None => s,
        }
    } else {
        let s = format!("{x:.4}");
        s.trim_end_matches('0').trim_end_matches('.').to_owned()
    }
}

/// One product's quality.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ProductQuality {
    /// The product: its kind and name, e.g. `sky sky@2026-06-21#0`.
    pub product: String,
    /// The worst of its checks and of what it inherited.
    pub verdict: Verdict,
    /// The worst of its own checks alone (`failed` if it could not be made).
    pub own_verdict: Verdict,
    /// Its figures against their gates.
    pub checks: Vec<Check>,
    /// What the checks do not say: the model chosen, why something was refused.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
    /// Upstream products that were not `ok`, as "product: verdict".
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub inherited: Vec<String>,
}

impl ProductQuality {
    /// A product judged by its checks.
    pub fn new(product: impl Into<String>, checks: Vec<Check>) -> ProductQuality {
        let verdict = checks.iter().map(|c| c.verdict).max().unwrap_or(Verdict::Ok);
        ProductQuality {
            product: product.into(),
            verdict,
            own_verdict: verdict,
            checks,
            notes: Vec::new(),
            inherited: Vec::new(),
        }
    }

    /// A product that could not be made, and why.
    pub fn not_made(product: impl Into<String>, why: impl Into<String>) -> ProductQuality {
        ProductQuality {
            product: product.into(),
            verdict: Verdict::Failed,
            own_verdict: Verdict::Failed,
            checks: Vec::new(),
            notes: vec![why.into()],
            inherited: Vec::new(),
        }
    }

    /// With a note.
    pub fn with_note(mut self, note: impl Into<String>) -> ProductQuality {
        self.notes.push(note.into());
        self
    }

    /// Takes on an upstream product's verdict if it was not `ok`: a sun
    /// measured through a failed response curve has failed too.
    pub fn inherit(&mut self, upstream: &ProductQuality) {
        if upstream.verdict == Verdict::Ok {
            return;
        }
        let what = format!("{}: {}", upstream.product, upstream.verdict);
        if !self.inherited.contains(&what) {
            self.inherited.push(what);
        }
        self.verdict = self.verdict.max(upstream.verdict);
    }

    /// The figures that put it where it is ("condition estimate 1.2e9 > 1e8"),
    /// its notes if it could not be made, and what it inherited.
    pub fn reasons(&self) -> String {
        let mut parts: Vec<String> = self
            .checks
            .iter()
            .filter(|c| c.verdict != Verdict::Ok)
            .map(Check::describe)
            .collect();
        if self.checks.is_empty() && self.verdict != Verdict::Ok {
            parts.extend(self.notes.iter().cloned());
        }
        if !self.inherited.is_empty() {
            parts.push(format!("inherited from {}", self.inherited.join(", ")));
        }
        parts.join("; ")
    }
}

/// A run's products and their verdicts: `quality.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct QualityReport {
    /// The worst verdict of any product.
    pub verdict: Verdict,
    /// Counts of `ok`, `poor` and `failed` products.
    pub counts: VerdictCounts,
    /// The thresholds the products were held to.
    pub thresholds: Quality,
    /// Every product.
    pub products: Vec<ProductQuality>,
}

/// How many products have each verdict.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct VerdictCounts {
    /// `ok` products.
    pub ok: usize,
    /// `poor` products.
    pub poor: usize,
    /// `failed` products.
    pub failed: usize,
}

impl QualityReport {
    /// The report of `products`, judged against `thresholds`.
    pub fn new(products: Vec<ProductQuality>, thresholds: &Quality) -> QualityReport {
        let mut counts = VerdictCounts::default();
        for p in &products {
            match p.verdict {
                Verdict::Ok => counts.ok += 1,
                Verdict::Poor => counts.poor += 1,
                Verdict::Failed => counts.failed += 1,
            }
        }
        QualityReport {
            verdict: products.iter().map(|p| p.verdict).max().unwrap_or(Verdict::Ok),
            counts,
            thresholds: thresholds.clone(),
            products,
        }
    }

    /// The products with this verdict.
    pub fn with(&self, verdict: Verdict) -> impl Iterator<Item = &ProductQuality> {
        self.products.iter().filter(move |p| p.verdict == verdict)
    }

    /// One line for the terminal: "quality: 41 ok, 2 poor, 1 failed — failed: response (…)".
    ///
    /// The products that failed their own checks are named with their
    /// figures, those that failed only through what they inherited are
    /// counted, and poor ones are named (beyond three, counted).
    pub fn summary_line(&self) -> String {
        let c = self.counts;
        let mut line = format!("quality: {} ok, {} poor, {} failed", c.ok, c.poor, c.failed);
        let failed = self.failed_products();
        if !failed.is_empty() {
            line.push_str(&format!(" — failed: {}", failed.join("; ")));
        }
        let poor: Vec<&str> = self.with(Verdict::Poor).map(|p| p.product.as_str()).collect();
        match poor.len() {
            0 => {}
            1..=3 => line.push_str(&format!(" — poor: {}", poor.join(", "))),
            n => line.push_str(&format!(
                " — poor: {}, … ({n} in all; see quality.json)",
                poor[..3].join(", ")
            )),
        }
        line
    }

    /// The products that failed their own checks, each with its figures;
    /// then those that failed only through what they inherited, named
    /// with it when there are at most three, else counted.
    pub fn failed_products(&self) -> Vec<String> {
        let (own, inherited): (Vec<&ProductQuality>, Vec<&ProductQuality>) = self
            .with(Verdict::Failed)
            .partition(|p| p.own_verdict == Verdict::Failed);
        let mut out: Vec<String> = own
            .iter()
            .map(|p| {
                let alone = ProductQuality {
                    inherited: Vec::new(),
                    ..(*p).clone()
                };
                format!("{} ({})", p.product, alone.reasons())
            })
            .collect();
        match inherited.len() {
            0 => {}
            1..=3 => out.extend(inherited.iter().map(|p| format!("{} ({})", p.product, p.reasons()))),
            n => out.push(format!(
                "{n} more through what they inherited (quality.json lists them)"
            )),
        }
        out
    }

    /// Pretty JSON, figures that are not numbers as `null`.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_check_is_ok_poor_or_failed_either_way_round_and_nan_fails() {
        let lower = Gate::new(1e6, 1e8);
        assert_eq!(Check::new("c", 1e3, lower, Better::Lower).verdict, Verdict::Ok);
        assert_eq!(Check::new("c", 1e6, lower, Better::Lower).verdict, Verdict::Ok);
        assert_eq!(Check::new("c", 2e6, lower, Better::Lower).verdict, Verdict::Poor);
        assert_eq!(Check::new("c", 1.2e9, lower, Better::Lower).verdict, Verdict::Failed);
        assert_eq!(Check::new("c", f64::NAN, lower, Better::Lower).verdict, Verdict::Failed);
        let higher = Gate::new(1.0, 0.75);
        assert_eq!(Check::new("u", 1.0, higher, Better::Higher).verdict, Verdict::Ok);
        assert_eq!(Check::new("u", 0.875, higher, Better::Higher).verdict, Verdict::Poor);
        assert_eq!(Check::new("u", 0.5, higher, Better::Higher).verdict, Verdict::Failed);
        assert_eq!(
            Check::new("condition estimate", 1.2e9, lower, Better::Lower).describe(),
            "condition estimate 1.2e9 > 1e8"
        );
        assert_eq!(
            Check::new("exposures used", 0.5, higher, Better::Higher).describe(),
            "exposures used 0.5 < 0.75"
        );
    }

    #[test]
    fn numbers_read_as_a_person_writes_them() {
        assert_eq!(number(1e308), "1e308");
        assert_eq!(number(0.03), "0.03");
        assert_eq!(number(12345.678), "12345.678");
        assert_eq!(number(2.5e-5), "2.5e-5");
        assert_eq!(number(f64::NAN), "NaN");
    }

    #[test]
    fn downstream_products_inherit_what_is_not_ok_and_the_report_names_it() {
        let response = ProductQuality::new(
            "response",
            vec![Check::new(
                "condition estimate",
                1.2e9,
                Gate::new(1e6, 1e8),
                Better::Lower,
            )],
        );
        let mut sun = ProductQuality::new(
            "sun s@1",
            vec![Check::new("triplet spread", 0.01, Gate::new(0.03, 0.15), Better::Lower)],
        );
        assert_eq!(sun.verdict, Verdict::Ok);
        sun.inherit(&response);
        sun.inherit(&response);
        assert_eq!(sun.verdict, Verdict::Failed);
        assert_eq!(sun.inherited, vec!["response: failed".to_owned()]);
        let ok = ProductQuality::new("sky s@1", vec![]);
        let report = QualityReport::new(vec![response, sun, ok], &Quality::default());
        assert_eq!(report.verdict, Verdict::Failed);
        assert_eq!(
            report.counts,
            VerdictCounts {
                ok: 1,
                poor: 0,
                failed: 2
            }
        );
        let line = report.summary_line();
        assert_eq!(
            line,
            "quality: 1 ok, 0 poor, 2 failed — failed: response (condition estimate 1.2e9 > 1e8); \
             sun s@1 (inherited from response: failed)"
        );
        assert_eq!(report.products[1].own_verdict, Verdict::Ok);
        let json: serde_json::Value = serde_json::from_str(&report.to_json()).unwrap();
        assert_eq!(json["products"][0]["verdict"], "failed");
        assert_eq!(json["products"][0]["checks"][0]["failed"], 1e8);
    }
}
