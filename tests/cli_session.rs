//! `campanile session import` on real camera files: the committed EOS 5D
//! Mark II brackets (`validation/hdr/fixtures/radiantlab-eos`, in-camera
//! JPEGs with the camera's own EXIF). A second bracket is made by copying
//! seven of them with their EXIF dates rewritten in place (same length, so
//! the EXIF structure is the camera's); the error cases likewise edit
//! real files' bytes (a model name, an EXIF tag number, the APP1 segment).

mod common;

use std::path::{Path, PathBuf};

use common::campanile;

const FIXTURES: &str = "validation/hdr/fixtures/radiantlab-eos";

fn fixture(name: &str) -> Vec<u8> {
    std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join(FIXTURES).join(name)).expect("fixture")
}

fn fixture_names() -> Vec<String> {
    (6955..=6972).map(|n| format!("IMG_{n}.JPG")).collect()
}

/// Every occurrence of `from` in `bytes` replaced by `to` (same length).
fn replace_all(bytes: &mut [u8], from: &[u8], to: &[u8]) -> usize {
    assert_eq!(from.len(), to.len());
    let mut n = 0;
    let mut i = 0;
    while i + from.len() <= bytes.len() {
        if &bytes[i..i + from.len()] == from {
            bytes[i..i + from.len()].copy_from_slice(to);
            n += 1;
            i += from.len();
        } else {
            i += 1;
        }
    }
    n
}

/// The 18 real frames (one bracket, 15:44:47–15:45:30 on the camera's
/// clock) and, with `sky`, 7 of them again as SKY_*.JPG ten minutes later.
fn folder(dir: &Path, sky: bool) -> PathBuf {
    let photos = dir.join("photos");
    std::fs::create_dir_all(&photos).unwrap();
    for name in fixture_names() {
        std::fs::write(photos.join(&name), fixture(&name)).unwrap();
    }
    if sky {
        for n in 6960..=6966 {
            let mut bytes = fixture(&format!("IMG_{n}.JPG"));
            // DateTimeOriginal, CreateDate and ModifyDate: 15:4x → 15:5x.
            assert!(replace_all(&mut bytes, b"2017:07:13 15:4", b"2017:07:13 15:5") >= 3);
            std::fs::write(photos.join(format!("SKY_{n}.JPG")), bytes).unwrap();
        }
    }
    photos
}

fn poses(dir: &Path) -> PathBuf {
    let path = dir.join("poses.ron");
    std::fs::write(
        &path,
        r#"ImportPoses(brackets: [
    (files: "IMG_*.JPG", position_m: (0.0, -20.0, 1.5), azimuth_deg: 180.0, elevation_deg: 10.0),
    (files: "SKY_*.JPG", azimuth_deg: 90.0, elevation_deg: 45.0),
])"#,
    )
    .unwrap();
    path
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn import(photos: &Path, out: &Path, poses: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec![
        "session",
        "import",
        s(photos),
        "--out",
        s(out),
        "--poses",
        s(poses),
        "--site",
        "37.8721,-122.2578,90",
    ];
    args.extend_from_slice(extra);
    campanile(&args)
}

fn text(o: &std::process::Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

#[test]
fn real_jpeg_brackets_become_a_session_that_process_takes() {
    let dir = tempfile::tempdir().expect("temp");
    let photos = folder(dir.path(), true);
    let poses = poses(dir.path());
    let session = dir.path().join("session");
    let o = import(
        &photos,
        &session,
        &poses,
        &["--clock-offset-s", "2.5", "--utc-offset", "-07:00", "--sky", "SKY_*"],
    );
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let out = text(&o);
    assert!(
        out.contains("2 brackets, 25 frames, camera Canon EOS 5D Mark II"),
        "{out}"
    );

    // The journal: the brackets, exposures and times the files' EXIF state.
    let journal = std::fs::read_to_string(session.join("journal.jsonl")).unwrap();
    let lines: Vec<serde_json::Value> = journal.lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(lines.len(), 25);
    let key = |i: usize| lines[i]["key"].as_str().unwrap().to_owned();
    let meta = |i: usize, f: &str| lines[i]["meta"][f].clone();
    assert_eq!(key(0), "import-1@2017-07-13/s0/t0/f0");
    assert_eq!(key(17), "import-1@2017-07-13/s0/t0/f17");
    // Ten minutes later, within the 15-minute occurrence gap: the same
    // light, the sky bracket as target 0 of a sky scan step.
    assert_eq!(key(18), "import-1@2017-07-13/s1/t0/f0");
    // IMG_6955: 13 s at 15:44:47.71 (SubSecTimeOriginal 71) at −07:00,
    // the camera's clock 2.5 s fast: 22:44:45.21 UTC.
    assert_eq!(meta(0, "time"), "2017-07-13T22:44:45.210Z");
    assert_eq!(meta(0, "exposure_actual_s"), 13.0);
    // IMG_6972: 1/8000 s at 15:45:30.21.
    assert_eq!(meta(17, "time"), "2017-07-13T22:45:27.710Z");
    assert_eq!(meta(17, "exposure_actual_s"), 0.000125);
    // SKY_6960: IMG_6960 (0.4 s, 15:45:17.57) ten minutes later.
    assert_eq!(meta(18, "time"), "2017-07-13T22:55:15.070Z");
    assert_eq!(meta(18, "exposure_actual_s"), 0.4);
    // Without a scene, the views and the sky bracket go through the head
    // and the estimated mount (level, its pan zero north): the views at
    // azimuth 180°, the sky at azimuth 90°, elevation 45°.
    assert_eq!(meta(0, "pose_reached")["pan_deg"], 180.0);
    let reached = |f: &str| meta(18, "pose_reached")[f].as_f64().expect("a head reading");
    assert!((reached("pan_deg") - 90.0).abs() < 1e-9, "{}", lines[18]);
    assert!((reached("tilt_deg") - 45.0).abs() < 1e-9, "{}", lines[18]);
    // Byte for byte.
    let file = lines[0]["file"].as_str().unwrap();
    assert_eq!(std::fs::read(session.join(file)).unwrap(), fixture("IMG_6955.JPG"));
    let plan = std::fs::read_to_string(session.join("plan.ron")).unwrap();
    assert!(plan.contains("SkyScan("), "{plan}");
    let record: serde_json::Value =
        serde_json::from_slice(&std::fs::read(session.join("import.json")).unwrap()).unwrap();
    assert_eq!(record["clock_offset_s"], 2.5);
    assert_eq!(record["brackets"][1]["purpose"], "sky");
    assert_eq!(record["brackets"][0]["frames"][0]["utc_offset_from"], "--utc-offset");

    let v = campanile(&["session", "verify", s(&session)]);
    assert_eq!(v.status.code(), Some(0), "{}", text(&v));
    assert!(
        text(&v).contains("25 frames checked, 0 damaged or missing"),
        "{}",
        text(&v)
    );

    let processed = dir.path().join("processed");
    let p = campanile(&["process", s(&session), "--out", s(&processed)]);
    assert!(matches!(p.status.code(), Some(0 | 3)), "{}", text(&p));
    let quality = std::fs::read_to_string(processed.join("quality.json")).unwrap();
    for said in [
        "estimated, not measured (camera): camera estimated from EXIF",
        "focal length 1212.4 px estimated from EXIF FocalLength 8 mm",
        "estimated, not measured (time): time from EXIF DateTimeOriginal with a stated clock offset of 2.5 s",
        "estimated, not measured (exposure)",
        "estimated, not measured (sun)",
    ] {
        assert!(quality.contains(said), "{said:?} not in {quality}");
    }
}

/// With a scene, a view is taken off the head: its frames journal no head
/// reading, and its pose (roll included) is kept among the scene's poses,
/// which `process` turns it by; without a scene a roll is refused.
#[test]
fn a_view_imported_with_a_scene_keeps_its_rolled_pose() {
    let dir = tempfile::tempdir().expect("temp");
    let photos = folder(dir.path(), false);
    let poses = dir.path().join("rolled.ron");
    std::fs::write(
        &poses,
        r#"ImportPoses(brackets: [
    (files: "IMG_*.JPG", position_m: (3.0, -20.0, 1.5), azimuth_deg: 170.0, elevation_deg: 10.0, roll_deg: -4.5),
])"#,
    )
    .unwrap();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/campanile-scene.ron");
    let session = dir.path().join("session");
    let clock = ["--clock-offset-s", "0", "--utc-offset", "-07:00"];
    let mut extra = clock.to_vec();
    extra.extend(["--scene", s(&scene)]);
    let o = import(&photos, &session, &poses, &extra);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let journal = std::fs::read_to_string(session.join("journal.jsonl")).unwrap();
    for line in journal.lines() {
        let v: serde_json::Value = serde_json::from_str(line).unwrap();
        assert!(v["meta"]["pose_reached"].is_null(), "{line}");
        assert!(v["meta"]["pose_requested"].is_null(), "{line}");
    }
    let snapshot = std::fs::read_to_string(session.join("scene.ron")).unwrap();
    let scene: campanile_config::Scene = ron::from_str(&snapshot).unwrap();
    let pose = scene.pose("import-IMG_6955").expect("the made pose");
    assert_eq!(
        (pose.position_m, pose.azimuth_deg, pose.elevation_deg, pose.roll_deg),
        ((3.0, -20.0, 1.5), 170.0, 10.0, -4.5)
    );

    let o = import(&photos, &dir.path().join("no-scene"), &poses, &clock);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(
        text(&o).contains("is given roll_deg -4.5: a rolled view needs --scene"),
        "{}",
        text(&o)
    );
}

/// Runs an import expected to fail with exit 2 and a message holding every `want`.
fn refused(photos: &Path, dir: &Path, extra: &[&str], want: &[&str]) {
    let poses = poses(dir);
    let out = dir.join(format!("session-{}", rand_name(want)));
    let mut args = vec!["--clock-offset-s", "0", "--utc-offset", "-07:00"];
    args.extend_from_slice(extra);
    let o = import(photos, &out, &poses, &args);
    let t = text(&o);
    assert_eq!(o.status.code(), Some(2), "{t}");
    for w in want {
        assert!(t.contains(w), "{w:?} not in {t}");
    }
    assert!(!t.contains("panicked"), "{t}");
}

fn rand_name(want: &[&str]) -> usize {
    want.iter().map(|w| w.len()).sum::<usize>() + want.len() * 1000
}

#[test]
fn bad_folders_and_options_exit_2_naming_the_file() {
    let dir = tempfile::tempdir().expect("temp");
    // An empty folder.
    let empty = dir.path().join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    refused(&empty, dir.path(), &[], &["no camera files in the folder"]);

    // A file that is not a JPEG.
    let d = dir.path().join("not-jpeg");
    let photos = folder(&d, false);
    std::fs::write(photos.join("notes.txt"), b"taken on a sunny day").unwrap();
    refused(&photos, &d, &[], &["notes.txt", "not a JPEG", "ff d8 ff"]);

    // A JPEG without EXIF: the camera's file with its APP1 segment cut out.
    let d = dir.path().join("no-exif");
    let photos = folder(&d, false);
    let stripped = strip_app1(&fixture("IMG_6960.JPG"));
    std::fs::write(photos.join("IMG_6960.JPG"), stripped).unwrap();
    refused(&photos, &d, &[], &["IMG_6960.JPG", "no EXIF block"]);

    // Two cameras: one file's Model rewritten.
    let d = dir.path().join("two-cameras");
    let photos = folder(&d, false);
    let mut bytes = fixture("IMG_6960.JPG");
    assert!(replace_all(&mut bytes, b"EOS 5D Mark II", b"EOS 5D Mark IV") >= 1);
    std::fs::write(photos.join("IMG_6960.JPG"), bytes).unwrap();
    refused(
        &photos,
        &d,
        &[],
        &[
            "2 cameras",
            "\"Canon EOS 5D Mark IV\": 1 files, e.g. IMG_6960.JPG",
            "own session",
        ],
    );

    // No ExposureTime: the tag's number changed in the file's IFD entry
    // (little-endian: 9a 82, RATIONAL, count 1); --times then gives it.
    let d = dir.path().join("no-time");
    let photos = folder(&d, false);
    let mut bytes = fixture("IMG_6960.JPG");
    assert_eq!(
        replace_all(
            &mut bytes,
            &[0x9a, 0x82, 0x05, 0x00, 0x01, 0x00, 0x00, 0x00],
            &[0x9b, 0x82, 0x05, 0x00, 0x01, 0x00, 0x00, 0x00]
        ),
        1
    );
    std::fs::write(photos.join("IMG_6960.JPG"), bytes).unwrap();
    refused(
        &photos,
        &d,
        &[],
        &["IMG_6960.JPG", "EXIF ExposureTime is absent", "--times"],
    );
    let times = d.join("times.csv");
    std::fs::write(&times, "file,time\nIMG_6960.JPG,0.4\n").unwrap();
    let o = import(
        &photos,
        &d.join("with-times"),
        &poses(&d),
        &["--clock-offset-s", "0", "--utc-offset", "-07:00", "--times", s(&times)],
    );
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));

    // A lone frame an hour later.
    let d = dir.path().join("lone");
    let photos = folder(&d, false);
    let mut bytes = fixture("IMG_6960.JPG");
    assert!(replace_all(&mut bytes, b"2017:07:13 15:4", b"2017:07:13 16:4") >= 3);
    std::fs::write(photos.join("IMG_9999.JPG"), bytes).unwrap();
    refused(
        &photos,
        &d,
        &[],
        &["IMG_9999.JPG", "a bracket of one frame", "--skip-single"],
    );
    let o = import(
        &photos,
        &d.join("skipped"),
        &poses(&d),
        &["--clock-offset-s", "0", "--utc-offset", "-07:00", "--skip-single"],
    );
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert!(
        text(&o).contains("left out: ") && text(&o).contains("IMG_9999.JPG"),
        "{}",
        text(&o)
    );

    // The clock: no offset from UTC, no stated clock error.
    let d = dir.path().join("clock");
    let photos = folder(&d, false);
    let o = import(&photos, &d.join("a"), &poses(&d), &["--clock-offset-s", "0"]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(
        text(&o).contains("IMG_6955.JPG: EXIF OffsetTimeOriginal is absent") && text(&o).contains("--utc-offset"),
        "{}",
        text(&o)
    );
    let o = import(&photos, &d.join("b"), &poses(&d), &["--utc-offset", "+02:00"]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("--clock-offset-s is missing"), "{}", text(&o));

    // An output directory that cannot be made (under a file).
    let blocker = d.join("a-file");
    std::fs::write(&blocker, b"x").unwrap();
    let o = import(
        &photos,
        &blocker.join("session"),
        &poses(&d),
        &["--clock-offset-s", "0", "--utc-offset", "-07:00"],
    );
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("a-file"), "{}", text(&o));
    assert!(!text(&o).contains("panicked"), "{}", text(&o));
}

/// A JPEG's bytes without its APP1 (EXIF) segments.
fn strip_app1(bytes: &[u8]) -> Vec<u8> {
    let mut out = bytes[..2].to_vec();
    let mut i = 2;
    while i + 4 <= bytes.len() && bytes[i] == 0xFF {
        let marker = bytes[i + 1];
        if marker == 0xDA {
            break; // start of scan: the rest is image data
        }
        let len = usize::from(u16::from_be_bytes([bytes[i + 2], bytes[i + 3]]));
        if marker != 0xE1 {
            out.extend_from_slice(&bytes[i..i + 2 + len]);
        }
        i += 2 + len;
    }
    out.extend_from_slice(&bytes[i..]);
    out
}

/// `bytes` (a little-endian EXIF JPEG) with its FocalLength rational set to
/// `mm`/1: the entry found by walking IFD0 to the Exif IFD, as the camera
/// wrote them (the file's structure is unchanged).
fn with_focal_length(mut bytes: Vec<u8>, mm: u32) -> Vec<u8> {
    let tiff = bytes.windows(6).position(|w| w == b"Exif\0\0").expect("an EXIF block") + 6;
    assert_eq!(&bytes[tiff..tiff + 2], b"II", "a little-endian EXIF");
    let u16_at = |b: &[u8], o: usize| u16::from_le_bytes([b[tiff + o], b[tiff + o + 1]]) as usize;
    let u32_at = |b: &[u8], o: usize| u32::from_le_bytes(b[tiff + o..tiff + o + 4].try_into().unwrap()) as usize;
    let entry = |b: &[u8], ifd: usize, tag: usize| {
        (0..u16_at(b, ifd))
            .map(|k| ifd + 2 + 12 * k)
            .find(|&e| u16_at(b, e) == tag)
            .expect("the tag")
    };
    let exif_ifd = u32_at(&bytes, entry(&bytes, u32_at(&bytes, 4), 0x8769) + 8);
    let focal = entry(&bytes, exif_ifd, 0x920A);
    assert_eq!(u16_at(&bytes, focal + 2), 5, "FocalLength is a RATIONAL");
    let value = tiff + u32_at(&bytes, focal + 8);
    bytes[value..value + 4].copy_from_slice(&mm.to_le_bytes());
    bytes[value + 4..value + 8].copy_from_slice(&1u32.to_le_bytes());
    bytes
}

/// Photographs at another focal length than most (a zoom lens zoomed in):
/// with a scene, their bracket journals the zoom's focal length in pixels
/// (the camera's, estimated from EXIF at 8 mm, times 32 / 8), and the
/// record says it was estimated; without a scene, or as a sky bracket, they
/// are refused naming the file and what was expected.
#[test]
fn zoom_photographs_journal_their_own_focal_length() {
    let dir = tempfile::tempdir().expect("temp");
    let photos = folder(dir.path(), false);
    for n in 6960..=6966 {
        let mut bytes = with_focal_length(fixture(&format!("IMG_{n}.JPG")), 32);
        assert!(replace_all(&mut bytes, b"2017:07:13 15:4", b"2017:07:13 15:5") >= 3);
        std::fs::write(photos.join(format!("ZOOM_{n}.JPG")), bytes).unwrap();
    }
    let poses = dir.path().join("poses.ron");
    std::fs::write(
        &poses,
        r#"ImportPoses(brackets: [
    (files: "IMG_*.JPG", position_m: (0.0, -20.0, 1.5), azimuth_deg: 180.0, elevation_deg: 10.0),
    (files: "ZOOM_*.JPG", position_m: (0.0, -20.0, 1.5), azimuth_deg: 185.0, elevation_deg: 12.0),
])"#,
    )
    .unwrap();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/campanile-scene.ron");
    let clock = ["--clock-offset-s", "0", "--utc-offset", "-07:00"];
    let with_scene = [&clock[..], &["--scene", s(&scene)]].concat();
    let session = dir.path().join("session");
    let o = import(&photos, &session, &poses, &with_scene);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let journal = std::fs::read_to_string(session.join("journal.jsonl")).unwrap();
    let lines: Vec<serde_json::Value> = journal.lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(lines.len(), 25);
    // The 18 frames at 8 mm are the session's camera (1212.4 px at the
    // frame's 5616 px, estimated from FocalLength and FocalPlaneXResolution);
    // the 7 at 32 mm journal four times that.
    let focal: Vec<Option<f64>> = lines.iter().map(|l| l["meta"]["focal_px"].as_f64()).collect();
    assert!(focal[..18].iter().all(Option::is_none), "{focal:?}");
    for f in &focal[18..] {
        let f = f.expect("a zoom frame's focal length");
        assert!((f - 4.0 * 1212.4).abs() < 0.5, "{f}");
    }
    let record = std::fs::read_to_string(session.join("import.json")).unwrap();
    assert!(
        record.contains("zoom photographs' focal lengths from EXIF: the camera's at 8 mm scaled by FocalLength / 8 mm"),
        "{record}"
    );
    assert!(record.contains("ZOOM_6960.JPG (FocalLength 32 mm)"), "{record}");

    let refused_with = |name: &str, extra: &[&str], want: &[&str]| {
        let o = import(&photos, &dir.path().join(name), &poses, &[&clock[..], extra].concat());
        let t = text(&o);
        assert_eq!(o.status.code(), Some(2), "{t}");
        for w in want {
            assert!(t.contains(w), "{w:?} not in {t}");
        }
    };
    refused_with(
        "no-scene",
        &[],
        &[
            "photographs at 2 focal lengths (most at Some(8.0) mm; ZOOM_6960.JPG at Some(32.0) mm)",
            "give --scene",
        ],
    );
    refused_with(
        "zoomed-sky",
        &["--scene", s(&scene), "--sky", "ZOOM_*"],
        &[
            "ZOOM_6960.JPG",
            "FocalLength",
            "32 mm",
            "sky frames are fitted through the station's lens",
        ],
    );
}
