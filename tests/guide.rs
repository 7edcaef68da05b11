//! The user guide's walkthroughs, run as a user would type them.
//!
//! Each chapter of `docs/guide/` is a Markdown file whose ```` ```sh ````
//! blocks are run in order, by bash with `-e -o pipefail`, in a fresh
//! directory holding links to the repository's `examples/` and
//! `validation/` (as in a clone), with the test's `campanile` first on the
//! PATH. Two HTML comments, invisible on the rendered page, steer the run:
//!
//! - `<!-- guide: exit N -->` before a block: the block must end with
//!   status N (a command that finishes with a failed quality gate exits 3);
//! - `<!-- guide: file NAME -->` before a block of any language: the block
//!   is written to NAME instead of run (a file the reader is asked to make).
//!
//! Blocks in other languages (`text`, `ron`, `json`) are shown, not run.
//! A further test checks that every relative link in the README and the
//! documentation points at a file that exists, and at a heading there.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Command;

/// One block to run or write, with the line it starts on.
#[derive(Debug)]
enum Step {
    Run { line: usize, script: String, exit: i32 },
    Write { line: usize, name: String, text: String },
}

fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The chapter's steps, in order.
fn steps(markdown: &str) -> Vec<Step> {
    let mut out = Vec::new();
    let mut exit = 0;
    let mut file: Option<String> = None;
    let mut lines = markdown.lines().enumerate();
    while let Some((i, line)) = lines.next() {
        let trimmed = line.trim();
        if let Some(rest) = trimmed.strip_prefix("<!-- guide:") {
            let rest = rest.trim_end_matches("-->").trim();
            if let Some(n) = rest.strip_prefix("exit") {
                exit = n.trim().parse().expect("`<!-- guide: exit N -->` takes a number");
            } else if let Some(name) = rest.strip_prefix("file") {
                file = Some(name.trim().to_string());
            } else {
                panic!("line {}: unknown guide directive {trimmed:?}", i + 1);
            }
            continue;
        }
        let Some(lang) = trimmed.strip_prefix("```") else {
            continue;
        };
        let lang = lang.trim().to_string();
        let mut body = String::new();
        for (_, l) in lines.by_ref() {
            if l.trim_start().starts_with("```") {
                break;
            }
            body.push_str(l);
            body.push('\n');
        }
        if let Some(name) = file.take() {
            out.push(Step::Write {
                line: i + 1,
                name,
                text: body,
            });
        } else if lang == "sh" {
            out.push(Step::Run {
                line: i + 1,
                script: body,
                exit,
            });
        }
        exit = 0;
    }
    out
}

/// Runs one chapter's steps; panics naming the chapter, the block's line,
/// the status and the output's tail when a step does not do what the
/// chapter says.
fn run_chapter(name: &str) {
    let path = repo().join("docs/guide").join(name);
    let markdown = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let steps = steps(&markdown);
    assert!(
        steps.iter().any(|s| matches!(s, Step::Run { .. })),
        "{name}: no ```sh block to run"
    );
    let dir = tempfile::tempdir().unwrap();
    for link in ["examples", "validation"] {
        std::os::unix::fs::symlink(repo().join(link), dir.path().join(link)).unwrap();
    }
    let bin_dir = Path::new(env!("CARGO_BIN_EXE_campanile")).parent().unwrap();
    let path_var = format!("{}:{}", bin_dir.display(), std::env::var("PATH").unwrap_or_default());
    for step in &steps {
        match step {
            Step::Write { line, name: file, text } => {
                let target = dir.path().join(file);
                if let Some(parent) = target.parent() {
                    std::fs::create_dir_all(parent).unwrap();
                }
                std::fs::write(&target, text).unwrap_or_else(|e| panic!("{name}:{line}: writing {file}: {e}"));
            }
            Step::Run { line, script, exit } => {
                let started = std::time::Instant::now();
                let out = Command::new("bash")
                    .args(["-e", "-o", "pipefail", "-c", script])
                    .current_dir(dir.path())
                    .env("PATH", &path_var)
                    .env("NO_COLOR", "1")
                    .output()
                    .expect("bash runs");
                let tail = |b: &[u8]| {
                    let s = String::from_utf8_lossy(b).into_owned();
                    let lines: Vec<&str> = s.lines().collect();
                    lines[lines.len().saturating_sub(30)..].join("\n")
                };
                eprintln!("{name}:{line}: {:.1} s", started.elapsed().as_secs_f64());
                assert_eq!(
                    out.status.code(),
                    Some(*exit),
                    "{name}:{line}: the block\n{script}ended with {:?}, the chapter says {exit}\n--- stdout\n{}\n--- stderr\n{}",
                    out.status,
                    tail(&out.stdout),
                    tail(&out.stderr)
                );
            }
        }
    }
}

#[test]
fn merge_a_bracket_from_my_camera() {
    run_chapter("merge-a-bracket.md");
}

#[test]
fn run_a_sky_station_for_a_month() {
    run_chapter("sky-station.md");
}

#[test]
fn capture_and_relight_a_building() {
    run_chapter("building.md");
}

#[test]
fn capture_and_relight_a_room() {
    run_chapter("room.md");
}

#[test]
fn bring_a_radiance_or_blender_scene() {
    run_chapter("other-renderers.md");
}

#[test]
fn test_a_new_pan_tilt_head() {
    run_chapter("pan-tilt-head.md");
}

#[test]
fn from_range_scans_to_a_scene() {
    run_chapter("range-scans.md");
}

#[test]
fn process_a_year_of_archive_on_a_cluster() {
    run_chapter("archive-on-a-cluster.md");
}

/// Every chapter has a test above (a new chapter cannot go unrun).
#[test]
fn every_chapter_is_run() {
    let this = std::fs::read_to_string(repo().join("tests/guide.rs")).unwrap();
    let chapters: Vec<String> = std::fs::read_dir(repo().join("docs/guide"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".md") && n != "README.md")
        .collect();
    assert!(chapters.len() >= 7, "{chapters:?}");
    for chapter in chapters {
        assert!(
            this.contains(&format!("run_chapter(\"{chapter}\")")),
            "docs/guide/{chapter} has no test in tests/guide.rs"
        );
    }
}

/// GitHub's anchor for a heading: lower case, spaces to hyphens, other
/// punctuation dropped.
fn anchor(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter_map(|c| match c {
            ' ' => Some('-'),
            c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c),
            _ => None,
        })
        .collect()
}

fn markdown_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let p = entry.unwrap().path();
        if p.is_dir() {
            markdown_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "md") {
            out.push(p);
        }
    }
}

/// The targets of `[text](target)` links outside code blocks and spans.
fn links(markdown: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut in_code = false;
    for (i, line) in markdown.lines().enumerate() {
        if line.trim_start().starts_with("```") {
            in_code = !in_code;
            continue;
        }
        if in_code {
            continue;
        }
        // Drop code spans, whose brackets are not links.
        let mut text = String::new();
        for (k, part) in line.split('`').enumerate() {
            if k % 2 == 0 {
                text.push_str(part);
            }
        }
        let mut rest = text.as_str();
        while let Some(at) = rest.find("](") {
            let after = &rest[at + 2..];
            let Some(end) = after.find(')') else { break };
            out.push((i + 1, after[..end].to_string()));
            rest = &after[end..];
        }
    }
    out
}

#[test]
fn the_documentation_links_resolve() {
    let mut files = vec![repo().join("README.md"), repo().join("BENCHMARKS.md")];
    markdown_files(&repo().join("docs"), &mut files);
    markdown_files(&repo().join("validation"), &mut files);
    let mut broken = BTreeSet::new();
    let mut checked = 0;
    for file in &files {
        let text = std::fs::read_to_string(file).unwrap();
        for (line, target) in links(&text) {
            if target.starts_with("http://") || target.starts_with("https://") || target.starts_with("mailto:") {
                continue;
            }
            checked += 1;
            let (path_part, fragment) = match target.split_once('#') {
                Some((p, f)) => (p, Some(f)),
                None => (target.as_str(), None),
            };
            let resolved = if path_part.is_empty() {
                file.clone()
            } else {
                file.parent().unwrap().join(path_part)
            };
            let at = format!("{}:{line}: {target}", file.strip_prefix(repo()).unwrap().display());
            if !resolved.exists() {
                broken.insert(format!("{at} (no such file)"));
                continue;
            }
            if let Some(fragment) = fragment
                && resolved.extension().is_some_and(|e| e == "md")
            {
                let headings: BTreeSet<String> = std::fs::read_to_string(&resolved)
                    .unwrap()
                    .lines()
                    .filter_map(|l| l.strip_prefix('#'))
                    .map(|h| anchor(h.trim_start_matches('#')))
                    .collect();
                if !headings.contains(fragment) {
                    broken.insert(format!("{at} (no heading with that anchor)"));
                }
            }
        }
    }
    assert!(checked >= 20, "only {checked} links found: is the guide linked?");
    assert!(
        broken.is_empty(),
        "broken links:\n{}",
        broken.into_iter().collect::<Vec<_>>().join("\n")
    );
}
