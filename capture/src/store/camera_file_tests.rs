//! Tests of frames delivered as the camera's file (JPEG, DNG, a maker's RAW): kept byte
//! for byte, journaled with their format, decoded through the HDR readers,
//! checked by `verify`; and journals from before the format field.

use super::*;
use crate::device::{ExposureTime, FrameFile, Gain};
use crate::store::{SessionReader, ShotKind};
use campanile_process::camera::bayer::{BayerSensor, Exposure};
use campanile_process::camera::image::RadianceImage;
use campanile_process::hdr::dng_file::{DngLayout, DngMetadata, dng_bytes};
use campanile_process::hdr::image_file::jpeg_bytes;
use campanile_process::hdr::linear_codes::log_code_curve;
use chrono::TimeZone;

const W: usize = 24;
const H: usize = 16;

fn snapshot() -> Snapshot {
    Snapshot {
        plan_ron: "(sessions: [(name: \"sky\")])\n".into(),
        station_ron: "(camera: Sim)\n".into(),
        scene_ron: None,
        provenance: crate::store::Provenance {
            campanile_version: "0.1.0".into(),
            created_utc: Utc.with_ymd_and_hms(2026, 8, 28, 5, 0, 0).unwrap(),
            calibration: Vec::new(),
            sources: None,
        },
    }
}

/// A 12-bit horizontal ramp (the camera's codes) and, if given, its file.
fn frame(file: Option<FrameFile>) -> Frame {
    let data: Vec<u16> = (0..W * H)
        .flat_map(|i| [((i % W) * 4095 / (W - 1)) as u16; 3])
        .collect();
    Frame {
        width: W,
        height: H,
        bits: 12,
        data,
        exposure_requested: ExposureTime::from_seconds(0.01).unwrap(),
        exposure_actual: ExposureTime::from_seconds(0.01).unwrap(),
        gain: Gain::UNITY,
        sequence: 7,
        timestamp: Utc.with_ymd_and_hms(2026, 8, 28, 6, 0, 0).unwrap(),
        temperature_c: None,
        file,
    }
}

fn jpeg_frame() -> Frame {
    let f = frame(None);
    let bytes = jpeg_bytes(&f.to_code_image(), 95, Some(0.01)).unwrap();
    frame(Some(FrameFile {
        format: FrameFormat::Jpeg,
        bytes,
    }))
}

/// A DNG of a flat field at linear value 0.25 (red), 0.5 (green), 0.35
/// (blue) of the white level, noiseless, except the right quarter at 4×
/// the light (green and blue clip).
fn dng_frame() -> (Frame, [f64; 3]) {
    let sensor = BayerSensor::typical_14bit();
    let e = Exposure {
        time_s: 1.0,
        f_number: 4.0,
        iso: 100.0,
    };
    let scene = RadianceImage {
        width: W,
        height: H,
        data: (0..W * H)
            .flat_map(|i| [if i % W >= 3 * W / 4 { 2.0f32 } else { 0.5 }; 3])
            .collect(),
    };
    let mosaic = sensor.photograph_noiseless(&scene, &e);
    let meta = DngMetadata {
        make: "Campanile".into(),
        model: "test".into(),
        exposure: e,
        xyz_to_camera: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        as_shot_neutral: sensor.neutral(),
        calibration_illuminant: 21,
    };
    let bytes = dng_bytes(&mosaic, &meta, DngLayout::SingleIfd);
    (
        frame(Some(FrameFile {
            format: FrameFormat::Dng,
            bytes,
        })),
        [0.25, 0.5, 0.35],
    )
}

fn record(dir: &Path, key: &str, f: &Frame) -> (SessionStore, FrameEntry) {
    let mut store = SessionStore::create(dir, snapshot()).unwrap();
    let entry = store
        .record_frame(key, &FrameMeta::from_frame(f, ShotKind::Data), f)
        .unwrap();
    let entry = entry.frame().unwrap().clone();
    (store, entry)
}

#[test]
fn a_jpeg_is_kept_byte_for_byte_journaled_as_jpeg_and_read_as_8_bit_codes() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("s");
    let f = jpeg_frame();
    let (store, entry) = record(&dir, "sky@2026-08-28/s0/t0/f0", &f);
    assert_eq!(entry.format, FrameFormat::Jpeg);
    assert!(entry.file.ends_with(".jpg"), "{}", entry.file);
    let on_disk = std::fs::read(dir.join(&entry.file)).unwrap();
    assert_eq!(on_disk, f.file.as_ref().unwrap().bytes, "stored as delivered");
    // The journal line names the format.
    let journal = std::fs::read_to_string(dir.join(JOURNAL_FILE)).unwrap();
    assert!(journal.contains("\"format\":\"jpeg\""), "{journal}");
    // Decoded through the HDR reader: 8-bit codes of the ramp, within 3 codes.
    let codes = store.read_frame(&entry).unwrap();
    assert_eq!((codes.width, codes.height, codes.bits), (W, H, 8));
    let worst = codes
        .data
        .iter()
        .zip(&f.data)
        .map(|(&a, &z)| (f64::from(a) - f64::from(z) * 255.0 / 4095.0).abs())
        .fold(0.0, f64::max);
    assert!(worst <= 3.0, "worst code error {worst}");
    let report = store.verify().unwrap();
    assert_eq!((report.frames_checked, report.problems.len()), (1, 0), "{report:?}");
    // The reader (what `campanile process` uses) reads the same codes.
    let reader = SessionReader::open(&dir).unwrap();
    assert_eq!(reader.read_frame(&entry).unwrap().data, codes.data);
}

#[test]
fn a_dng_reads_as_the_linear_frame_in_logarithmic_codes_with_clipping_at_the_top() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("s");
    let (f, linear) = dng_frame();
    let (store, entry) = record(&dir, "sky@2026-08-28/s0/t0/f1", &f);
    assert_eq!(entry.format, FrameFormat::Dng);
    assert!(entry.file.ends_with(".dng"), "{}", entry.file);
    let codes = store.read_frame(&entry).unwrap();
    assert_eq!((codes.width, codes.height, codes.bits), (W, H, 16));
    let curve = log_code_curve();
    // A pixel of the dim part, away from the bright quarter: each channel
    // is its linear value (black removed, white = 1) within 0.1%
    // (14-bit rounding of the mosaic is 6e-5 of the white level).
    let p = 5 * W + 4;
    for (c, want) in linear.iter().enumerate() {
        let v = curve.ln_exposure(c, f64::from(codes.data[p * 3 + c])).exp();
        assert!((v / want - 1.0).abs() < 1e-3, "channel {c}: {v} vs {want}");
    }
    // In the bright quarter green (4 × 0.5) and blue (4 × 0.35) clip: the
    // largest code; red (4 × 0.25 = 1.0, at the white level) too.
    let q = 5 * W + W - 2;
    assert_eq!(&codes.data[q * 3..q * 3 + 3], &[65_535, 65_535, 65_535]);
    assert_eq!(store.verify().unwrap().problems.len(), 0);
}

/// A maker's RAW format is kept under its own extension and name in the
/// journal, and read through the same RAW reader. No maker's RAW file is
/// in the repository, so the bytes are the DNG's (rawler knows a file by
/// its content): what is tested is the store's handling of the format.
#[test]
fn a_makers_raw_is_kept_under_its_own_format_and_read_like_a_dng() {
    let tmp = tempfile::tempdir().unwrap();
    let (mut f, _) = dng_frame();
    let (dng_store, dng_entry) = record(&tmp.path().join("d"), "sky@2026-08-28/s0/t0/f1", &f);
    let dng_codes = dng_store.read_frame(&dng_entry).unwrap();
    if let Some(file) = f.file.as_mut() {
        file.format = FrameFormat::Nef;
    }
    let dir = tmp.path().join("n");
    let (store, entry) = record(&dir, "sky@2026-08-28/s0/t0/f1", &f);
    assert_eq!(entry.format, FrameFormat::Nef);
    assert!(entry.file.ends_with(".nef"), "{}", entry.file);
    let journal = std::fs::read_to_string(dir.join(JOURNAL_FILE)).unwrap();
    assert!(journal.contains("\"format\":\"nef\""), "{journal}");
    assert_eq!(store.read_frame(&entry).unwrap().data, dng_codes.data);
    assert_eq!(store.verify().unwrap().problems.len(), 0);
    // A "CR3" that is a TIFF is refused by its first bytes.
    if let Some(file) = f.file.as_mut() {
        file.format = FrameFormat::Cr3;
    }
    let mut store = SessionStore::create(&tmp.path().join("c"), snapshot()).unwrap();
    let err = store
        .record_frame(
            "sky@2026-08-28/s0/t0/f1",
            &FrameMeta::from_frame(&f, ShotKind::Data),
            &f,
        )
        .unwrap_err()
        .to_string();
    assert!(err.contains("CR3"), "{err}");
}

#[test]
fn a_damaged_camera_file_is_a_verify_problem_naming_it_never_a_panic() {
    for (f, name) in [(jpeg_frame(), "JPEG"), (dng_frame().0, "DNG")] {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().join("s");
        // The camera delivered a file cut short: its signature is right, so it is recorded.
        let mut damaged = f.clone();
        if let Some(file) = damaged.file.as_mut() {
            file.bytes.truncate(file.bytes.len() / 4);
        }
        let (store, entry) = record(&dir, "sky@2026-08-28/s0/t0/f2", &damaged);
        let path = dir.join(&entry.file);
        let err = store.read_frame(&entry).unwrap_err();
        let msg = err.to_string();
        assert!(matches!(err, StoreError::BadFrameFile { .. }), "{name}: {msg}");
        let why = if name == "JPEG" {
            "expected the JPEG end of image ff d9: the file is cut short"
        } else {
            "not a readable DNG frame"
        };
        assert!(
            msg.contains(&path.display().to_string()) && msg.contains(why),
            "{name}: {msg}"
        );
        let report = store.verify().unwrap();
        assert_eq!(report.problems.len(), 1, "{name}: {report:?}");
    }
}

#[test]
fn a_camera_file_whose_first_bytes_are_not_its_format_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("s");
    let mut store = SessionStore::create(&dir, snapshot()).unwrap();
    let (dng, _) = dng_frame();
    let mut f = dng;
    if let Some(file) = f.file.as_mut() {
        file.format = FrameFormat::Jpeg;
    }
    let err = store
        .record_frame(
            "sky@2026-08-28/s0/t0/f3",
            &FrameMeta::from_frame(&f, ShotKind::Data),
            &f,
        )
        .unwrap_err();
    let msg = err.to_string();
    assert!(matches!(err, StoreError::BadFrame { .. }), "{msg}");
    assert!(msg.contains("[49 49 2a 00") && msg.contains("JPEG"), "{msg}");
    assert!(store.entries().is_empty());
    assert_eq!(std::fs::read_dir(dir.join(FRAMES_DIR)).unwrap().count(), 0);
}

#[test]
fn a_journal_from_before_the_format_field_reads_its_frames_as_png() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("s");
    let f = frame(None);
    let (_, entry) = record(&dir, "sky@2026-08-28/s0/t0/f4", &f);
    assert_eq!(entry.format, FrameFormat::Png);
    // Rewrite the journal as an older version wrote it: no "format".
    let journal = dir.join(JOURNAL_FILE);
    let text = std::fs::read_to_string(&journal).unwrap();
    let old = text.replace(",\"format\":\"png\"", "");
    assert_ne!(old, text, "the new line names the format: {text}");
    assert!(!old.contains("format"), "{old}");
    std::fs::write(&journal, &old).unwrap();
    let (store, report) = SessionStore::resume(&dir).unwrap();
    assert_eq!(report.frames, 1);
    let back = store.frame_entry("sky@2026-08-28/s0/t0/f4").unwrap().clone();
    assert_eq!(back.format, FrameFormat::Png);
    assert_eq!(store.read_frame(&back).unwrap().data, f.data);
    let reader = SessionReader::open(&dir).unwrap();
    let first = reader.frames().next().unwrap();
    assert_eq!(reader.read_frame(first).unwrap().data, f.data);
}

#[test]
fn resume_removes_an_unjournaled_camera_file() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("s");
    let (_, _) = record(&dir, "sky@2026-08-28/s0/t0/f0", &jpeg_frame());
    let orphan = dir
        .join(FRAMES_DIR)
        .join(frame_file_name_as("sky@2026-08-28/s0/t0/f9", FrameFormat::Dng));
    std::fs::write(&orphan, b"II*\0").unwrap();
    let (_, report) = SessionStore::resume(&dir).unwrap();
    assert_eq!(report.orphan_frames_removed, vec![orphan.clone()]);
    assert!(!orphan.exists());
}
