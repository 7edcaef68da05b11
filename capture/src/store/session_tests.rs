//! Tests of the session store: round trips, crash and resume, repairs,
//! a full disk, and refused input.

use super::*;
use crate::device::{ExposureTime, Gain};
use crate::store::fault::{CrashingStorage, Operation, QuotaStorage};
use crate::store::frame_file_name;
use crate::store::{CalibrationRef, LightLevel, PoseDeg, Provenance, SessionReader, ShotKind, SourcePaths};
use chrono::TimeZone;
use std::collections::BTreeSet;

const W: usize = 12;
const H: usize = 8;

/// SplitMix64: a small seeded generator, so every test is repeatable.
struct SplitMix(u64);

impl SplitMix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in `lo..=hi`.
    fn range(&mut self, lo: u64, hi: u64) -> u64 {
        lo + self.next() % (hi - lo + 1)
    }
}

fn snapshot() -> Snapshot {
    Snapshot {
        plan_ron: "(sessions: [(name: \"morning\")])\n".into(),
        station_ron: "(camera: Sim, head: Sim)\n".into(),
        scene_ron: Some("(name: \"courtyard\")\n".into()),
        provenance: Provenance {
            campanile_version: "0.1.0".into(),
            created_utc: Utc.with_ymd_and_hms(2026, 8, 28, 5, 0, 0).unwrap(),
            calibration: vec![CalibrationRef {
                file: "response.csv".into(),
                checksum: "crc32c:0badf00d".into(),
            }],
            sources: Some(SourcePaths {
                plan: "/plans/day.ron".into(),
                station: "/stations/roof.ron".into(),
                scene: None,
            }),
        },
    }
}

fn key(i: usize) -> String {
    format!("morning@2026-08-28/s{}/t{}/f{}", i / 20, (i / 5) % 4, i % 5)
}

/// A frame of seeded codes; the first code is the largest one `bits` allows.
fn synth_frame(seed: u64, bits: u8) -> Frame {
    let mut rng = SplitMix(seed);
    let max = u16::MAX >> (16 - bits);
    let mut data: Vec<u16> = (0..W * H * 3)
        .map(|_| (rng.next() % (u64::from(max) + 1)) as u16)
        .collect();
    data[0] = max;
    data[1] = 0;
    Frame {
        width: W,
        height: H,
        bits,
        data,
        exposure_requested: ExposureTime::from_seconds(1.0 / 3.0).unwrap(),
        exposure_actual: ExposureTime::from_seconds(0.333_33).unwrap(),
        gain: Gain::from_db(6.1).unwrap(),
        sequence: seed + 1000,
        timestamp: Utc.with_ymd_and_hms(2026, 8, 28, 6, 0, 0).unwrap() + chrono::Duration::seconds(seed as i64 * 7),
        temperature_c: Some(31.7),
        file: None,
    }
}

/// Metadata with every field set, awkward floats included.
fn meta_for(i: usize, frame: &Frame) -> FrameMeta {
    let mut meta = FrameMeta::from_frame(
        frame,
        if i.is_multiple_of(10) {
            ShotKind::Metering
        } else {
            ShotKind::Data
        },
    );
    meta.pose_requested = Some(PoseDeg {
        pan_deg: 0.1 * i as f64,
        tilt_deg: -12.345_678_9,
    });
    meta.pose_reached = Some(PoseDeg {
        pan_deg: 0.1 * i as f64 + 1e-9,
        tilt_deg: -12.345_678_8,
    });
    meta.filter = i.is_multiple_of(3).then(|| "ND3".to_string());
    meta.lights = i.is_multiple_of(4).then(|| {
        vec![
            LightLevel { channel: 0, level: 1.0 },
            LightLevel {
                channel: 3,
                level: 1.0 / 7.0,
            },
        ]
    });
    meta.late_by_s = (i % 11 == 4).then_some(12.5);
    meta.focal_px = (i % 7 == 2).then_some(1_234.567_890_123);
    if meta.late_by_s.is_some() {
        meta.notes.push("late by 12.5 s: head stalled".into());
    }
    meta
}

/// Shot `i` of the synthetic plan is missed rather than taken.
fn is_missed(i: usize) -> bool {
    i % 13 == 7
}

/// Run the synthetic plan of `n` shots, skipping what the journal already
/// holds, as a controller would.
fn run_plan<S: Storage>(store: &mut SessionStore<S>, n: usize) -> Result<(), StoreError> {
    for i in 0..n {
        let k = key(i);
        if store.completed(&k) || store.missed(&k) {
            continue;
        }
        if is_missed(i) {
            let t = Utc.with_ymd_and_hms(2026, 8, 28, 7, 0, 0).unwrap() + chrono::Duration::seconds(i as i64);
            store.record_missed(&k, "sun behind cloud", t)?;
        } else {
            let frame = synth_frame(i as u64, 12);
            store.record_frame(&k, &meta_for(i, &frame), &frame)?;
        }
    }
    Ok(())
}

/// Every file under `dir`, relative path → bytes.
fn tree(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut out = Vec::new();
    for sub in ["", FRAMES_DIR] {
        let d = dir.join(sub);
        for e in std::fs::read_dir(&d).unwrap() {
            let e = e.unwrap();
            if e.file_type().unwrap().is_file() {
                let name = format!("{sub}/{}", e.file_name().to_string_lossy());
                out.push((name, std::fs::read(e.path()).unwrap()));
            }
        }
    }
    out.sort();
    out
}

fn tree_size(dir: &Path) -> u64 {
    tree(dir).iter().map(|(_, b)| b.len() as u64).sum()
}

fn journal_entries(dir: &Path) -> Vec<JournalEntry> {
    let path = dir.join(JOURNAL_FILE);
    let parsed = parse_journal(&path, &std::fs::read(&path).unwrap()).unwrap();
    assert_eq!(parsed.torn_len, 0);
    parsed.entries
}

#[test]
fn round_trip_keeps_codes_and_journal_fields_exactly() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("s");
    let mut store = SessionStore::create(&dir, snapshot()).unwrap();
    let mut written = Vec::new();
    for (i, bits) in [8u8, 12, 16].into_iter().enumerate() {
        let frame = synth_frame(100 + i as u64, bits);
        let meta = meta_for(i + 4, &frame); // i + 4 = 4: late, with lights.
        let entry = store.record_frame(&key(i), &meta, &frame).unwrap();
        let fe = entry.frame().unwrap().clone();
        assert_eq!(
            (fe.width, fe.height, fe.bits, fe.sequence),
            (W as u32, H as u32, bits, frame.sequence)
        );
        assert_eq!(&fe.meta, &meta);
        // Codes back exactly: unscaled, the largest code included.
        let image = store.read_frame(&fe).unwrap();
        assert_eq!(image.data, frame.data, "{bits}-bit codes");
        assert_eq!((image.width, image.height, image.bits), (W, H, bits));
        assert_eq!(image.data[0], u16::MAX >> (16 - bits));
        written.push(entry);
    }
    assert!(
        matches!(written[0], JournalEntry::Late(_)),
        "late_by_s set gives status late"
    );
    assert!(matches!(written[1], JournalEntry::Done(_)));
    // The journal file reads back to identical entries (floats bit-for-bit).
    assert_eq!(journal_entries(&dir), written);
    let text = std::fs::read_to_string(dir.join(JOURNAL_FILE)).unwrap();
    assert_eq!(text.lines().count(), 3);
    let statuses: Vec<_> = text.lines().map(|l| l.split(',').next().unwrap_or_default()).collect();
    assert_eq!(
        statuses,
        ["{\"status\":\"late\"", "{\"status\":\"done\"", "{\"status\":\"done\""],
        "{text}"
    );
    // A resume sees the same entries and snapshot, and nothing to repair;
    // the snapshot (with its source paths) reads back without opening the session.
    drop(store);
    assert_eq!(Snapshot::read_dir(&dir).unwrap(), snapshot());
    let (store, report) = SessionStore::resume(&dir).unwrap();
    assert!(report.is_clean(), "{report}");
    assert_eq!(report.frames, 3);
    assert_eq!(store.entries(), written.as_slice());
    assert_eq!(store.snapshot(), &snapshot());
    let verify = store.verify().unwrap();
    assert!(verify.is_ok());
    assert_eq!(verify.frames_checked, 3);
    assert!(store.completed(&key(2)) && !store.completed(&key(3)));
}

/// Where in the write sequence a crash struck, named for the report.
fn phase(op: Operation, path: &Path) -> String {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let what = if name == JOURNAL_FILE {
        "journal"
    } else if name == FRAMES_DIR {
        "frames dir"
    } else if is_temp_name(&name) {
        "frame temp"
    } else {
        "frame"
    };
    format!("{op} {what}")
}

#[test]
fn crash_at_20_random_points_and_resume_matches_an_uninterrupted_run() {
    const SHOTS: usize = 60;
    let tmp = tempfile::tempdir().unwrap();
    let reference = tmp.path().join("reference");
    let mut store = SessionStore::create(&reference, snapshot()).unwrap();
    run_plan(&mut store, SHOTS).unwrap();
    drop(store);

    let dir = tmp.path().join("crashed");
    SessionStore::create(&dir, snapshot()).unwrap();
    let mut rng = SplitMix(20_260_828);
    let mut phases = BTreeSet::new();
    let mut repairs = 0;
    for crash in 0..20 {
        let budget = rng.range(1, 20);
        let storage = CrashingStorage::new(FsStorage, budget);
        let outcome = SessionStore::resume_with(&storage, &dir).and_then(|(mut store, report)| {
            repairs += usize::from(!report.is_clean());
            run_plan(&mut store, SHOTS)
        });
        let point = storage.crash_point();
        match (outcome, point) {
            (Err(_), Some(p)) => {
                phases.insert(phase(p.operation, &p.path));
            }
            (outcome, point) => panic!("crash {crash} (budget {budget}): expected a crash, got {outcome:?} {point:?}"),
        }
    }
    let (mut store, _) = SessionStore::resume(&dir).unwrap();
    run_plan(&mut store, SHOTS).unwrap();

    // Same journal bytes (same keys in the same order, same checksums) and
    // the same files, byte for byte; no temporary file left.
    let (a, b) = (tree(&reference), tree(&dir));
    let names = |t: &[(String, Vec<u8>)]| t.iter().map(|(n, _)| n.clone()).collect::<Vec<_>>();
    assert_eq!(names(&b), names(&a));
    assert!(b.iter().all(|(n, _)| !n.contains(".tmp")));
    for ((name, x), (_, y)) in a.iter().zip(&b) {
        assert!(x == y, "{name} differs from the uninterrupted run");
    }
    let entries = journal_entries(&dir);
    assert_eq!(entries, journal_entries(&reference));
    let keys: Vec<_> = entries.iter().map(|e| e.key().to_string()).collect();
    let unique: BTreeSet<_> = keys.iter().collect();
    assert_eq!(unique.len(), keys.len(), "no key twice");
    assert_eq!(keys.len(), SHOTS);
    let frames = entries.iter().filter(|e| e.frame().is_some()).count();
    assert_eq!(frames, SHOTS - (0..SHOTS).filter(|&i| is_missed(i)).count());
    assert!(store.verify().unwrap().is_ok());
    eprintln!(
        "crash phases hit ({}): {phases:?}; resumes with repairs: {repairs}",
        phases.len()
    );
    // Every step of a frame's write sequence was interrupted at least once.
    for p in [
        "write frame temp",
        "fsync file frame temp",
        "rename frame temp",
        "fsync directory frames dir",
        "append journal",
        "fsync file journal",
    ] {
        assert!(phases.contains(p), "phase {p:?} not hit: {phases:?}");
    }
    assert!(repairs >= 5, "{repairs} resumes repaired something");
}

#[test]
fn a_crash_during_resume_repairs_is_repaired_by_the_next_resume() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("s");
    let mut store = SessionStore::create(&dir, snapshot()).unwrap();
    run_plan(&mut store, 2).unwrap();
    drop(store);
    // Crash at the journal append of shot 2: an orphan frame and a torn
    // line. Its write sequence is 5 operations; the 5th is the append.
    let storage = CrashingStorage::new(FsStorage, 5);
    let (mut store, _) = SessionStore::resume_with(&storage, &dir).unwrap();
    assert!(run_plan(&mut store, 3).is_err());
    let point = storage.crash_point().unwrap();
    assert_eq!(phase(point.operation, &point.path), "append journal");
    // From copies of that state, resumes that crash at each of their
    // repair steps; each is repaired by the next resume.
    let mut crashed_at = Vec::new();
    for n in 1.. {
        let copy = tmp.path().join(format!("copy{n}"));
        for (name, bytes) in tree(&dir) {
            let path = copy.join(name.trim_start_matches('/'));
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            std::fs::write(path, bytes).unwrap();
        }
        let storage = CrashingStorage::new(FsStorage, n);
        if SessionStore::resume_with(&storage, &copy).is_ok() {
            break;
        }
        let p = storage.crash_point().unwrap();
        crashed_at.push(phase(p.operation, &p.path));
        let (mut store, _) = SessionStore::resume(&copy).unwrap();
        run_plan(&mut store, 3).unwrap();
        assert_eq!(journal_entries(&copy).len(), 3);
        assert!(store.verify().unwrap().is_ok());
    }
    assert_eq!(
        crashed_at,
        [
            "truncate journal",
            "fsync file journal",
            "remove frame",
            "fsync directory frames dir"
        ]
    );
}

#[test]
fn torn_journal_line_is_cut_and_reported() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("s");
    let mut store = SessionStore::create(&dir, snapshot()).unwrap();
    run_plan(&mut store, 3).unwrap();
    drop(store);
    let journal = dir.join(JOURNAL_FILE);
    let before = std::fs::metadata(&journal).unwrap().len();
    let torn = b"{\"status\":\"done\",\"key\":\"morning@2026";
    std::fs::OpenOptions::new()
        .append(true)
        .open(&journal)
        .and_then(|mut f| std::io::Write::write_all(&mut f, torn))
        .unwrap();
    let (mut store, report) = SessionStore::resume(&dir).unwrap();
    assert_eq!(
        report.torn_line,
        Some(TornLine {
            offset: before,
            bytes: torn.len() as u64
        })
    );
    assert!(report.to_string().contains("torn journal line"), "{report}");
    assert_eq!(std::fs::metadata(&journal).unwrap().len(), before);
    assert_eq!(store.entries().len(), 3);
    // The journal takes new lines cleanly after the cut.
    run_plan(&mut store, 4).unwrap();
    assert_eq!(journal_entries(&dir).len(), 4);
}

#[test]
fn orphan_frame_and_temp_files_are_removed_and_reported() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("s");
    let mut store = SessionStore::create(&dir, snapshot()).unwrap();
    run_plan(&mut store, 2).unwrap();
    drop(store);
    // A frame renamed into place but never journaled, and two temp files.
    let frames = dir.join(FRAMES_DIR);
    let orphan = frames.join(frame_file_name(&key(2)));
    std::fs::write(&orphan, encode_png("x", &synth_frame(2, 12)).unwrap()).unwrap();
    let temp = frames.join(format!(".{}.tmp", frame_file_name(&key(3))));
    std::fs::write(&temp, b"half a png").unwrap();
    std::fs::write(dir.join(".plan.ron.tmp"), b"(").unwrap();
    let (mut store, report) = SessionStore::resume(&dir).unwrap();
    assert_eq!(report.orphan_frames_removed, vec![orphan.clone()]);
    assert_eq!(report.temp_files_removed.len(), 2);
    assert!(!orphan.exists() && !temp.exists() && !dir.join(".plan.ron.tmp").exists());
    assert!(!store.completed(&key(2)));
    assert_eq!(report.frames, 2);
    // The shot is retaken.
    run_plan(&mut store, 3).unwrap();
    assert!(store.completed(&key(2)) && orphan.exists());
}

#[test]
fn damaged_or_missing_journaled_frame_is_an_error_naming_the_file() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("s");
    let mut store = SessionStore::create(&dir, snapshot()).unwrap();
    run_plan(&mut store, 3).unwrap();
    let entry = store.frame_entry(&key(1)).unwrap().clone();
    let path = store.frame_path(&entry);
    let mut bytes = std::fs::read(&path).unwrap();
    bytes[60] ^= 0x40;
    std::fs::write(&path, &bytes).unwrap();
    // verify lists it; read_frame refuses it.
    let report = store.verify().unwrap();
    assert_eq!(report.frames_checked, 3);
    assert_eq!(report.problems.len(), 1);
    assert!(
        report.problems[0].to_string().contains(&entry.file),
        "{}",
        report.problems[0]
    );
    assert!(matches!(
        store.read_frame(&entry),
        Err(StoreError::ChecksumMismatch { .. })
    ));
    drop(store);
    let err = SessionStore::resume(&dir).unwrap_err();
    assert!(
        matches!(&err, StoreError::ChecksumMismatch { path: p, .. } if *p == path),
        "{err}"
    );
    assert!(err.to_string().contains(&entry.file), "{err}");
    // Missing: also an error naming it, and the file is not dropped from
    // the journal.
    std::fs::remove_file(&path).unwrap();
    let err = SessionStore::resume(&dir).unwrap_err();
    assert!(
        matches!(&err, StoreError::MissingFrame { path: p, .. } if *p == path),
        "{err}"
    );
    assert!(err.to_string().contains("missing on disk"), "{err}");
    assert_eq!(journal_entries(&dir).len(), 3);
}

#[test]
fn corrupt_complete_journal_line_is_an_error_with_its_line_number() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("s");
    let mut store = SessionStore::create(&dir, snapshot()).unwrap();
    run_plan(&mut store, 3).unwrap();
    drop(store);
    let journal = dir.join(JOURNAL_FILE);
    let text = std::fs::read_to_string(&journal).unwrap();
    let mut lines: Vec<&str> = text.lines().collect();
    lines[1] = "{\"status\":\"exploded\"}";
    std::fs::write(&journal, lines.join("\n") + "\n").unwrap();
    let err = SessionStore::resume(&dir).unwrap_err();
    assert!(matches!(err, StoreError::JournalCorrupt { line: 2, .. }), "{err}");
    assert!(err.to_string().contains("journal.jsonl:2:"), "{err}");
    // Binary junk: an error, not a panic.
    std::fs::write(&journal, [0xff, 0xfe, b'\n', 0x00]).unwrap();
    assert!(matches!(
        SessionStore::resume(&dir),
        Err(StoreError::JournalCorrupt { line: 1, .. })
    ));
}

/// The reference run of `n` shots, and the session size after each shot.
fn reference_sizes(root: &Path, n: usize) -> (PathBuf, Vec<u64>) {
    let dir = root.join("reference");
    let mut store = SessionStore::create(&dir, snapshot()).unwrap();
    let mut sizes = vec![tree_size(&dir)];
    for i in 1..=n {
        run_plan(&mut store, i).unwrap();
        sizes.push(tree_size(&dir));
    }
    (dir, sizes)
}

#[test]
fn disk_full_during_a_frame_stops_cleanly_and_resume_completes() {
    const SHOTS: usize = 20;
    const K: usize = 5;
    let tmp = tempfile::tempdir().unwrap();
    let (reference, sizes) = reference_sizes(tmp.path(), SHOTS);
    let dir = tmp.path().join("full");
    SessionStore::create(&dir, snapshot()).unwrap();
    // Room for shots 0..K and half of frame K's PNG.
    let png_k = sizes[K + 1] - sizes[K] - journal_line_len(&reference, K);
    let quota = QuotaStorage::open(FsStorage, &dir, sizes[K] + png_k / 2).unwrap();
    let (mut store, _) = SessionStore::resume_with(&quota, &dir).unwrap();
    let err = run_plan(&mut store, SHOTS).unwrap_err();
    let msg = err.to_string();
    assert!(
        matches!(&err, StoreError::DiskFull(d) if d.what == "frame" && d.key == key(K) && d.frames == 5),
        "{err}"
    );
    assert!(msg.contains("disk full while writing frame"), "{msg}");
    assert!(msg.contains(&format!("intact up to shot {:?}", key(K - 1))), "{msg}");
    assert!(msg.contains("campanile capture --resume"), "{msg}");
    drop(store);
    // Journal parses and holds shots 0..K exactly; no partial or temp file.
    assert_eq!(journal_entries(&dir), journal_entries(&reference)[..K].to_vec());
    let final_k = dir.join(FRAMES_DIR).join(frame_file_name(&key(K)));
    assert!(!final_k.exists());
    assert!(tree(&dir).iter().all(|(n, _)| !n.contains(".tmp")));
    assert_eq!(tree_size(&dir), sizes[K]);
    // Free space; resume completes and matches the uninterrupted run.
    quota.set_quota(u64::MAX);
    let (mut store, report) = SessionStore::resume_with(&quota, &dir).unwrap();
    assert!(report.is_clean(), "{report}");
    assert!(store.verify().unwrap().is_ok());
    run_plan(&mut store, SHOTS).unwrap();
    assert_eq!(tree(&dir), tree(&reference));
}

/// Length of the journal line for shot `i` of the reference run.
fn journal_line_len(reference: &Path, i: usize) -> u64 {
    journal_entries(reference)[i].to_line().len() as u64
}

#[test]
fn disk_full_during_the_journal_append_rolls_back_the_frame() {
    const SHOTS: usize = 8;
    const K: usize = 3;
    let tmp = tempfile::tempdir().unwrap();
    let (reference, sizes) = reference_sizes(tmp.path(), SHOTS);
    let dir = tmp.path().join("full");
    SessionStore::create(&dir, snapshot()).unwrap();
    // The frame fits; its journal line does not (10 bytes of it do).
    let png_k = sizes[K + 1] - sizes[K] - journal_line_len(&reference, K);
    let quota = QuotaStorage::open(FsStorage, &dir, sizes[K] + png_k + 10).unwrap();
    let (mut store, _) = SessionStore::resume_with(&quota, &dir).unwrap();
    let err = run_plan(&mut store, SHOTS).unwrap_err();
    assert!(
        matches!(&err, StoreError::DiskFull(d) if d.what == "journal line"),
        "{err}"
    );
    // Journal exactly as before, the frame file removed, nothing torn.
    let journal = std::fs::read(dir.join(JOURNAL_FILE)).unwrap();
    assert_eq!(
        journal,
        std::fs::read(reference.join(JOURNAL_FILE)).unwrap()[..journal.len()]
    );
    assert_eq!(journal_entries(&dir).len(), K);
    assert!(!dir.join(FRAMES_DIR).join(frame_file_name(&key(K))).exists());
    assert_eq!(tree_size(&dir), sizes[K]);
    // The same store carries on once there is room: it was left consistent.
    quota.set_quota(u64::MAX);
    run_plan(&mut store, SHOTS).unwrap();
    assert_eq!(tree(&dir), tree(&reference));
}

#[test]
fn duplicate_invalid_and_misplaced_requests_are_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("s");
    let mut store = SessionStore::create(&dir, snapshot()).unwrap();
    let frame = synth_frame(1, 12);
    let meta = meta_for(1, &frame);
    store.record_frame("a/b", &meta, &frame).unwrap();
    let err = store.record_frame("a/b", &meta, &frame).unwrap_err();
    assert!(
        matches!(
            err,
            StoreError::Duplicate {
                status: "completed",
                ..
            }
        ),
        "{err}"
    );
    assert!(err.to_string().contains("already in the journal"), "{err}");
    assert!(matches!(
        store.record_missed("a/b", "late", meta.time),
        Err(StoreError::Duplicate { .. })
    ));
    for bad in ["", "a\nb"] {
        let err = store.record_frame(bad, &meta, &frame).unwrap_err();
        assert!(matches!(err, StoreError::InvalidKey { .. }), "{err}");
        assert!(err.to_string().starts_with("invalid shot key"), "{err}");
    }
    // Missed is final within the run …
    store.record_missed("c", "head stalled", meta.time).unwrap();
    let err = store.record_frame("c", &meta, &frame).unwrap_err();
    assert!(
        matches!(
            err,
            StoreError::Duplicate {
                status: "missed in this run",
                ..
            }
        ),
        "{err}"
    );
    // … and a frame or metadata that cannot be stored is refused.
    let mut bad = frame.clone();
    bad.data[5] = 4096;
    assert!(matches!(
        store.record_frame("d", &meta, &bad),
        Err(StoreError::BadFrame { .. })
    ));
    bad.data.pop();
    assert!(matches!(
        store.record_frame("d", &meta, &bad),
        Err(StoreError::BadFrame { .. })
    ));
    let mut nan = meta.clone();
    nan.gain_db = f64::NAN;
    let err = store.record_frame("d", &nan, &frame).unwrap_err();
    assert!(err.to_string().contains("gain_db is NaN"), "{err}");
    assert_eq!(store.entries().len(), 2);
    drop(store);
    // … but a resumed run may retake it; the journal keeps both lines.
    let (mut store, report) = SessionStore::resume(&dir).unwrap();
    assert_eq!((report.frames, report.missed), (1, 1));
    assert!(store.missed("c") && !store.missed_in_this_run("c"));
    store.record_frame("c", &meta, &frame).unwrap();
    assert!(store.completed("c") && !store.missed("c"));
    let statuses: Vec<_> = journal_entries(&dir)
        .iter()
        .map(|e| (e.key().to_string(), e.frame().is_some()))
        .collect();
    assert_eq!(
        statuses,
        [("a/b".into(), true), ("c".into(), false), ("c".into(), true)]
    );
    // create refuses a non-empty directory; resume refuses a non-session.
    let err = SessionStore::create(&dir, snapshot()).unwrap_err();
    assert!(matches!(err, StoreError::SessionExists { .. }), "{err}");
    assert!(err.to_string().contains("is not empty"), "{err}");
    let empty = tmp.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    let err = SessionStore::resume(&empty).unwrap_err();
    assert!(err.to_string().contains("journal.jsonl is missing"), "{err}");
    // An existing empty directory is fine for create.
    SessionStore::create(&empty, snapshot()).unwrap();
}

#[test]
fn pruned_frames_are_gone_on_purpose_and_outages_are_journaled() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("s");
    let mut store = SessionStore::create(&dir, snapshot()).unwrap();
    for i in 0..4 {
        let frame = synth_frame(i as u64, 12);
        store.record_frame(&key(i), &meta_for(i, &frame), &frame).unwrap();
    }
    let t = Utc.with_ymd_and_hms(2026, 8, 28, 9, 0, 0).unwrap();
    let files: Vec<PathBuf> = (0..2)
        .map(|i| store.frame_path(store.frame_entry(&key(i)).unwrap()))
        .collect();
    let bytes: u64 = (0..2).map(|i| store.frame_entry(&key(i)).unwrap().bytes).sum();
    // Refused: a key without a frame, a key listed twice; nothing journaled.
    let e = store.record_pruned(&["nope".into()], "budget", t).unwrap_err();
    assert!(
        matches!(e, StoreError::NotPrunable { .. }) && e.to_string().contains("\"nope\""),
        "{e}"
    );
    let e = store.record_pruned(&[key(0), key(0)], "budget", t).unwrap_err();
    assert!(e.to_string().contains("listed twice"), "{e}");
    assert_eq!(store.entries().len(), 4);
    let entry = store.record_pruned(&[key(0), key(1)], "budget", t).unwrap();
    let JournalEntry::Pruned(p) = &entry else {
        panic!("{entry:?}")
    };
    assert_eq!(p.bytes, bytes);
    assert!(files.iter().all(|f| !f.exists()));
    assert!(store.completed(&key(0)) && store.pruned(&key(0)) && store.frame_entry(&key(0)).is_none());
    let e = store.record_pruned(&[key(1)], "budget", t).unwrap_err();
    assert!(e.to_string().contains("pruned twice"), "{e}");
    store
        .record_outage("head", t, t + chrono::Duration::minutes(30), false)
        .unwrap();
    let verify = store.verify().unwrap();
    assert!(verify.is_ok() && verify.frames_checked == 2 && verify.frames_pruned == 2);
    drop(store);

    // Resume accepts the pruned frames as gone; readers leave them out.
    let (store, report) = SessionStore::resume(&dir).unwrap();
    assert!(report.is_clean(), "{report}");
    assert!(store.pruned(&key(1)) && !store.pruned(&key(2)));
    assert!(matches!(store.entries().last(), Some(JournalEntry::Outage(o)) if o.device == "head" && !o.open));
    let reader = SessionReader::open(&dir).unwrap();
    let keys: Vec<&str> = reader.frames().map(|f| f.key.as_str()).collect();
    assert_eq!(keys, [key(2), key(3)]);
    drop(store);

    // A crash between the pruned line and the deletions: resume removes
    // the files as unjournaled frames.
    let store = SessionStore::resume(&dir).unwrap().0;
    let kept = store.frame_path(store.frame_entry(&key(2)).unwrap());
    let line = JournalEntry::Pruned(PrunedEntry {
        time: t,
        keys: vec![key(2)],
        bytes: 1,
        reason: "budget".into(),
    })
    .to_line();
    store.storage().append(&dir.join(JOURNAL_FILE), &line).unwrap();
    drop(store);
    let (store, report) = SessionStore::resume(&dir).unwrap();
    assert_eq!(report.orphan_frames_removed, vec![kept.clone()]);
    assert!(!kept.exists() && store.pruned(&key(2)) && store.completed(&key(2)));
}

#[test]
fn a_shot_missed_again_on_each_resume_keeps_its_one_missed_line() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("s");
    let t0 = Utc.with_ymd_and_hms(2026, 8, 28, 7, 0, 0).unwrap();
    let mut store = SessionStore::create(&dir, snapshot()).unwrap();
    store.record_missed("c", "head stalled", t0).unwrap();
    drop(store);
    for run in 1..=3 {
        let (mut store, report) = SessionStore::resume(&dir).unwrap();
        assert_eq!(report.missed, 1, "run {run}");
        let later = t0 + chrono::Duration::hours(run);
        let stands = store.record_missed("c", "camera timed out", later).unwrap();
        let JournalEntry::Missed(m) = &stands else {
            panic!("{stands:?}")
        };
        assert_eq!((m.reason.as_str(), m.time), ("head stalled", t0), "run {run}");
        assert!(store.missed_in_this_run("c"));
        // Still final for this run.
        let err = store.record_missed("c", "again", later).unwrap_err();
        assert!(matches!(err, StoreError::Duplicate { .. }), "{err}");
        assert_eq!(store.entries().len(), 1, "run {run}");
    }
    let lines = std::fs::read_to_string(dir.join(JOURNAL_FILE)).unwrap();
    assert_eq!(lines.lines().count(), 1, "{lines}");
}

#[test]
fn a_create_that_fails_leaves_the_directory_as_it_was() {
    let tmp = tempfile::tempdir().unwrap();
    // Absent before: absent after.
    let dir = tmp.path().join("s");
    let quota = QuotaStorage::open(FsStorage, &dir, 100).unwrap();
    let err = SessionStore::create_with(&quota, &dir, snapshot()).unwrap_err();
    assert!(matches!(err, StoreError::Io { .. } | StoreError::DiskFull(_)), "{err}");
    assert!(!dir.exists(), "{:?}", std::fs::read_dir(&dir).map(|d| d.count()));
    assert_eq!(quota.used(), 0);
    // Empty before: empty after, and a new create takes it.
    std::fs::create_dir(&dir).unwrap();
    let quota = QuotaStorage::open(FsStorage, &dir, 100).unwrap();
    SessionStore::create_with(&quota, &dir, snapshot()).unwrap_err();
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0);
    SessionStore::create(&dir, snapshot()).unwrap();
    assert!(dir.join(JOURNAL_FILE).exists());
}

#[test]
fn an_unused_new_session_is_discarded_and_a_used_or_resumed_one_kept() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("s");
    let store = SessionStore::create(&dir, snapshot()).unwrap();
    assert!(store.discard_unused().unwrap());
    assert!(!dir.exists());
    let empty = tmp.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    let store = SessionStore::create(&empty, snapshot()).unwrap();
    assert!(store.discard_unused().unwrap());
    assert_eq!(std::fs::read_dir(&empty).unwrap().count(), 0);
    let mut store = SessionStore::create(&dir, snapshot()).unwrap();
    store.record_missed("c", "head stalled", Utc::now()).unwrap();
    assert!(!store.discard_unused().unwrap());
    let (store, _) = SessionStore::resume(&dir).unwrap();
    assert!(!store.discard_unused().unwrap());
    assert!(dir.join(JOURNAL_FILE).exists());
}
