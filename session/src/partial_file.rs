//! Writing an output file whole or not at all: into `NAME.partial` beside
//! it, renamed over `NAME` when complete. A failed write or rename removes
//! the partial file, so a failure leaves neither half a file nor a
//! `.partial` behind.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use anyhow::Context;
use serde::Serialize;

use crate::Result;

/// `path` with `.partial` appended to its name.
fn partial_of(path: &Path) -> PathBuf {
    let mut name = path.as_os_str().to_owned();
    name.push(".partial");
    PathBuf::from(name)
}

/// Writes `bytes` to `path` through `path.partial`.
pub fn write(path: &Path, bytes: &[u8]) -> Result<()> {
    write_with(path, |w| w.write_all(bytes).map_err(|e| anyhow::Error::from(e).into()))
}

/// Writes `path` through `path.partial` with `fill`, which writes the
/// contents; on any error the partial file is removed.
pub fn write_with<T>(path: &Path, fill: impl FnOnce(&mut BufWriter<File>) -> Result<T>) -> Result<T> {
    let tmp = partial_of(path);
    let result = (|| {
        let file = File::create(&tmp).with_context(|| format!("{}: cannot create", tmp.display()))?;
        let mut w = BufWriter::new(file);
        let value = fill(&mut w)?;
        w.flush().with_context(|| format!("{}: cannot write", tmp.display()))?;
        std::fs::rename(&tmp, path).with_context(|| format!("{}: cannot write", path.display()))?;
        Ok(value)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Writes `value` as pretty RON (and a newline) to `path` through `path.partial`.
pub fn write_ron<T: Serialize>(value: &T, path: &Path) -> Result<()> {
    let text = ron::ser::to_string_pretty(value, ron::ser::PrettyConfig::default()).map_err(anyhow::Error::from)?;
    write(path, (text + "\n").as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_failed_fill_leaves_no_partial_file_and_a_good_one_the_file() {
        let dir = tempfile::tempdir().expect("temp");
        let path = dir.path().join("out.csv");
        let err = write_with::<()>(&path, |w| {
            w.write_all(b"half")?;
            Err(anyhow::anyhow!("row 3: bad").into())
        })
        .unwrap_err();
        assert_eq!(err.to_string(), "row 3: bad");
        assert_eq!(std::fs::read_dir(dir.path()).expect("dir").count(), 0);
        write(&path, b"whole").expect("written");
        assert_eq!(std::fs::read(&path).expect("read"), b"whole");
        assert_eq!(std::fs::read_dir(dir.path()).expect("dir").count(), 1);
    }
}
