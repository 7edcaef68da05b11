//! Day rollover: one session directory per plan day under the store,
//! `STORE/YYYY-MM-DD/`.
//!
//! The day is the scheduler's *plan day*, the date in an occurrence's key
//! (`sky@2026-06-21#12`): the site's mean solar day, the 24 hours centred
//! on local mean noon (see [`crate::schedule::sun_track`]). So a day's
//! scans from sunrise to sunset share one directory wherever the site is;
//! at Berkeley (122° W) a UTC-dated directory would cut every afternoon
//! in two at 17:00 local time.

use std::path::{Path, PathBuf};

use chrono::NaiveDate;

use crate::schedule::Occurrence;
use crate::store::{FsStorage, JOURNAL_FILE, ResumeReport, SessionStore, Snapshot, StoreError};

/// The plan day of an occurrence: the date in its key
/// `{session}@{YYYY-MM-DD}` or `{session}@{YYYY-MM-DD}#{n}`.
pub fn plan_day(occurrence: &Occurrence) -> Option<NaiveDate> {
    let (_, rest) = occurrence.key.rsplit_once('@')?;
    let date = rest.split('#').next()?;
    NaiveDate::parse_from_str(date, "%Y-%m-%d").ok()
}

/// The session directory of `day` under `store`.
pub fn day_dir(store: &Path, day: NaiveDate) -> PathBuf {
    store.join(day.format("%Y-%m-%d").to_string())
}

/// The day sessions already under `store`, oldest first: directories named
/// `YYYY-MM-DD` that hold a journal.
pub fn existing_days(store: &Path) -> std::io::Result<Vec<NaiveDate>> {
    let mut days = Vec::new();
    let entries = match std::fs::read_dir(store) {
        Ok(e) => e,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(days),
        Err(e) => return Err(e),
    };
    for entry in entries {
        let entry = entry?;
        let Some(name) = entry.file_name().to_str().map(str::to_owned) else {
            continue;
        };
        if let Ok(day) = NaiveDate::parse_from_str(&name, "%Y-%m-%d")
            && entry.path().join(JOURNAL_FILE).is_file()
        {
            days.push(day);
        }
    }
    days.sort();
    Ok(days)
}

/// How a day's session was opened.
#[derive(Debug)]
pub enum Opened {
    /// A new session directory.
    Created,
    /// An existing one, resumed (repairs listed).
    Resumed(ResumeReport),
}

/// Open the session of `day` under `store`: resume it if it has a journal
/// (its snapshot must be `snapshot`'s plan and station), else create it.
pub fn open_day(
    store: &Path,
    day: NaiveDate,
    snapshot: &Snapshot,
) -> Result<(SessionStore<FsStorage>, Opened), DayError> {
    let dir = day_dir(store, day);
    if dir.join(JOURNAL_FILE).is_file() {
        let (session, report) = SessionStore::resume(&dir).map_err(|source| DayError::Store {
            dir: dir.clone(),
            source,
        })?;
        if session.snapshot().plan_ron != snapshot.plan_ron || session.snapshot().station_ron != snapshot.station_ron {
            return Err(DayError::OtherPlan { dir });
        }
        Ok((session, Opened::Resumed(report)))
    } else {
        let session = SessionStore::create(&dir, snapshot.clone()).map_err(|source| DayError::Store { dir, source })?;
        Ok((session, Opened::Created))
    }
}

/// Why a day's session could not be opened.
#[derive(Debug, thiserror::Error)]
pub enum DayError {
    /// The store refused (e.g. a non-empty directory without a journal).
    #[error("the day session {}: {source}", dir.display())]
    Store {
        /// The day's directory.
        dir: PathBuf,
        /// The store's error.
        #[source]
        source: StoreError,
    },
    /// The directory holds a session of another plan or station.
    #[error(
        "the day session {} began with another plan or station; use another --store, or the plan and station it began with (its plan.ron and station.ron)",
        dir.display()
    )]
    OtherPlan {
        /// The day's directory.
        dir: PathBuf,
    },
}

#[cfg(test)]
mod tests {
    use super::*;
    use chrono::{TimeZone, Utc};

    fn occurrence(key: &str) -> Occurrence {
        Occurrence {
            key: key.to_owned(),
            session: 0,
            name: "sky".to_owned(),
            held_out: false,
            start: Utc.with_ymd_and_hms(2026, 6, 22, 1, 0, 0).unwrap(),
            sun: (280.0, 20.0),
            shots: Vec::new(),
            estimated_duration: std::time::Duration::ZERO,
        }
    }

    #[test]
    fn the_day_is_the_plan_day_of_the_key_not_the_utc_date() {
        // Starts on 2026-06-22 UTC but belongs to the plan day 2026-06-21.
        let d = plan_day(&occurrence("sky@2026-06-21#80")).unwrap();
        assert_eq!(d, NaiveDate::from_ymd_opt(2026, 6, 21).unwrap());
        assert_eq!(
            plan_day(&occurrence("noon@2026-08-28")),
            NaiveDate::from_ymd_opt(2026, 8, 28)
        );
        assert_eq!(plan_day(&occurrence("no-date")), None);
        assert_eq!(day_dir(Path::new("/s"), d), PathBuf::from("/s/2026-06-21"));
    }
}
