//! The storage budget: the most bytes of raw frames the store may hold.
//! Over it, the oldest raw frames are deleted, but only frames of
//! occurrences whose processed products exist (listed in their session's
//! `processed/products.ron`, [`ProcessedProducts`]); each deletion is
//! journaled as a `pruned` line and logged in one line.
//!
//! What counts: the journaled sizes of the frame files still on disk, in
//! every day session of the store, plus each journal's length. Snapshots,
//! the heartbeat and processed products are not counted (they are small
//! next to the frames, and products are what the budget makes room to
//! keep).
//!
//! When nothing is deletable (no processed occurrence has frames left) and
//! the budget is still exceeded, a warning is logged and capture goes on:
//! the budget is a target, not a quota. If the disk then fills, the store
//! stops the run cleanly ([`crate::store::StoreError::DiskFull`]) with the
//! journal valid, and the same command resumes once there is room.

use chrono::{DateTime, NaiveDate, Utc};

use crate::store::{JOURNAL_FILE, JournalEntry, ProcessedProducts, SessionStore, Storage};

/// The byte budget.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StorageBudget {
    /// The most bytes of frames (and journals) to keep.
    pub max_bytes: u64,
}

/// Parse a size: a number of bytes with an optional unit, `kB`, `MB`,
/// `GB`, `TB` (powers of 1000) or `KiB`, `MiB`, `GiB`, `TiB` (powers of
/// 1024), e.g. `2GB`, `500 MiB`, `1.5GB`, `123456`.
pub fn parse_bytes(text: &str) -> Result<u64, String> {
    let s = text.trim();
    let split = s.find(|c: char| !(c.is_ascii_digit() || c == '.')).unwrap_or(s.len());
    let (number, unit) = s.split_at(split);
    let bad = || format!("found {text:?}; expected a size such as 2GB, 500MB, 1.5GiB or 123456 (bytes)");
    let value: f64 = number.parse().map_err(|_| bad())?;
    let factor: f64 = match unit.trim().to_ascii_lowercase().as_str() {
        "" | "b" => 1.0,
        "kb" | "k" => 1e3,
        "mb" | "m" => 1e6,
        "gb" | "g" => 1e9,
        "tb" | "t" => 1e12,
        "kib" => 1024.0,
        "mib" => 1024.0 * 1024.0,
        "gib" => 1024.0 * 1024.0 * 1024.0,
        "tib" => 1024.0 * 1024.0 * 1024.0 * 1024.0,
        _ => return Err(bad()),
    };
    let bytes = value * factor;
    if !bytes.is_finite() || !(1.0..1.8e19).contains(&bytes) {
        return Err(format!("{} (at least 1 byte)", bad()));
    }
    Ok(bytes.round() as u64)
}

/// The bytes a session holds, as the budget counts them.
pub fn session_bytes<S: Storage>(store: &SessionStore<S>) -> u64 {
    let frames: u64 = store
        .entries()
        .iter()
        .filter_map(JournalEntry::frame)
        .filter(|f| !store.pruned(&f.key))
        .map(|f| f.bytes)
        .sum();
    let journal = std::fs::metadata(store.dir().join(JOURNAL_FILE)).map_or(0, |m| m.len());
    frames + journal
}

/// A frame the budget may delete.
#[derive(Debug, Clone, PartialEq)]
pub struct Deletable {
    /// The day session holding it.
    pub day: NaiveDate,
    /// Its shot key.
    pub key: String,
    /// When it was taken.
    pub time: DateTime<Utc>,
    /// Its size.
    pub bytes: u64,
}

/// The occurrence of a shot key (`{occurrence}/s…`).
pub fn occurrence_of(key: &str) -> &str {
    key.split('/').next().unwrap_or(key)
}

/// The frames of `store` (the session of `day`) still on disk whose
/// occurrence is listed in `products`.
pub fn deletable<S: Storage>(day: NaiveDate, store: &SessionStore<S>, products: &ProcessedProducts) -> Vec<Deletable> {
    store
        .entries()
        .iter()
        .filter_map(JournalEntry::frame)
        .filter(|f| !store.pruned(&f.key) && products.contains(occurrence_of(&f.key)))
        .map(|f| Deletable {
            day,
            key: f.key.clone(),
            time: f.meta.time,
            bytes: f.bytes,
        })
        .collect()
}

/// The oldest of `candidates` whose sizes add up to at least `excess`
/// bytes (all of them if they do not), oldest first.
pub fn oldest_first(mut candidates: Vec<Deletable>, excess: u64) -> Vec<Deletable> {
    candidates.sort_by(|a, b| a.time.cmp(&b.time).then_with(|| a.key.cmp(&b.key)));
    let mut freed = 0;
    let mut chosen = Vec::new();
    for c in candidates {
        if freed >= excess {
            break;
        }
        freed += c.bytes;
        chosen.push(c);
    }
    chosen
}

#[cfg(test)]
mod tests {
    use super::*;
    use chrono::TimeZone;

    #[test]
    fn sizes_parse_with_units_and_bad_ones_are_named() {
        assert_eq!(parse_bytes("2GB"), Ok(2_000_000_000));
        assert_eq!(parse_bytes("500 MiB"), Ok(500 * 1024 * 1024));
        assert_eq!(parse_bytes("1.5kB"), Ok(1500));
        assert_eq!(parse_bytes("123456"), Ok(123_456));
        for bad in ["", "GB", "2XB", "-1GB", "0", "1e30GB"] {
            let e = parse_bytes(bad).unwrap_err();
            assert!(e.contains("expected a size"), "{bad}: {e}");
        }
    }

    #[test]
    fn the_oldest_frames_go_first_until_the_excess_is_freed() {
        let day = NaiveDate::from_ymd_opt(2026, 6, 21).unwrap();
        let c = |m: u32, bytes: u64| Deletable {
            day,
            key: format!("sky@2026-06-21#{m}/s1/t0/f0"),
            time: Utc.with_ymd_and_hms(2026, 6, 21, 14, m, 0).unwrap(),
            bytes,
        };
        let chosen = oldest_first(vec![c(30, 100), c(10, 100), c(20, 100)], 150);
        let minutes: Vec<_> = chosen.iter().map(|d| d.key.clone()).collect();
        assert_eq!(minutes, vec![c(10, 0).key, c(20, 0).key]);
        assert!(oldest_first(vec![c(10, 100)], 0).is_empty());
        assert_eq!(oldest_first(vec![c(10, 100)], 1000).len(), 1);
        assert_eq!(occurrence_of("sky@2026-06-21#3/s1/t0/f0"), "sky@2026-06-21#3");
    }
}
