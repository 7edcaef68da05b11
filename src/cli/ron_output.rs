//! Writing a command's RON result: to a file (through a temporary file and
//! a rename, so that a crash never leaves half a file), or to standard output.

use std::path::Path;

use anyhow::{Context, Result};
use serde::Serialize;

/// Writes `value` as pretty RON to `out`, or prints it.
pub fn write_ron<T: Serialize>(value: &T, out: Option<&Path>) -> Result<()> {
    let text = ron::ser::to_string_pretty(value, ron::ser::PrettyConfig::default())?;
    match out {
        Some(path) => {
            let tmp = path.with_extension("ron.partial");
            std::fs::write(&tmp, text + "\n").with_context(|| format!("{}: cannot write", tmp.display()))?;
            std::fs::rename(&tmp, path).with_context(|| format!("{}: cannot write", path.display()))?;
        }
        None => outln!("{text}")?,
    }
    Ok(())
}
