//! A configuration file's text, read once, with what is needed to point
//! at any of its fields.

use std::path::{Path, PathBuf};

use serde::de::DeserializeOwned;

use crate::error::ConfigError;
use crate::span_tree::{self, Node};
use crate::validate::{Issue, Segment};

/// Files larger than this are refused rather than read.
pub const MAX_FILE_BYTES: u64 = 16 * 1024 * 1024;

/// The RON dialect of Campanile's files: standard RON, plus `implicit_some`
/// so that an optional field may be written `x: 1.0` as well as `x: Some(1.0)`.
pub fn ron_options() -> ron::Options {
    ron::Options::default().with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME)
}

/// A configuration file's text and the span tree over it.
#[derive(Debug, Clone)]
pub struct SourceFile {
    /// The path it was read from (as given).
    pub path: PathBuf,
    /// Its text.
    pub text: String,
    tree: Option<Node>,
}

impl SourceFile {
    /// Reads a file.
    pub fn read(path: &Path) -> Result<SourceFile, ConfigError> {
        let fail = |message: String| ConfigError {
            file: path.to_owned(),
            position: None,
            field: None,
            value: None,
            message,
        };
        let meta = std::fs::metadata(path).map_err(|e| fail(format!("cannot read the file: {e}")))?;
        if !meta.is_file() {
            return Err(fail("cannot read the file: it is not a regular file".into()));
        }
        if meta.len() > MAX_FILE_BYTES {
            return Err(fail(format!(
                "the file is {} bytes; a configuration file must be under {MAX_FILE_BYTES}",
                meta.len()
            )));
        }
        let bytes = std::fs::read(path).map_err(|e| fail(format!("cannot read the file: {e}")))?;
        match String::from_utf8(bytes) {
            Ok(text) => Ok(SourceFile::from_text(path, text)),
            Err(e) => {
                let valid = e.utf8_error().valid_up_to();
                let text = String::from_utf8_lossy(&e.as_bytes()[..valid]).into_owned();
                let (line, col) = span_tree::line_col(&text, valid);
                let field = span_tree::path_before(&text, valid);
                Err(ConfigError {
                    file: path.to_owned(),
                    position: Some((line, col)),
                    field: (!field.0.is_empty()).then(|| field.to_string()),
                    value: None,
                    message: "the file is not valid UTF-8 text".into(),
                })
            }
        }
    }

    /// Wraps text already in memory.
    pub fn from_text(path: &Path, text: String) -> SourceFile {
        let tree = span_tree::parse(&text);
        SourceFile {
            path: path.to_owned(),
            text,
            tree,
        }
    }

    /// The directory that relative paths in this file resolve against.
    pub fn base_dir(&self) -> PathBuf {
        self.path.parent().map(Path::to_owned).unwrap_or_default()
    }

    /// The name of the top-level value, e.g. `Station`, with its offset.
    pub fn top_level_name(&self) -> Option<(String, usize)> {
        span_tree::first_name(&self.text)
    }

    /// Deserializes the whole file as a `T`.
    pub fn parse<T: DeserializeOwned>(&self) -> Result<T, ConfigError> {
        ron_options().from_str::<T>(&self.text).map_err(|e| self.ron_error(e))
    }

    fn ron_error(&self, e: ron::error::SpannedError) -> ConfigError {
        let reported = span_tree::offset_of_line_col(&self.text, e.span.start.line, e.span.start.col);
        // ron may report the blank before a value: point at the value itself.
        let start = span_tree::next_token_start(&self.text, reported).unwrap_or(reported);
        let mut field = match &self.tree {
            Some(t) => t.path_at(start),
            None => span_tree::path_before(&self.text, start),
        };
        let token = span_tree::token_text_at(&self.text, start);
        let (value, message) = match &e.code {
            ron::Error::MissingStructField { field: name, .. } => {
                field = field.join(Segment::Field((*name).to_owned()));
                (None, "a value for this required field, which is missing".to_owned())
            }
            ron::Error::Eof => (
                None,
                "more text: the file ends too early (is a closing bracket missing?)".to_owned(),
            ),
            ron::Error::InvalidValueForType { expected, found } => (Some(found.clone()), expected.clone()),
            ron::Error::ExpectedFloat => (token, "a number with a decimal point, e.g. 1.0".to_owned()),
            ron::Error::ExpectedInteger => (token, "a whole number".to_owned()),
            ron::Error::ExpectedString | ron::Error::ExpectedStringEnd => {
                (token, "a string in double quotes".to_owned())
            }
            ron::Error::ExpectedComma => (token, "a comma between fields or elements".to_owned()),
            ron::Error::Message(m) => (token, format!("a valid value ({m})")),
            other => (None, other.to_string()),
        };
        let field = (!field.0.is_empty()).then(|| field.to_string());
        ConfigError {
            file: self.path.clone(),
            position: Some(span_tree::line_col(&self.text, start)),
            field,
            value,
            message,
        }
    }

    /// Turns a validation issue into an error at the issue's position.
    pub fn locate(&self, issue: Issue) -> ConfigError {
        let offset = self.tree.as_ref().map_or(0, |t| t.offset_of(&issue.path));
        ConfigError {
            file: self.path.clone(),
            position: Some(span_tree::line_col(&self.text, offset)),
            field: Some(issue.path.to_string()),
            value: Some(issue.value),
            message: issue.expected,
        }
    }
}
