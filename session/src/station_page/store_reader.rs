//! What the live page shows, read from the files the station writes and
//! nothing else: `STORE/heartbeat.json`, each day's `journal.jsonl`, and
//! the day's `processed/` products (`sky-series.csv`, `extinction.csv`,
//! `keogram.png`). The station is never asked anything.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::SystemTime;

use campanile_capture::store::{FrameEntry, JOURNAL_FILE, JournalEntry, PROCESSED_DIR, parse_journal};
use campanile_capture::unattended::day_rollover::{day_dir, existing_days};
use campanile_capture::unattended::{HEARTBEAT_FILE, Heartbeat};
use chrono::{DateTime, NaiveDate, Utc};
use serde::Serialize;

/// The day's sky series, as written by the station's processing.
pub const SERIES_FILE: &str = "sky-series.csv";
/// The day's extinction fit per channel.
pub const EXTINCTION_FILE: &str = "extinction.csv";
/// The day's keogram, rewritten after each processed scan.
pub const KEOGRAM_FILE: &str = "keogram.png";
/// The most outages and scans with missed shots listed per day (the
/// newest); the totals are always given.
pub const MAX_LISTED: usize = 50;

/// A plan day named in a request: exactly `YYYY-MM-DD`. Anything else
/// (`..`, `%2e%2e`, an absolute path, a longer string) is refused, so a
/// request can only name a day directory directly under the store.
pub fn parse_day(text: &str) -> Option<NaiveDate> {
    let ok_shape = text.len() == 10
        && text.bytes().enumerate().all(|(i, b)| {
            if i == 4 || i == 7 {
                b == b'-'
            } else {
                b.is_ascii_digit()
            }
        });
    ok_shape
        .then(|| NaiveDate::parse_from_str(text, "%Y-%m-%d").ok())
        .flatten()
}

/// The page's whole state: the heartbeat and the current day.
#[derive(Debug, Clone, Serialize)]
pub struct StationSnapshot {
    /// The heartbeat, when it could be read.
    pub heartbeat: Option<Heartbeat>,
    /// Why it could not (no station has run here yet, or a bad file).
    pub heartbeat_error: Option<String>,
    /// Seconds since the heartbeat was written, on this computer's clock.
    pub heartbeat_age_s: Option<f64>,
    /// Every day session in the store, oldest first.
    pub days: Vec<NaiveDate>,
    /// The day shown: the heartbeat's, else the newest in the store.
    pub day: Option<DayView>,
}

/// One day's session, as the page shows it.
#[derive(Debug, Clone, Serialize)]
pub struct DayView {
    /// The plan day.
    pub date: NaiveDate,
    /// Frames journaled (done or late).
    pub frames: usize,
    /// Scans (occurrences) with at least one frame.
    pub scans: usize,
    /// The newest sky frame (no filter, or a slot without neutral
    /// density) whose file is still on disk.
    pub latest_sky_frame: Option<FrameView>,
    /// Device outages (the newest [`MAX_LISTED`]).
    pub outages: Vec<OutageView>,
    /// All outages of the day.
    pub outages_total: usize,
    /// Scans with shots not taken (the newest [`MAX_LISTED`]).
    pub missed: Vec<MissedView>,
    /// All scans of the day with missed shots.
    pub missed_scans_total: usize,
    /// All missed shots of the day.
    pub missed_shots: usize,
    /// The processed sky series, if the day has one.
    pub series: Option<SeriesColumns>,
    /// The extinction fit per channel, if written.
    pub extinction: Vec<BTreeMap<String, String>>,
    /// Whether `processed/keogram.png` exists, and its version (its
    /// modification time in ms), so the page reloads the image only when
    /// it changed.
    pub keogram_version: Option<u128>,
    /// Problems reading the day's files (a torn or bad file is reported,
    /// not fatal: the station may be writing it).
    pub problems: Vec<String>,
}

/// A journaled frame.
#[derive(Debug, Clone, Serialize)]
pub struct FrameView {
    /// Its shot key.
    pub key: String,
    /// When it was taken (station time).
    pub time_utc: DateTime<Utc>,
    /// Its exposure, seconds.
    pub exposure_s: f64,
    /// Width × height, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
    /// The frame's file, relative to the day's directory (`frames/…`).
    #[serde(skip)]
    pub file: String,
    #[serde(skip)]
    pub(crate) entry: FrameEntry,
}

/// A device outage from the journal.
#[derive(Debug, Clone, Serialize)]
pub struct OutageView {
    /// The device.
    pub device: String,
    /// Its first failed call.
    pub start: DateTime<Utc>,
    /// Its return (or the stop, when `open`).
    pub end: DateTime<Utc>,
    /// Still down when the run stopped.
    pub open: bool,
}

/// A scan's missed shots from the journal.
#[derive(Debug, Clone, Serialize)]
pub struct MissedView {
    /// The scan (occurrence) whose shots were missed.
    pub occurrence: String,
    /// How many of its shots.
    pub shots: usize,
    /// When the first was given up.
    pub time: DateTime<Utc>,
    /// Why the first was.
    pub reason: String,
}

/// The sky series as columns: numbers (empty cells as null) and text.
#[derive(Debug, Clone, Serialize)]
pub struct SeriesColumns {
    /// Rows (scans).
    pub rows: usize,
    /// Column names in file order.
    pub names: Vec<String>,
    /// The numeric columns (every non-empty cell a finite number).
    pub numbers: BTreeMap<String, Vec<Option<f64>>>,
    /// The other columns, as text.
    pub text: BTreeMap<String, Vec<String>>,
}

/// The store's files whose change changes the page: their sizes and
/// modification times. Cheap: a few `stat` calls per poll.
pub fn store_stamp(store: &Path) -> Vec<(PathBuf, Option<(u64, SystemTime)>)> {
    let stat = |p: PathBuf| {
        let m = std::fs::metadata(&p)
            .ok()
            .and_then(|m| Some((m.len(), m.modified().ok()?)));
        (p, m)
    };
    let mut out = vec![stat(store.join(HEARTBEAT_FILE)), stat(store.to_path_buf())];
    if let Some(day) = current_day(store, Heartbeat::read(store).ok().as_ref()) {
        let dir = day_dir(store, day);
        let processed = dir.join(PROCESSED_DIR);
        out.push(stat(dir.join(JOURNAL_FILE)));
        for f in [SERIES_FILE, EXTINCTION_FILE, KEOGRAM_FILE] {
            out.push(stat(processed.join(f)));
        }
    }
    out
}

/// The day the page shows: the heartbeat's, else the newest in the store.
fn current_day(store: &Path, beat: Option<&Heartbeat>) -> Option<NaiveDate> {
    beat.and_then(|b| b.day)
        .or_else(|| existing_days(store).ok().and_then(|d| d.last().copied()))
}

/// Reads the heartbeat and the current day.
pub fn snapshot(store: &Path) -> StationSnapshot {
    let (heartbeat, heartbeat_error) = match Heartbeat::read(store) {
        Ok(b) => (Some(b), None),
        Err(e) => (None, Some(e)),
    };
    let days = existing_days(store).unwrap_or_default();
    let day = current_day(store, heartbeat.as_ref()).map(|d| day_view(store, d));
    StationSnapshot {
        heartbeat_age_s: heartbeat.as_ref().map(|b| b.age_s(Utc::now())),
        heartbeat,
        heartbeat_error,
        days,
        day,
    }
}

/// One day's view: its journal and processed products.
pub fn day_view(store: &Path, date: NaiveDate) -> DayView {
    let dir = day_dir(store, date);
    let mut problems = Vec::new();
    let journal_path = dir.join(JOURNAL_FILE);
    let entries = match std::fs::read(&journal_path) {
        Ok(bytes) => match parse_journal(&journal_path, &bytes) {
            Ok(p) => p.entries,
            Err(e) => {
                problems.push(e.to_string());
                Vec::new()
            }
        },
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Vec::new(),
        Err(e) => {
            problems.push(format!("{}: {e}", journal_path.display()));
            Vec::new()
        }
    };
    let pruned: std::collections::HashSet<&str> = entries
        .iter()
        .filter_map(|e| match e {
            JournalEntry::Pruned(p) => Some(p.keys.iter().map(String::as_str)),
            _ => None,
        })
        .flatten()
        .collect();
    let frames: Vec<&FrameEntry> = entries.iter().filter_map(JournalEntry::frame).collect();
    let scans: std::collections::HashSet<&str> = frames
        .iter()
        .map(|f| f.key.split('/').next().unwrap_or_default())
        .collect();
    let clear = clear_filters(&dir);
    let latest_sky_frame = frames
        .iter()
        .rev()
        .find(|f| {
            f.meta.filter.as_ref().is_none_or(|name| clear.contains(name))
                && !pruned.contains(f.key.as_str())
                && dir.join(&f.file).is_file()
                && matches!(f.meta.kind, campanile_capture::store::ShotKind::Data)
        })
        .map(|f| FrameView {
            key: f.key.clone(),
            time_utc: f.meta.time,
            exposure_s: f.meta.exposure_actual_s,
            width: f.width,
            height: f.height,
            file: f.file.clone(),
            entry: (*f).clone(),
        });
    let outages: Vec<OutageView> = entries
        .iter()
        .filter_map(|e| match e {
            JournalEntry::Outage(o) => Some(OutageView {
                device: o.device.clone(),
                start: o.start,
                end: o.end,
                open: o.open,
            }),
            _ => None,
        })
        .collect();
    let mut missed: Vec<MissedView> = Vec::new();
    let mut missed_shots = 0;
    for e in &entries {
        if let JournalEntry::Missed(m) = e {
            missed_shots += 1;
            let occurrence = m.key.split('/').next().unwrap_or_default();
            match missed.iter_mut().find(|v| v.occurrence == occurrence) {
                Some(v) => v.shots += 1,
                None => missed.push(MissedView {
                    occurrence: occurrence.to_owned(),
                    shots: 1,
                    time: m.time,
                    reason: m.reason.clone(),
                }),
            }
        }
    }
    let newest = |n: usize| n.saturating_sub(MAX_LISTED);
    let processed = dir.join(PROCESSED_DIR);
    let series = match read_table(&processed.join(SERIES_FILE)) {
        Ok(Some(t)) => Some(columns(t)),
        Ok(None) => None,
        Err(e) => {
            problems.push(e);
            None
        }
    };
    let extinction = match read_table(&processed.join(EXTINCTION_FILE)) {
        Ok(Some((names, rows))) => rows
            .into_iter()
            .map(|r| names.iter().cloned().zip(r).collect())
            .collect(),
        Ok(None) => Vec::new(),
        Err(e) => {
            problems.push(e);
            Vec::new()
        }
    };
    let keogram_version = std::fs::metadata(processed.join(KEOGRAM_FILE))
        .and_then(|m| m.modified())
        .ok()
        .and_then(|t| t.duration_since(SystemTime::UNIX_EPOCH).ok())
        .map(|d| d.as_millis());
    DayView {
        date,
        frames: frames.len(),
        scans: scans.len(),
        latest_sky_frame,
        outages_total: outages.len(),
        outages: outages[newest(outages.len())..].to_vec(),
        missed_shots,
        missed_scans_total: missed.len(),
        missed: missed[newest(missed.len())..].to_vec(),
        series,
        extinction,
        keogram_version,
        problems,
    }
}

/// The filter slots without neutral density in the day's station
/// snapshot (`station.ron`): a frame through one of them, or through no
/// filter, is a sky frame (sun shots go through ND filters). Empty when
/// the snapshot cannot be read.
fn clear_filters(dir: &Path) -> std::collections::HashSet<String> {
    campanile_config::load_station(&dir.join("station.ron"))
        .ok()
        .and_then(|loaded| loaded.value.filter_wheel)
        .map(|wheel| {
            wheel
                .slots
                .into_iter()
                .filter(|s| s.optical_density == (0.0, 0.0, 0.0))
                .map(|s| s.name)
                .collect()
        })
        .unwrap_or_default()
}

/// A CSV with `#` comment lines above its header: the header and rows;
/// `None` when the file does not exist.
type Table = (Vec<String>, Vec<Vec<String>>);

fn read_table(path: &Path) -> Result<Option<Table>, String> {
    let bytes = match std::fs::read(path) {
        Ok(b) => b,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(format!("{}: {e}", path.display())),
    };
    let mut reader = csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .flexible(false)
        .from_reader(bytes.as_slice());
    let bad = |e: csv::Error| format!("{}: {e}", path.display());
    let names: Vec<String> = reader.headers().map_err(bad)?.iter().map(str::to_owned).collect();
    let rows = reader
        .records()
        .map(|r| r.map(|r| r.iter().map(str::to_owned).collect()))
        .collect::<Result<Vec<Vec<String>>, _>>()
        .map_err(bad)?;
    Ok(Some((names, rows)))
}

/// The table as columns: a column whose every non-empty cell is a finite
/// number is numeric, any other is text.
fn columns((names, rows): Table) -> SeriesColumns {
    let mut numbers = BTreeMap::new();
    let mut text = BTreeMap::new();
    for (i, name) in names.iter().enumerate() {
        let cells: Vec<&str> = rows.iter().map(|r| r.get(i).map_or("", String::as_str)).collect();
        let parsed: Option<Vec<Option<f64>>> = cells
            .iter()
            .map(|c| match c.trim() {
                "" => Some(None),
                t => t.parse::<f64>().ok().filter(|v| v.is_finite()).map(Some),
            })
            .collect();
        match parsed {
            Some(v) if v.iter().any(Option::is_some) => {
                numbers.insert(name.clone(), v);
            }
            _ => {
                text.insert(name.clone(), cells.iter().map(|c| (*c).to_owned()).collect());
            }
        }
    }
    SeriesColumns {
        rows: rows.len(),
        names,
        numbers,
        text,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_a_plain_date_names_a_day() {
        assert_eq!(parse_day("2026-06-21"), NaiveDate::from_ymd_opt(2026, 6, 21));
        for bad in [
            "..",
            "../2026-06-21",
            "%2e%2e",
            "/etc/passwd",
            "2026-06-21/..",
            "2026-6-21",
            "2026-02-30",
            "+2026-06-2",
            "２０２６-06-21",
            "",
        ] {
            assert_eq!(parse_day(bad), None, "{bad:?}");
        }
    }

    #[test]
    fn a_series_table_splits_into_number_and_text_columns() {
        let csv = "# a comment\n# more\noccurrence,sun_e_r_w_m2,cloud_cover,flags\n\
                   sky@2026-06-21#1,850.5,,clouds_near_sun\nsky@2026-06-21#2,,0.25,\n";
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.csv");
        std::fs::write(&path, csv).unwrap();
        let cols = columns(read_table(&path).unwrap().unwrap());
        assert_eq!(cols.rows, 2);
        assert_eq!(cols.numbers["sun_e_r_w_m2"], [Some(850.5), None]);
        assert_eq!(cols.numbers["cloud_cover"], [None, Some(0.25)]);
        assert_eq!(cols.text["flags"], ["clouds_near_sun", ""]);
        assert_eq!(cols.text["occurrence"].len(), 2);
        assert!(read_table(&dir.path().join("none.csv")).unwrap().is_none());
        // A torn row (the station rewrites the file atomically, but a
        // copy may be partial) is a problem reported, not a crash.
        std::fs::write(&path, "a,b\n1,2\n3\n").unwrap();
        assert!(read_table(&path).unwrap_err().contains("s.csv"));
    }
}
