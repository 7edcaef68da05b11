//! A sky archive processed on a real Slurm cluster (issue 29): Debian's
//! `slurm-wlm` and `munge` (installed by `.ci/run`), started here as a
//! one-node cluster by `deploy/slurm/one-node.sh` (munged, slurmctld and
//! slurmd on ports of their own, stopped by their PIDs when the test ends,
//! pass or fail), and `deploy/slurm/submit.sh`: one array job of
//! days × shards tasks (`campanile process DAY --shard K/N`) and a merge job
//! that runs when every task has succeeded (`--merge-shards`).
//!
//! The archive: the example sky station (`examples/sky-station.ron`, a sun
//! triplet and a sky scan, here every 2 hours for 2 days) captured by
//! `station run` on the 64×48 `examples/sky-sim-station.ron`; the response
//! given is the simulator's own (the plan has no calibration bracket).
//! Each merged day must be byte-equal, file by file, to the unsharded
//! `campanile process DAY --out …` of the same day (18 files a day: the
//! per-scan records, the series (CSV and Parquet), the extinction CSV, plots, keograms, the
//! response, the verdicts), except the report page, which also says what
//! the run itself processed (a merge processes nothing).
//!
//! `CAMPANILE_KEEP_RESPONSE=FILE` keeps the response CSV (for the
//! throughput bench in BENCHMARKS.md, "Sky time series").

mod common;
mod sim_response;

use std::collections::BTreeMap;
use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use common::campanile;

const SHARDS: usize = 2;

/// Files of a processed day that record the run, not only the products:
/// the report page has a section on the scans this run processed (none
/// in a merge).
const RUN_RECORDS: [&str; 1] = ["report.html"];

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// A one-node Slurm cluster under `dir`; stopped (by PID) when dropped.
struct Cluster {
    dir: PathBuf,
    conf: PathBuf,
}

impl Cluster {
    fn start(dir: &Path) -> Cluster {
        // Two free ports for slurmctld and slurmd.
        let ports: Vec<u16> = (0..2)
            .map(|_| TcpListener::bind("127.0.0.1:0").unwrap())
            .collect::<Vec<_>>()
            .iter()
            .map(|l| l.local_addr().unwrap().port())
            .collect();
        let out = Command::new(root().join("deploy/slurm/one-node.sh"))
            .args(["start", dir.to_str().unwrap()])
            .args(ports.iter().map(u16::to_string))
            .output()
            .expect("deploy/slurm/one-node.sh runs");
        let cluster = Cluster {
            dir: dir.to_path_buf(),
            conf: dir.join("slurm.conf"),
        };
        assert!(
            out.status.success(),
            "one-node Slurm did not start (Debian's slurm-wlm and munge are needed: .ci/run installs them)\nstdout:\n{}\nstderr:\n{}",
            text(&out.stdout),
            text(&out.stderr)
        );
        cluster
    }

    /// Runs a Slurm client command against this cluster; its stdout.
    fn run(&self, program: &str, args: &[&str]) -> String {
        let out = Command::new(program)
            .args(args)
            .env("SLURM_CONF", &self.conf)
            .output()
            .unwrap_or_else(|e| panic!("{program}: {e}"));
        assert!(
            out.status.success(),
            "{program} {args:?}: {}\n{}",
            text(&out.stdout),
            text(&out.stderr)
        );
        text(&out.stdout)
    }
}

impl Drop for Cluster {
    fn drop(&mut self) {
        let _ = Command::new(root().join("deploy/slurm/one-node.sh"))
            .args(["stop", self.dir.to_str().unwrap()])
            .status();
    }
}

/// Every file under `dir` (relative path → bytes), without the run records.
fn files(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                let rel = p.strip_prefix(dir).unwrap().to_string_lossy().into_owned();
                if !RUN_RECORDS.contains(&rel.as_str()) {
                    out.insert(rel, std::fs::read(&p).unwrap());
                }
            }
        }
    }
    out
}

/// The day directories of a station store, in date order.
fn days(store: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(store)
        .unwrap()
        .filter_map(|e| {
            let e = e.unwrap();
            let name = e.file_name().to_string_lossy().into_owned();
            (e.path().is_dir() && name.len() == 10 && name.as_bytes()[4] == b'-').then_some(name)
        })
        .collect();
    v.sort();
    v
}

/// `scontrol show job ID`'s JobState of every record (array tasks included).
fn job_states(cluster: &Cluster, id: &str) -> Vec<String> {
    cluster
        .run("scontrol", &["show", "job", id])
        .split_whitespace()
        .filter_map(|w| w.strip_prefix("JobState=").map(str::to_string))
        .collect()
}

#[test]
fn a_slurm_array_over_a_sky_archive_merges_byte_equal_to_the_unsharded_run() {
    let tmp = tempfile::tempdir().unwrap();
    let sim_response::TwoDaySkyStation {
        plan,
        station_path,
        response,
        ..
    } = sim_response::two_day_sky_station(tmp.path());
    let store = tmp.path().join("store");
    let o = campanile(&[
        "-q",
        "station",
        "run",
        "--sim-bounces",
        "1",
        plan.to_str().unwrap(),
        "--station",
        station_path.to_str().unwrap(),
        "--store",
        store.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let days = days(&store);
    assert_eq!(days.len(), 2, "{days:?}");
    // For the throughput bench (BENCHMARKS.md, "Sky time series"): the
    // simulator's response CSV, kept where CAMPANILE_KEEP_RESPONSE says.
    if let Some(keep) = std::env::var_os("CAMPANILE_KEEP_RESPONSE") {
        std::fs::copy(&response, keep).unwrap();
    }

    // The unsharded run of each day.
    let unsharded = tmp.path().join("unsharded");
    for day in &days {
        let o = campanile(&[
            "-q",
            "process",
            store.join(day).to_str().unwrap(),
            "--response",
            response.to_str().unwrap(),
            "--out",
            unsharded.join(day).to_str().unwrap(),
        ]);
        assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    }

    // The same archive through Slurm.
    let cluster = Cluster::start(&tmp.path().join("slurm"));
    let out = tmp.path().join("slurm-out");
    let submitted = Command::new(root().join("deploy/slurm/submit.sh"))
        .args([
            store.to_str().unwrap(),
            out.to_str().unwrap(),
            "--shards",
            &SHARDS.to_string(),
            "--response",
            response.to_str().unwrap(),
            "--campanile",
            env!("CARGO_BIN_EXE_campanile"),
        ])
        .env("SLURM_CONF", &cluster.conf)
        .output()
        .unwrap();
    assert!(submitted.status.success(), "{}", text(&submitted.stderr));
    let ids: Vec<String> = text(&submitted.stdout).split_whitespace().map(str::to_string).collect();
    assert_eq!(ids.len(), 2, "submit.sh printed {ids:?}");
    let (array, merge) = (&ids[0], &ids[1]);
    let start = Instant::now();
    loop {
        let queued = cluster.run("squeue", &["-h", "-j", &format!("{array},{merge}")]);
        if queued.trim().is_empty() {
            break;
        }
        assert!(
            start.elapsed() < Duration::from_secs(900),
            "jobs still queued after 15 min:\n{queued}"
        );
        std::thread::sleep(Duration::from_millis(500));
    }
    let logs = || {
        std::fs::read_dir(out.join("logs"))
            .map(|d| {
                d.filter_map(|e| {
                    let p = e.ok()?.path();
                    Some(format!("{}:\n{}", p.display(), std::fs::read_to_string(&p).ok()?))
                })
                .collect::<Vec<_>>()
                .join("\n")
            })
            .unwrap_or_default()
    };
    let tasks = job_states(&cluster, array);
    assert_eq!(tasks.len(), days.len() * SHARDS, "{tasks:?}");
    assert!(
        tasks.iter().all(|s| s == "COMPLETED"),
        "array tasks: {tasks:?}\n{}",
        logs()
    );
    assert_eq!(job_states(&cluster, merge), ["COMPLETED"], "{}", logs());
    eprintln!(
        "Slurm: {} tasks and the merge in {:.1} s",
        tasks.len(),
        start.elapsed().as_secs_f64()
    );

    // Each shard processed some of the day's scans, and together all of them.
    for day in &days {
        let whole = files(&unsharded.join(day));
        let scans = whole.keys().filter(|k| k.starts_with("scans/")).count();
        assert!(scans >= 5, "{day}: {scans} scans");
        let per_shard: Vec<usize> = (1..=SHARDS)
            .map(|k| {
                std::fs::read_dir(out.join("shards").join(day).join(k.to_string()).join("scans"))
                    .map(|d| d.count())
                    .unwrap_or(0)
            })
            .collect();
        assert_eq!(per_shard.iter().sum::<usize>(), scans, "{day}: {per_shard:?}");
        assert!(per_shard.iter().all(|&n| n > 0), "{day}: {per_shard:?}");
        for name in RUN_RECORDS {
            assert!(
                out.join(day).join(name).is_file() && unsharded.join(day).join(name).is_file(),
                "{day}/{name} missing"
            );
        }
        // The merged day against the unsharded one, byte for byte.
        let merged = files(&out.join(day));
        let names = |m: &BTreeMap<String, Vec<u8>>| m.keys().cloned().collect::<Vec<_>>();
        assert_eq!(names(&merged), names(&whole), "{day}: the files differ");
        for (name, bytes) in &whole {
            assert!(merged[name] == *bytes, "{day}/{name} differs from the unsharded run");
        }
        eprintln!(
            "{day}: {scans} scans in shards of {per_shard:?}; {} files byte-equal",
            whole.len()
        );
    }
}
