//! `campanile station serve` in a real browser (issue 29): a simulated sky
//! station (the example plan every 2 hours on the 64×48 camera, processing
//! each scan) runs its first day; the page is served and opened in
//! headless Chromium, driven over the DevTools protocol on a pipe (no
//! WebDriver, no extra crate); the page must show the heartbeat, the day,
//! the processed scans, the keogram and the latest frame. Then the station
//! runs its second day, with the head down for 3 hours; the page must show
//! the new day, its frames, scans, outage and missed shots, pushed by the
//! server without a reload.
//!
//! Needs Chromium (`/usr/bin/chromium`, Debian's `chromium`, which
//! `.ci/run` installs); without it the test fails and says so. With
//! `CAMPANILE_SCREENSHOTS=1` it also writes the final screenshot into
//! `docs/guide/station-page.png` (both are always written under `target/`).

mod common;
mod sim_response;

use std::io::{BufRead, BufReader, Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, ChildStdout, Command, Stdio};
use std::time::{Duration, Instant};

use base64::Engine;
use campanile_capture::unattended::Heartbeat;
use serde_json::{Value, json};

const CHROMIUM: &str = "/usr/bin/chromium";

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Chromium driven over `--remote-debugging-pipe`: commands on its fd 3,
/// answers on its fd 4, each message JSON ended by a NUL byte.
struct Browser {
    child: Child,
    to: ChildStdin,
    from: BufReader<ChildStdout>,
    next_id: u64,
    session: Option<String>,
}

impl Browser {
    fn launch(profile: &Path) -> Browser {
        assert!(
            Path::new(CHROMIUM).exists(),
            "{CHROMIUM} not found: this test opens the page in headless Chromium (Debian: apt-get install chromium; .ci/run installs it)"
        );
        // The shell hands the pipes to Chromium as fds 3 and 4.
        let child = Command::new("sh")
            .arg("-c")
            .arg(r#"exec "$0" "$@" 3<&0 4>&1 0</dev/null 1>/dev/null"#)
            .arg(CHROMIUM)
            .args([
                "--headless",
                "--no-sandbox",
                "--disable-gpu",
                "--disable-quic",
                "--no-first-run",
                "--disable-background-networking",
                "--disable-component-update",
                "--disable-sync",
                "--hide-scrollbars",
                "--remote-debugging-pipe",
                &format!("--user-data-dir={}", profile.display()),
                "about:blank",
            ])
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .unwrap_or_else(|e| panic!("{CHROMIUM}: {e}"));
        let mut child = child;
        let to = child.stdin.take().unwrap();
        let from = BufReader::new(child.stdout.take().unwrap());
        Browser {
            child,
            to,
            from,
            next_id: 1,
            session: None,
        }
    }

    /// Sends a command (to the page's session once attached) and returns
    /// its result; events in between are skipped.
    fn call(&mut self, method: &str, params: Value) -> Value {
        let id = self.next_id;
        self.next_id += 1;
        let mut msg = json!({"id": id, "method": method, "params": params});
        if let Some(s) = &self.session {
            msg["sessionId"] = json!(s);
        }
        let mut bytes = msg.to_string().into_bytes();
        bytes.push(0);
        self.to.write_all(&bytes).unwrap();
        self.to.flush().unwrap();
        loop {
            let mut buf = Vec::new();
            let n = self.from.read_until(0, &mut buf).unwrap();
            assert!(n > 0, "Chromium closed its pipe during {method}");
            buf.pop();
            let answer: Value = serde_json::from_slice(&buf).unwrap();
            if answer["id"] == json!(id) {
                assert!(answer.get("error").is_none(), "{method}: {answer}");
                return answer["result"].clone();
            }
        }
    }

    /// Opens `url` in a new tab of 1280 × 900 and attaches to it.
    fn open(&mut self, url: &str) {
        let target = self.call("Target.createTarget", json!({"url": url}));
        let target_id = target["targetId"].as_str().unwrap().to_owned();
        let attached = self.call("Target.attachToTarget", json!({"targetId": target_id, "flatten": true}));
        self.session = Some(attached["sessionId"].as_str().unwrap().to_owned());
        self.call(
            "Emulation.setDeviceMetricsOverride",
            json!({"width": 1280, "height": 900, "deviceScaleFactor": 1, "mobile": false}),
        );
    }

    /// The value of a JavaScript expression in the page.
    fn eval(&mut self, expression: &str) -> Value {
        let r = self.call(
            "Runtime.evaluate",
            json!({"expression": expression, "returnByValue": true}),
        );
        r["result"]["value"].clone()
    }

    /// What the page shows: the text of the elements the checks read.
    fn shown(&mut self) -> Value {
        self.eval(
            r#"JSON.stringify({
                state: document.getElementById('state').textContent,
                day: document.getElementById('day').textContent,
                frames: document.getElementById('frames-today').textContent,
                scans: document.getElementById('scans-today').textContent,
                series: document.getElementById('series-caption').textContent,
                plots: document.querySelectorAll('#plots svg').length,
                outages: document.getElementById('outages').textContent,
                missed: document.getElementById('missed-caption').textContent,
                latest: document.getElementById('latest-caption').textContent,
                keogram_px: document.getElementById('keogram').naturalWidth,
                latest_px: document.getElementById('latest').naturalWidth,
                live: document.getElementById('live').textContent,
                updates: Number(document.body.dataset.updates),
                mark: window.campanileTestMark || null,
            })"#,
        )
        .as_str()
        .map(|s| serde_json::from_str(s).unwrap())
        .unwrap_or(Value::Null)
    }

    /// Waits up to 60 s for the page to show what `ok` accepts.
    fn wait_for(&mut self, what: &str, ok: impl Fn(&Value) -> bool) -> Value {
        let deadline = Instant::now() + Duration::from_secs(60);
        loop {
            let shown = self.shown();
            if ok(&shown) {
                return shown;
            }
            assert!(Instant::now() < deadline, "the page never showed {what}: {shown:#}");
            std::thread::sleep(Duration::from_millis(100));
        }
    }

    /// A PNG of the whole page.
    fn screenshot(&mut self) -> Vec<u8> {
        let shot = self.call(
            "Page.captureScreenshot",
            json!({"format": "png", "captureBeyondViewport": true}),
        );
        base64::engine::general_purpose::STANDARD
            .decode(shot["data"].as_str().unwrap())
            .unwrap()
    }
}

impl Drop for Browser {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// `campanile station serve` on a free loopback port; its URL.
struct Server(Child);

impl Server {
    fn start(store: &Path) -> (Server, String) {
        let mut child = Command::new(env!("CARGO_BIN_EXE_campanile"))
            .args([
                "station",
                "serve",
                store.to_str().unwrap(),
                "--listen",
                "127.0.0.1:0",
                "--poll-ms",
                "100",
            ])
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .unwrap();
        let mut line = String::new();
        BufReader::new(child.stdout.take().unwrap())
            .read_line(&mut line)
            .unwrap();
        let url = line
            .split_whitespace()
            .find(|w| w.starts_with("http://"))
            .unwrap_or_else(|| panic!("no URL in {line:?}"))
            .to_owned();
        (Server(child), url)
    }

    /// SIGTERM: the server must stop on its own, with status 0.
    fn stop(mut self) {
        let pid = self.0.id().to_string();
        assert!(Command::new("kill").args(["-TERM", &pid]).status().unwrap().success());
        let deadline = Instant::now() + Duration::from_secs(20);
        loop {
            if let Some(status) = self.0.try_wait().unwrap() {
                assert_eq!(status.code(), Some(0), "station serve after SIGTERM");
                return;
            }
            assert!(Instant::now() < deadline, "station serve did not stop on SIGTERM");
            std::thread::sleep(Duration::from_millis(50));
        }
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        if self.0.try_wait().ok().flatten().is_none() {
            let _ = self.0.kill();
            let _ = self.0.wait();
        }
    }
}

/// Rows of a day's processed sky series.
fn series_rows(store: &Path, day: &str) -> usize {
    let text = std::fs::read_to_string(store.join(day).join("processed/sky-series.csv")).unwrap();
    text.lines().filter(|l| !l.starts_with('#')).count() - 1
}

/// Writes the screenshot under cargo's temporary directory for tests
/// (`CARGO_TARGET_TMPDIR`, wherever the target directory is), and the guide's one into
/// `docs/guide/` too when `CAMPANILE_SCREENSHOTS` is set.
fn keep_screenshot(name: &str, png: &[u8], in_guide: bool) {
    let target = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    std::fs::write(&target, png).unwrap();
    if in_guide && std::env::var_os("CAMPANILE_SCREENSHOTS").is_some() {
        std::fs::write(root().join("docs/guide").join(name), png).unwrap();
    }
    println!("screenshot {} ({} bytes)", target.display(), png.len());
}

#[test]
fn the_page_shows_the_station_and_follows_a_new_day_without_reload() {
    let tmp = tempfile::tempdir().unwrap();
    let station = sim_response::two_day_sky_station(tmp.path());
    let store = tmp.path().join("store");
    let run = |days: &str, extra: &[&str]| {
        let mut args = vec![
            "-q",
            "station",
            "run",
            "--sim-bounces",
            "1",
            station.plan.to_str().unwrap(),
            "--station",
            station.station_path.to_str().unwrap(),
            "--store",
            store.to_str().unwrap(),
            "--process",
            "--response",
            station.response.to_str().unwrap(),
            "--days",
            days,
        ];
        args.extend_from_slice(extra);
        let out = common::campanile(&args);
        assert!(
            out.status.success(),
            "station run {args:?}\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
    };

    // Day 1.
    run("1", &[]);
    let beat = Heartbeat::read(&store).unwrap();
    let rows1 = series_rows(&store, "2026-06-21");
    assert!(rows1 >= 3, "{rows1} scans processed on day 1");
    let (server, url) = Server::start(&store);
    let mut browser = Browser::launch(&tmp.path().join("chromium-profile"));
    browser.open(&url);
    let frames1 = beat.frames_today.to_string();
    let shown = browser.wait_for("day 1", |s| {
        s["state"] == "finished"
            && s["day"] == "2026-06-21"
            && s["frames"] == frames1.as_str()
            && s["series"].as_str().is_some_and(|t| t.starts_with(&format!("{rows1} processed scans")))
            // The keogram's cells are 4 px wide, one per processed scan.
            && s["keogram_px"] == 4 * rows1
            && s["latest_px"] == 64
            && s["live"] == "live"
    });
    println!("day 1 on the page: {shown:#}");
    assert!(shown["plots"].as_u64().unwrap() >= 5, "{shown:#}");
    assert_eq!(shown["missed"], "no shot missed today");
    let updates = shown["updates"].as_u64().unwrap();
    browser.eval("window.campanileTestMark = 'this page, not reloaded'");
    keep_screenshot("station-page-day1.png", &browser.screenshot(), false);

    // Day 2, its head down for 3 hours from an hour after day 1's first
    // frame's time of day (scans every 2 hours: one or two are missed).
    let first_frame = std::fs::read_to_string(store.join("2026-06-21/journal.jsonl"))
        .unwrap()
        .lines()
        .find_map(|l| {
            serde_json::from_str::<Value>(l).ok()?["meta"]["time"]
                .as_str()
                .map(str::to_owned)
        })
        .unwrap();
    let start = chrono::DateTime::parse_from_rfc3339(&first_frame).unwrap()
        + chrono::Duration::days(1)
        + chrono::Duration::hours(1);
    let outage = format!(
        "head:{}:10800",
        start.to_utc().to_rfc3339_opts(chrono::SecondsFormat::Secs, true)
    );
    run("2", &["--sim-outage", &outage]);
    let beat = Heartbeat::read(&store).unwrap();
    let rows2 = series_rows(&store, "2026-06-22");
    let frames2 = beat.frames_today.to_string();
    let shown = browser.wait_for("day 2", |s| {
        s["day"] == "2026-06-22"
            && s["state"] == "finished"
            && s["frames"] == frames2.as_str()
            && s["keogram_px"] == 4 * rows2
            && s["series"]
                .as_str()
                .is_some_and(|t| t.starts_with(&format!("{rows2} processed scan")))
            && s["outages"].as_str().is_some_and(|t| t.contains("head"))
            && s["missed"]
                .as_str()
                .is_some_and(|t| t.contains("missed today, in") && t.ends_with(":"))
            && s["latest"].as_str().is_some_and(|t| t.contains("sky@2026-06-22"))
    });
    println!("day 2 on the page: {shown:#}");
    assert_eq!(shown["mark"], "this page, not reloaded");
    assert!(shown["updates"].as_u64().unwrap() > updates, "{shown:#}");
    keep_screenshot("station-page.png", &browser.screenshot(), true);

    browser.session = None;
    let _ = browser.call("Browser.close", json!({}));
    let mut rest = Vec::new();
    let _ = browser.from.read_to_end(&mut rest);
    server.stop();
}

#[test]
fn serving_off_loopback_without_a_token_or_without_a_store_is_bad_input() {
    let out = common::campanile(&["station", "serve", "examples", "--listen", "0.0.0.0:0"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("--listen 0.0.0.0:0: not a loopback address; serving on a network needs --token"),
        "{stderr}"
    );
    let out = common::campanile(&["station", "serve", "no-such-store"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("no-such-store: not a directory"), "{stderr}");
    let out = common::campanile(&["station", "serve", "examples", "--token", "short"]);
    assert_eq!(out.status.code(), Some(2));
}
