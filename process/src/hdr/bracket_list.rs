//! Bracket list files, exposure-time parsing, and loading a bracket from
//! files with its times from the command line, a list, or EXIF.
//!
//! A bracket list is either
//! - plain text, one image per line: `PATH TIME`, where `TIME` is in
//!   seconds, as a decimal (`0.0333`) or a fraction (`1/30`); or
//! - CSV with a header naming the columns: `file` (or `image`, `path`),
//!   `time` (or `exposure_time`, `ExposureTime`, `exposure_time_s`, `t`; any case), and optionally
//!   `iso` and `f_number` (or `fnumber`, `aperture`, `n`). With ISO and
//!   f-number, each frame's time becomes the effective time
//!   `t · (S/S₀) · (N₀/N)²` of [`super::exposure_metadata`].
//!
//! Blank lines and lines starting with `#` are ignored; a relative `PATH` is
//! relative to the list file's folder.

use std::path::{Path, PathBuf};

use super::HdrError;
use super::bracket::Bracket;
use super::bracket_files::BracketFiles;
use super::exposure_metadata::{ExposureMetadata, effective_times};
use super::image_file::read_frame;

/// Parses an exposure time in seconds: `0.5`, `2`, `1/30`.
pub fn parse_time_s(text: &str) -> Option<f64> {
    let t = text.trim();
    let v = match t.split_once('/') {
        Some((n, d)) => n.trim().parse::<f64>().ok()? / d.trim().parse::<f64>().ok()?,
        None => t.parse().ok()?,
    };
    (v.is_finite() && v > 0.0).then_some(v)
}

/// Reads a bracket list file (plain or CSV, module doc) into (image paths,
/// times in seconds).
pub fn read_bracket_list(path: &Path) -> Result<(Vec<PathBuf>, Vec<f64>), HdrError> {
    let text = std::fs::read_to_string(path).map_err(|cause| HdrError::Io {
        path: path.to_path_buf(),
        cause,
    })?;
    let base = path.parent().unwrap_or(Path::new(""));
    let lines: Vec<(usize, &str)> = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'))
        .collect();
    let perr = |line: usize, what: String| HdrError::Parse {
        path: path.to_path_buf(),
        line,
        what,
    };
    let resolve = |p: &str| {
        let p = Path::new(p.trim());
        if p.is_absolute() { p.to_path_buf() } else { base.join(p) }
    };
    let Some(&(first_line, first)) = lines.first() else {
        return Err(perr(
            1,
            "no images listed: expected 'IMAGE TIME_S' lines or a CSV with a header".into(),
        ));
    };
    let (paths, times) = if let Some(columns) = csv_header(first) {
        let columns = columns.map_err(|what| perr(first_line, what))?;
        let mut paths = Vec::new();
        let mut frames = Vec::new();
        for &(n, line) in &lines[1..] {
            let cells: Vec<&str> = line.split(',').map(str::trim).collect();
            let cell = |i: usize, name: &str| {
                cells
                    .get(i)
                    .copied()
                    .filter(|c| !c.is_empty())
                    .ok_or_else(|| perr(n, format!("no {name} value: expected {} columns", columns.count)))
            };
            let number = |i: Option<usize>, name: &str| -> Result<Option<f64>, HdrError> {
                let Some(i) = i else { return Ok(None) };
                let v = cell(i, name)?;
                parse_time_s(v)
                    .map(Some)
                    .ok_or_else(|| perr(n, format!("{name} '{v}': expected a number > 0")))
            };
            paths.push(resolve(cell(columns.file, "file")?));
            let t = number(Some(columns.time), "time")?;
            let meta = ExposureMetadata {
                exposure_time_s: t,
                f_number: number(columns.f_number, "f_number")?,
                iso: number(columns.iso, "iso")?,
                ..Default::default()
            };
            frames.push((paths[paths.len() - 1].clone(), meta));
        }
        let times = effective_times(&frames)?;
        (paths, times)
    } else {
        let mut paths = Vec::new();
        let mut times = Vec::new();
        for &(n, line) in &lines {
            let (p, t) = line
                .rsplit_once(char::is_whitespace)
                .ok_or_else(|| perr(n, format!("'{line}': expected 'IMAGE TIME_S' (e.g. 'a.png 1/30')")))?;
            let time = parse_time_s(t)
                .ok_or_else(|| perr(n, format!("time '{t}': expected seconds > 0, e.g. 0.033 or 1/30")))?;
            paths.push(resolve(p));
            times.push(time);
        }
        (paths, times)
    };
    if paths.is_empty() {
        return Err(perr(first_line, "no images listed under the header".into()));
    }
    Ok((paths, times))
}

/// Column positions of a CSV bracket list.
struct Columns {
    file: usize,
    time: usize,
    iso: Option<usize>,
    f_number: Option<usize>,
    count: usize,
}

/// `None` when `line` is not a CSV header (no comma); otherwise the columns,
/// or what is wrong with the header.
fn csv_header(line: &str) -> Option<Result<Columns, String>> {
    if !line.contains(',') {
        return None;
    }
    let names: Vec<String> = line.split(',').map(|c| c.trim().to_ascii_lowercase()).collect();
    let find = |aliases: &[&str]| names.iter().position(|n| aliases.contains(&n.as_str()));
    let file = find(&["file", "image", "path"]);
    let time = find(&["time", "exposure_time", "exposuretime", "exposure_time_s", "t"]);
    Some(match (file, time) {
        (Some(file), Some(time)) => Ok(Columns {
            file,
            time,
            iso: find(&["iso"]),
            f_number: find(&["f_number", "fnumber", "aperture", "n"]),
            count: names.len(),
        }),
        _ => Err(format!(
            "header '{line}': expected columns 'file' and 'time' (optionally 'iso', 'f_number')"
        )),
    })
}

/// Where a frame's exposure time came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TimeSource {
    /// Given on the command line or in a list file.
    Given,
    /// The file's EXIF (effective time from exposure time, ISO and f-number).
    Exif,
}

/// One frame as read: its file, EXIF, and the (effective) time used.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameRecord {
    /// The file.
    pub path: PathBuf,
    /// What its EXIF said.
    pub metadata: ExposureMetadata,
    /// The effective exposure time in seconds.
    pub time_s: f64,
    /// Where the time came from.
    pub source: TimeSource,
}

/// Reads image files (turned upright by their EXIF orientation) into a
/// validated bracket held in memory. `times_s`: the times given by the
/// user, one per file; `None` reads them from each file's EXIF
/// ([`effective_times`]). The records come shortest exposure first, as
/// [`BracketFiles`] sorts them (which reads a bracket one frame at a time
/// instead).
pub fn load_bracket_files(paths: &[PathBuf], times_s: Option<&[f64]>) -> Result<(Bracket, Vec<FrameRecord>), HdrError> {
    let files = BracketFiles::open(paths, times_s)?;
    let images = files
        .records()
        .iter()
        .map(|r| read_frame(&r.path).map(|(img, _)| img))
        .collect::<Result<Vec<_>, _>>()?;
    Ok((Bracket::new(images, files.times_s())?, files.records().to_vec()))
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

    #[test]
    fn csv_list_with_header_iso_and_aperture() {
        let dir = tempfile::tempdir().unwrap();
        let list = dir.path().join("b.csv");
        std::fs::write(
            &list,
            "# from exiftool\nFile, ExposureTime, ISO, FNumber\na.jpg, 1/100, 100, 8\nb.jpg, 1/100, 400, 8\nc.jpg,1/100,100,4\n",
        )
        .unwrap();
        let (p, t) = read_bracket_list(&list).unwrap();
        assert_eq!(p[2], dir.path().join("c.jpg"));
        for (got, want) in t.iter().zip([0.01, 0.04, 0.04]) {
            assert!((got / want - 1.0).abs() < 1e-12, "{got} vs {want}");
        }
        std::fs::write(&list, "file,time\na.jpg,1/100\nb.jpg\n").unwrap();
        let e = read_bracket_list(&list).unwrap_err().to_string();
        assert!(e.contains("b.csv:3") && e.contains("no time value"), "{e}");
        std::fs::write(&list, "name,seconds\na.jpg,1\n").unwrap();
        let e = read_bracket_list(&list).unwrap_err().to_string();
        assert!(e.contains("b.csv:1") && e.contains("'file' and 'time'"), "{e}");
    }
}
