//! Semantic validation: ranges, units and cross-references, collected as
//! issues at field paths. The loader turns each path into a file position.

use std::fmt;
use std::path::{Path, PathBuf};

/// One step of a path into a configuration value.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Segment {
    /// A named struct field.
    Field(String),
    /// A list element or tuple component.
    Index(usize),
}

impl From<&str> for Segment {
    fn from(name: &str) -> Self {
        Segment::Field(name.to_owned())
    }
}

impl From<usize> for Segment {
    fn from(i: usize) -> Self {
        Segment::Index(i)
    }
}

/// A path to a field, such as `sessions[2].steps[0].filter`.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct FieldPath(pub Vec<Segment>);

impl FieldPath {
    /// The path with one more segment.
    pub fn join(&self, seg: impl Into<Segment>) -> FieldPath {
        let mut p = self.0.clone();
        p.push(seg.into());
        FieldPath(p)
    }
}

impl fmt::Display for FieldPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.0.is_empty() {
            return f.write_str("(top level)");
        }
        for (k, seg) in self.0.iter().enumerate() {
            match seg {
                Segment::Field(name) if k == 0 => write!(f, "{name}")?,
                Segment::Field(name) => write!(f, ".{name}")?,
                Segment::Index(i) => write!(f, "[{i}]")?,
            }
        }
        Ok(())
    }
}

/// A problem found at a field.
#[derive(Debug, Clone, PartialEq)]
pub struct Issue {
    /// Where.
    pub path: FieldPath,
    /// The offending value, as the user would write it.
    pub value: String,
    /// What was expected instead.
    pub expected: String,
}

/// Something that can check itself.
pub trait Validate {
    /// Records every problem found into `v`.
    fn validate(&self, v: &mut Validator);
}

/// Collects issues while walking a configuration value.
#[derive(Debug, Default)]
pub struct Validator {
    path: FieldPath,
    issues: Vec<Issue>,
    base_dir: PathBuf,
}

impl Validator {
    /// A validator whose relative file paths resolve against `base_dir`.
    pub fn new(base_dir: impl Into<PathBuf>) -> Self {
        Validator {
            base_dir: base_dir.into(),
            ..Default::default()
        }
    }

    /// The issues found so far.
    pub fn into_issues(self) -> Vec<Issue> {
        self.issues
    }

    /// The directory relative paths resolve against.
    pub fn base_dir(&self) -> &Path {
        &self.base_dir
    }

    /// Runs `f` one level down, at `seg`.
    pub fn at<R>(&mut self, seg: impl Into<Segment>, f: impl FnOnce(&mut Self) -> R) -> R {
        self.path.0.push(seg.into());
        let r = f(self);
        self.path.0.pop();
        r
    }

    /// Records that `field` holds `value` where `expected` was wanted.
    pub fn invalid(&mut self, field: impl Into<Segment>, value: String, expected: &str) {
        let path = self.path.join(field);
        self.issues.push(Issue {
            path,
            value,
            expected: expected.to_owned(),
        });
    }

    /// Records that the value at the current path is `value` where
    /// `expected` was wanted.
    pub fn invalid_here(&mut self, value: String, expected: &str) {
        let path = self.path.clone();
        self.issues.push(Issue {
            path,
            value,
            expected: expected.to_owned(),
        });
    }

    /// Checks `lo <= x <= hi` (and that `x` is finite).
    pub fn range(&mut self, field: impl Into<Segment>, x: f64, lo: f64, hi: f64, what: &str) {
        if !(x.is_finite() && x >= lo && x <= hi) {
            self.invalid(
                field,
                fmt_f64(x),
                &format!("{what} in [{}, {}]", fmt_f64(lo), fmt_f64(hi)),
            );
        }
    }

    /// Checks `lo < x <= hi`.
    pub fn range_open_low(&mut self, field: impl Into<Segment>, x: f64, lo: f64, hi: f64, what: &str) {
        if !(x.is_finite() && x > lo && x <= hi) {
            self.invalid(
                field,
                fmt_f64(x),
                &format!("{what} in ({}, {}]", fmt_f64(lo), fmt_f64(hi)),
            );
        }
    }

    /// Checks `lo <= x < hi`.
    pub fn range_open_high(&mut self, field: impl Into<Segment>, x: f64, lo: f64, hi: f64, what: &str) {
        if !(x.is_finite() && x >= lo && x < hi) {
            self.invalid(
                field,
                fmt_f64(x),
                &format!("{what} in [{}, {})", fmt_f64(lo), fmt_f64(hi)),
            );
        }
    }

    /// Checks `lo < x < hi`.
    pub fn range_open(&mut self, field: impl Into<Segment>, x: f64, lo: f64, hi: f64, what: &str) {
        if !(x.is_finite() && x > lo && x < hi) {
            self.invalid(
                field,
                fmt_f64(x),
                &format!("{what} in ({}, {})", fmt_f64(lo), fmt_f64(hi)),
            );
        }
    }

    /// Checks an integer `lo <= x <= hi`.
    pub fn range_u(&mut self, field: impl Into<Segment>, x: u64, lo: u64, hi: u64, what: &str) {
        if !(lo..=hi).contains(&x) {
            self.invalid(field, x.to_string(), &format!("{what} in [{lo}, {hi}]"));
        }
    }

    /// Checks that a name is not empty or blank.
    pub fn non_empty(&mut self, field: impl Into<Segment>, s: &str) {
        if s.trim().is_empty() {
            self.invalid(field, format!("{s:?}"), "a non-empty name");
        }
    }

    /// Checks that the names of a list's elements (at `list`) are unique.
    pub fn unique_names<'a>(&mut self, list: &str, names: impl Iterator<Item = &'a str>) {
        let mut seen = std::collections::BTreeMap::new();
        for (i, name) in names.enumerate() {
            if let Some(first) = seen.insert(name, i) {
                self.at(list, |v| {
                    v.at(i, |v| {
                        v.invalid(
                            "name",
                            format!("{name:?}"),
                            &format!("a name not already used by {list}[{first}]"),
                        )
                    })
                });
            }
        }
    }

    /// Checks that a path, relative to the file being checked, names an
    /// existing file.
    pub fn existing_file(&mut self, field: impl Into<Segment>, p: &Path, what: &str) {
        let full = self.base_dir.join(p);
        if !full.is_file() {
            self.invalid(
                field,
                format!("{:?}", p.display().to_string()),
                &format!(
                    "the path of {what}, relative to this file ({} does not exist)",
                    full.display()
                ),
            );
        }
    }
}

/// Formats a float the way RON would show it.
pub fn fmt_f64(x: f64) -> String {
    if x.is_finite() && x == x.trunc() && x.abs() < 1e15 {
        format!("{x:.1}")
    } else {
        format!("{x}")
    }
}
