//! The server over real sockets, with raw HTTP requests (so that paths
//! reach it exactly as written, `..` and `%2e%2e` included), on a small
//! store written here: a heartbeat, one day's journal, a frame, a
//! keogram.

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::path::Path;
use std::time::Duration;

use campanile_capture::unattended::{Heartbeat, StationState};
use chrono::{NaiveDate, TimeZone, Utc};

use super::{PageServer, ServeOptions};

const TOKEN: &str = "s3cret-token-0123456789";
const DAY: &str = "2026-06-21";

/// A journal line for a frame `n` of scan `scan`, of kind data, with no
/// filter (a sky tile), its file `frames/f{n}.png`.
fn frame_line(scan: u32, n: u32) -> String {
    let t = Utc.with_ymd_and_hms(2026, 6, 21, 8, 0, 0).unwrap() + chrono::Duration::minutes(i64::from(10 * scan));
    serde_json::json!({
        "status": "done", "key": format!("sky@{DAY}#{scan}/s1/t{n}/f1"), "file": format!("frames/f{n}.png"),
        "format": "png", "crc32c": 0, "bytes": 10, "width": 2, "height": 2, "bits": 16, "sequence": n,
        "meta": {"time": t, "kind": "data", "pose_requested": null, "pose_reached": null,
                 "exposure_requested_s": 0.01, "exposure_actual_s": 0.01, "gain_db": 0.0, "filter": null,
                 "lights": null, "temperature_c": null, "late_by_s": null, "notes": []}
    })
    .to_string()
        + "\n"
}

fn write_store(store: &Path, frames: u64) {
    let mut beat = Heartbeat::starting(Utc::now(), None);
    beat.state = StationState::Capturing;
    beat.frames_today = frames;
    beat.day = NaiveDate::from_ymd_opt(2026, 6, 21);
    beat.write(store).unwrap();
    let day = store.join(DAY);
    std::fs::create_dir_all(day.join("processed")).unwrap();
    std::fs::create_dir_all(day.join("frames")).unwrap();
    let mut journal: String = (0..frames as u32).map(|n| frame_line(n / 2, n)).collect();
    // Two shots of scan 9 missed in an outage.
    for t in ["t0", "t1"] {
        let missed = serde_json::json!({"status": "missed", "key": format!("sky@{DAY}#9/s1/{t}/f0"),
            "time": "2026-06-21T12:00:00Z", "reason": "outage: the head is down"});
        journal += &(missed.to_string() + "\n");
    }
    std::fs::write(day.join("journal.jsonl"), journal).unwrap();
    std::fs::write(day.join("processed/keogram.png"), b"\x89PNG not really").unwrap();
    // Only the last frame's file exists (the others were pruned, say).
    let codes: Vec<u16> = (0..12).map(|i| i * 5000).collect();
    image::ImageBuffer::<image::Rgb<u16>, _>::from_raw(2, 2, codes)
        .unwrap()
        .save(day.join(format!("frames/f{}.png", frames - 1)))
        .unwrap();
    std::fs::write(store.join("secret.txt"), "not to be served").unwrap();
}

/// Sends `request` as is; returns the status code and the body.
fn raw(addr: SocketAddr, request: &str) -> (u16, String) {
    let mut s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
    s.write_all(request.as_bytes()).unwrap();
    let mut out = Vec::new();
    let _ = s.read_to_end(&mut out);
    let text = String::from_utf8_lossy(&out).into_owned();
    let code = text.get(9..12).and_then(|c| c.parse().ok()).unwrap_or(0);
    let body = text.split_once("\r\n\r\n").map_or("", |(_, b)| b).to_owned();
    (code, body)
}

fn get(addr: SocketAddr, path: &str, extra: &str) -> (u16, String) {
    raw(
        addr,
        &format!("GET {path} HTTP/1.1\r\nHost: x\r\nConnection: close\r\n{extra}\r\n"),
    )
}

/// A server on a free loopback port, in its own runtime on a thread.
fn start(
    store: &Path,
    token: Option<&str>,
) -> (
    SocketAddr,
    tokio::sync::oneshot::Sender<()>,
    std::thread::JoinHandle<()>,
) {
    let options = ServeOptions {
        store: store.to_path_buf(),
        listen: "127.0.0.1:0".parse().unwrap(),
        token: token.map(str::to_owned),
        poll: Duration::from_millis(50),
    };
    let (addr_tx, addr_rx) = std::sync::mpsc::channel();
    let (stop_tx, stop_rx) = tokio::sync::oneshot::channel::<()>();
    let thread = std::thread::spawn(move || {
        let rt = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(2)
            .enable_all()
            .build()
            .unwrap();
        rt.block_on(async {
            let server = PageServer::bind(options).await.unwrap();
            addr_tx.send(server.local_addr().unwrap()).unwrap();
            server
                .run(async {
                    let _ = stop_rx.await;
                })
                .await
                .unwrap();
        });
    });
    (addr_rx.recv().unwrap(), stop_tx, thread)
}

#[test]
fn bad_requests_get_4xx_and_no_path_leaves_the_day_directory() {
    let tmp = tempfile::tempdir().unwrap();
    write_store(tmp.path(), 4);
    let (addr, stop, thread) = start(tmp.path(), None);

    let (code, body) = get(addr, "/api/state", "");
    assert_eq!(code, 200, "{body}");
    let state: serde_json::Value = serde_json::from_str(&body).unwrap();
    assert_eq!(state["heartbeat"]["frames_today"], 4);
    assert_eq!(state["day"]["date"], DAY);
    assert_eq!(state["day"]["frames"], 4);
    assert_eq!(state["day"]["scans"], 2);
    assert_eq!(state["day"]["latest_sky_frame"]["key"], format!("sky@{DAY}#1/s1/t3/f1"));
    assert_eq!(state["day"]["missed_shots"], 2);
    assert_eq!(state["day"]["missed_scans_total"], 1);
    assert_eq!(state["day"]["missed"][0]["occurrence"], format!("sky@{DAY}#9"));
    assert_eq!(state["day"]["missed"][0]["shots"], 2);
    let (code, body) = get(addr, &format!("/day/{DAY}/keogram.png"), "");
    assert_eq!((code, body.as_str()), (200, "\u{fffd}PNG not really"));
    assert_eq!(get(addr, "/", "").0, 200);
    let mut s = TcpStream::connect(addr).unwrap();
    s.write_all(format!("GET /day/{DAY}/latest.png HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n").as_bytes())
        .unwrap();
    let mut reply = Vec::new();
    s.read_to_end(&mut reply).unwrap();
    let at = reply.windows(4).position(|w| w == b"\r\n\r\n").unwrap() + 4;
    let preview = image::load_from_memory(&reply[at..]).unwrap().to_rgb8();
    assert_eq!(preview.dimensions(), (2, 2));
    // Codes 0, 5000 … 55000: the 99th percentile is 50000 (index 10 of
    // 12), so the last pixel's 45000, 50000, 55000 are 221 (220.5 rounded up), 245, 255.
    assert_eq!(preview.get_pixel(1, 1).0, [221, 245, 255]);
    assert_eq!(preview.get_pixel(0, 0).0, [0, 25, 49]);
    assert_eq!(get(addr, "/api/days", "").1, format!("[\"{DAY}\"]"));

    for (path, want) in [
        ("/day/..%2Fsecret.txt/keogram.png", 400),
        ("/day/%2e%2e/keogram.png", 400),
        ("/day/%2E%2E%2F%2E%2E%2Fetc%2Fpasswd/latest.png", 400),
        ("/api/day/%2Fetc%2Fpasswd", 400),
        ("/api/day/2026-02-30", 400),
        ("/api/day/%ff%fe", 400),
        ("/day/../secret.txt", 404),
        ("/../secret.txt", 404),
        ("/%2e%2e/secret.txt", 404),
        ("//etc/passwd", 404),
        ("/etc/passwd", 404),
        ("/day/2026-06-22/keogram.png", 404),
        ("/day/2026-06-21/../../secret.txt", 404),
        ("/day/2026-06-21/journal.jsonl", 404),
    ] {
        let (code, body) = get(addr, path, "");
        assert_eq!(code, want, "{path}: {body}");
        assert!(
            !body.contains("not to be served") && !body.contains("root:"),
            "{path}: {body}"
        );
    }
    // An absolute URI as the request target, a wrong method, garbage.
    let (code, _) = raw(
        addr,
        "GET http://x/../secret.txt HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n",
    );
    assert_eq!(code, 404);
    let (code, _) = raw(
        addr,
        "POST /api/state HTTP/1.1\r\nHost: x\r\nContent-Length: 0\r\nConnection: close\r\n\r\n",
    );
    assert_eq!(code, 405);
    let (code, _) = raw(addr, "NOT HTTP AT ALL\r\n\r\n");
    assert_eq!(code, 400);
    // Still serving.
    assert_eq!(get(addr, "/api/state", "").0, 200);
    stop.send(()).unwrap();
    thread.join().unwrap();
}

#[test]
fn with_a_token_every_route_needs_it() {
    let tmp = tempfile::tempdir().unwrap();
    write_store(tmp.path(), 2);
    let (addr, stop, thread) = start(tmp.path(), Some(TOKEN));
    for path in [
        "/",
        "/api/state",
        "/events",
        &format!("/day/{DAY}/keogram.png"),
        "/no/such",
    ] {
        let (code, body) = get(addr, path, "");
        assert_eq!(code, 401, "{path}: {body}");
        assert!(body.contains("needs its token"), "{body}");
        assert_eq!(get(addr, &format!("{path}?token=wrong-token-0123456789"), "").0, 401);
    }
    assert_eq!(get(addr, &format!("/api/state?token={TOKEN}"), "").0, 200);
    assert_eq!(
        get(addr, "/api/state", &format!("Authorization: Bearer {TOKEN}\r\n")).0,
        200
    );
    assert_eq!(
        get(addr, &format!("/day/{DAY}/keogram.png?v=1&token={TOKEN}"), "").0,
        200
    );
    assert_eq!(get(addr, &format!("/nowhere?token={TOKEN}"), "").0, 404);
    stop.send(()).unwrap();
    thread.join().unwrap();
}

#[test]
fn a_new_frame_is_pushed_on_the_event_stream() {
    let tmp = tempfile::tempdir().unwrap();
    write_store(tmp.path(), 2);
    let (addr, stop, thread) = start(tmp.path(), None);
    let mut s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(20))).unwrap();
    s.write_all(b"GET /events HTTP/1.1\r\nHost: x\r\n\r\n").unwrap();
    // Reads until `n` `state` events have come; returns their data lines.
    let mut seen = String::new();
    let mut events = |n: usize| -> Vec<serde_json::Value> {
        let mut buf = [0u8; 65536];
        loop {
            let data: Vec<serde_json::Value> = seen
                .lines()
                .filter_map(|l| l.strip_prefix("data: "))
                .filter_map(|d| serde_json::from_str(d).ok())
                .collect();
            if data.len() >= n {
                return data;
            }
            let k = s.read(&mut buf).expect("an event within 20 s");
            assert!(k > 0, "the stream ended: {seen}");
            seen.push_str(&String::from_utf8_lossy(&buf[..k]));
        }
    };
    let first = events(1);
    assert_eq!(first[0]["day"]["frames"], 2);
    // The station lands frames 2 and 3 (a new scan) and rewrites its heartbeat.
    let day = tmp.path().join(DAY);
    let mut journal = std::fs::OpenOptions::new()
        .append(true)
        .open(day.join("journal.jsonl"))
        .unwrap();
    journal
        .write_all((frame_line(1, 2) + &frame_line(1, 3)).as_bytes())
        .unwrap();
    drop(journal);
    let mut beat = Heartbeat::read(tmp.path()).unwrap();
    beat.frames_today = 4;
    beat.write(tmp.path()).unwrap();
    let after = loop {
        let all = events(first.len() + 1);
        let last = all.last().unwrap().clone();
        if last["day"]["frames"] == 4 && last["heartbeat"]["frames_today"] == 4 {
            break last;
        }
        let n = all.len();
        let _ = events(n + 1);
    };
    assert_eq!(after["day"]["scans"], 2);
    assert!(seen.contains("event: state"), "{seen}");
    drop(s);
    stop.send(()).unwrap();
    thread.join().unwrap();
}
