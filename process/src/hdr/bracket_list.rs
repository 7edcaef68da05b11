//! Bracket list files and exposure-time parsing, for the command line.
//!
//! A bracket list has one image per line: `PATH TIME`, where `TIME` is in
//! seconds, as a decimal (`0.0333`) or a fraction (`1/30`). Blank lines and
//! lines starting with `#` are ignored; a relative `PATH` is relative to the
//! list file's folder.

use std::path::{Path, PathBuf};

use super::HdrError;
use super::bracket::Bracket;
use super::image_file::read_code_image;

/// Parses an exposure time in seconds: `0.5`, `2`, `1/30`.
pub fn parse_time_s(text: &str) -> Option<f64> {
    let t = text.trim();
    let v = match t.split_once('/') {
        Some((n, d)) => n.trim().parse::<f64>().ok()? / d.trim().parse::<f64>().ok()?,
        None => t.parse().ok()?,
    };
    (v.is_finite() && v > 0.0).then_some(v)
}

/// Reads a bracket list file into (image paths, times in seconds).
pub fn read_bracket_list(path: &Path) -> Result<(Vec<PathBuf>, Vec<f64>), HdrError> {
    let text = std::fs::read_to_string(path).map_err(|cause| HdrError::Io {
        path: path.to_path_buf(),
        cause,
    })?;
    let base = path.parent().unwrap_or(Path::new(""));
    let mut paths = Vec::new();
    let mut times = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let perr = |what: String| HdrError::Parse {
            path: path.to_path_buf(),
            line: i + 1,
            what,
        };
        let (p, t) = line
            .rsplit_once(char::is_whitespace)
            .ok_or_else(|| perr(format!("'{line}': expected 'IMAGE TIME_S' (e.g. 'a.png 1/30')")))?;
        let time =
            parse_time_s(t).ok_or_else(|| perr(format!("time '{t}': expected seconds > 0, e.g. 0.033 or 1/30")))?;
        let p = Path::new(p.trim());
        paths.push(if p.is_absolute() { p.to_path_buf() } else { base.join(p) });
        times.push(time);
    }
    if paths.is_empty() {
        return Err(HdrError::Parse {
            path: path.to_path_buf(),
            line: 1,
            what: "no images listed: expected 'IMAGE TIME_S' lines".into(),
        });
    }
    Ok((paths, times))
}

/// Reads and validates a bracket from image files and their times.
pub fn load_bracket(paths: &[PathBuf], times_s: &[f64]) -> Result<Bracket, HdrError> {
    if paths.len() != times_s.len() {
        return Err(HdrError::TimeCountMismatch {
            images: paths.len(),
            times: times_s.len(),
        });
    }
    let images = paths
        .iter()
        .map(|p| read_code_image(p))
        .collect::<Result<Vec<_>, _>>()?;
    Bracket::new(images, times_s.to_vec())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn times_and_list_parse() {
        assert_eq!(parse_time_s("1/4"), Some(0.25));
        assert_eq!(parse_time_s(" 2 "), Some(2.0));
        assert_eq!(parse_time_s("0"), None);
        assert_eq!(parse_time_s("1/0"), None);
        let dir = tempfile::tempdir().unwrap();
        let list = dir.path().join("b.txt");
        std::fs::write(&list, "# bracket\na.png 1/30\n\n/abs/b.png 0.5\n").unwrap();
        let (p, t) = read_bracket_list(&list).unwrap();
        assert_eq!(p, vec![dir.path().join("a.png"), PathBuf::from("/abs/b.png")]);
        assert!((t[0] - 1.0 / 30.0).abs() < 1e-15 && t[1] == 0.5);
        std::fs::write(&list, "a.png fast\n").unwrap();
        let e = read_bracket_list(&list).unwrap_err().to_string();
        assert!(e.contains("b.txt:1") && e.contains("time 'fast'"), "{e}");
    }
}
