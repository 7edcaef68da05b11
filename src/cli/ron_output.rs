//! Writing a command's RON result: to a file (through a temporary file and
//! a rename, so that a crash never leaves half a file), or to standard output.

use std::path::Path;

use anyhow::Result;
use serde::Serialize;

/// Writes `value` as pretty RON to `out`, or prints it.
pub fn write_ron<T: Serialize>(value: &T, out: Option<&Path>) -> Result<()> {
    let text = ron::ser::to_string_pretty(value, ron::ser::PrettyConfig::default())?;
    match out {
        Some(path) => campanile_session::partial_file::write(path, (text + "\n").as_bytes())?,
        None => outln!("{text}")?,
    }
    Ok(())
}
