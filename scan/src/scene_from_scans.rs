//! Range scans to a scene directory, the work of `campanile segment`:
//! read the scans ([`crate::read`]), segment them ([`crate::segment`],
//! thesis §2.3), mesh every group and write the OBJ, the scene skeleton and
//! the coloured points ([`crate::reconstruction`], §2.4), then the reports.
//!
//! Besides what [`crate::reconstruction`] writes, the directory holds:
//!
//! - `segment-report.json`: the segmenter's [`SegmentReport`] (parameters
//!   chosen and why, splits accepted and refused with their Ncut and
//!   NWAcut, groups, targets, time per stage, verdict);
//! - `groups-N.png`: scan N drawn with its points in their groups' colours
//!   ([`crate::group_view`]);
//! - `report.html`: one page with the verdicts, the figures and the views.
//!
//! The run's verdict is the worse of the segmentation's and the meshes'.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::cloud::Scan;
use crate::group_view::group_view;
use crate::mesh::MeshOptions;
use crate::read::{ReadError, read_scan};
use crate::reconstruction::{ReconstructionError, ReconstructionReport, reconstruct};
use crate::segment::params::Overrides;
use crate::segment::{Progress, SegmentError, SegmentReport, Verdict, segment};
use crate::segmentation::Segmentation;

/// What to read, how to segment and mesh it, and where to write.
#[derive(Debug, Clone, Default)]
pub struct SceneRequest {
    /// Scan files (PLY, E57, LAS/LAZ), registered in one scene frame.
    pub scans: Vec<PathBuf>,
    /// The segmenter's parameters the user fixed (the rest are derived).
    pub overrides: Overrides,
    /// Meshing options (with the true geometry, when measuring).
    pub mesh: MeshOptions,
    /// The output directory.
    pub out: PathBuf,
}

/// What a run made.
#[derive(Debug, Clone)]
pub struct SceneRun {
    /// The segmenter's report.
    pub segmentation: SegmentReport,
    /// The meshes' report.
    pub meshes: ReconstructionReport,
    /// The worse of the two verdicts.
    pub verdict: Verdict,
    /// Points read, per scan.
    pub points: Vec<usize>,
    /// Every file written.
    pub files: Vec<PathBuf>,
}

/// Why a run stopped.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// No scan file was given.
    #[error("no scan files given (expected one or more PLY, E57 or LAS/LAZ files)")]
    NoScans,
    /// A scan file could not be read.
    #[error(transparent)]
    Read(#[from] ReadError),
    /// Segmentation could not run.
    #[error(transparent)]
    Segment(#[from] SegmentError),
    /// The meshes or their files could not be made.
    #[error(transparent)]
    Reconstruct(#[from] ReconstructionError),
    /// A report could not be written.
    #[error("{}: {message}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
}

impl SceneError {
    /// Whether the caller's input is at fault (exit 2) rather than the
    /// work (exit 1).
    pub fn is_bad_input(&self) -> bool {
        match self {
            SceneError::NoScans | SceneError::Read(_) => true,
            SceneError::Segment(_) => true,
            SceneError::Reconstruct(e) => e.is_bad_input(),
            SceneError::Io { .. } => false,
        }
    }
}

fn io(path: &Path, e: impl std::fmt::Display) -> SceneError {
    SceneError::Io {
        path: path.to_path_buf(),
        message: e.to_string(),
    }
}

/// Reads, segments and meshes `request.scans` into `request.out`;
/// `progress` hears of each file read and each of the segmenter's stages.
pub fn scene_from_scans(request: &SceneRequest, progress: &(dyn Fn(Progress) + Sync)) -> Result<SceneRun, SceneError> {
    if request.scans.is_empty() {
        return Err(SceneError::NoScans);
    }
    let mut scans: Vec<Scan> = Vec::new();
    for (i, path) in request.scans.iter().enumerate() {
        progress(Progress {
            stage: "reading",
            done: i,
            total: request.scans.len(),
        });
        scans.extend(read_scan(path)?);
    }
    let (segmentation, report) = segment(&scans, &request.overrides, progress)?;
    progress(Progress {
        stage: "meshing",
        done: 0,
        total: 1,
    });
    let meshes = reconstruct(&scans, &segmentation, &request.mesh, &request.out)?;
    let mut files = meshes.files.clone();

    let json = request.out.join("segment-report.json");
    let text = serde_json::to_string_pretty(&report).map_err(|e| io(&json, e))?;
    std::fs::write(&json, text).map_err(|e| io(&json, e))?;
    files.push(json);
    let views = write_views(&scans, &segmentation, &request.out)?;
    files.extend(views.iter().cloned());

    let verdict = meshes.verdict.max(report.verdict);
    let mut run = SceneRun {
        segmentation: report,
        meshes,
        verdict,
        points: scans.iter().map(Scan::len).collect(),
        files,
    };
    let page = request.out.join("report.html");
    std::fs::write(&page, report_page(&run, &request.scans, &views)).map_err(|e| io(&page, e))?;
    run.files.push(page);
    Ok(run)
}

/// `groups-N.png` for every scan.
fn write_views(scans: &[Scan], segmentation: &Segmentation, out: &Path) -> Result<Vec<PathBuf>, SceneError> {
    let mut written = Vec::new();
    for (i, (scan, labels)) in scans.iter().zip(&segmentation.labels).enumerate() {
        if let Some(img) = group_view(scan, labels) {
            let path = out.join(format!("groups-{i}.png"));
            img.save(&path).map_err(|e| io(&path, e))?;
            written.push(path);
        }
    }
    Ok(written)
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}

fn verdict_text(v: Verdict) -> &'static str {
    match v {
        Verdict::Ok => "ok",
        Verdict::Poor => "poor",
        Verdict::Failed => "failed",
    }
}

/// The report page: verdicts, parameters, groups and their meshes, targets,
/// stage times, and each scan's view.
fn report_page(run: &SceneRun, inputs: &[PathBuf], views: &[PathBuf]) -> String {
    let s = &run.segmentation;
    let m = &run.meshes;
    let mut h = String::new();
    let _ = write!(
        h,
        "<!doctype html><meta charset=utf-8><title>campanile segment</title>\
         <style>body{{font:14px sans-serif;margin:2em}}td,th{{padding:2px 8px;text-align:left}}\
         img{{max-width:100%;image-rendering:pixelated;border:1px solid #ccc}}</style>\
         <h1>Range scans to a scene: {}</h1>",
        verdict_text(run.verdict)
    );
    let _ = write!(
        h,
        "<p>Segmentation <b>{}</b>: {} groups from {} points ({} unassigned), {}.<br>Meshes <b>{}</b>: \
         {} triangles ({} before simplification); {} planar, {} spheres, {} from scan order, {} height fields, {} ball pivoting, {} skipped.</p>",
        verdict_text(s.verdict),
        s.groups,
        s.points,
        s.unassigned,
        escape(&s.verdict_reason),
        verdict_text(m.verdict),
        m.triangles_after,
        m.triangles_before,
        m.planar,
        m.spheres,
        m.scan_grid,
        m.height_field,
        m.ball_pivoting,
        m.skipped
    );
    h.push_str("<h2>Scans</h2><table><tr><th>file</th><th>points</th></tr>");
    for (path, n) in inputs.iter().zip(&run.points) {
        let _ = write!(
            h,
            "<tr><td>{}</td><td>{n}</td></tr>",
            escape(&path.display().to_string())
        );
    }
    h.push_str("</table><h2>Parameters</h2><table><tr><th>name</th><th>value</th><th>why</th></tr>");
    for c in &s.parameters {
        let _ = write!(
            h,
            "<tr><td>{}</td><td>{:.4}</td><td>{}</td></tr>",
            escape(&c.name),
            c.value,
            escape(&c.reason)
        );
    }
    h.push_str("</table><h2>Groups</h2><table><tr><th>group</th><th>points</th><th>method</th><th>triangles</th><th>area m²</th><th>verdict</th><th>note</th></tr>");
    for g in &m.groups {
        let _ = write!(
            h,
            "<tr><td>{}</td><td>{}</td><td>{:?}</td><td>{}</td><td>{:.3}</td><td>{}</td><td>{}</td></tr>",
            escape(&g.name),
            g.points,
            g.method,
            g.triangles_after,
            g.area_m2,
            verdict_text(g.verdict),
            escape(&g.note)
        );
    }
    h.push_str("</table>");
    if !s.layers.is_empty() || !s.objects.is_empty() {
        h.push_str(
            "<h2>Layers and objects</h2><p>Layers stand proud of a plane or are set into it (posters, boards); \
             objects are points no cluster held, lying together (small things).</p>\
             <table><tr><th>group</th><th>kind</th><th>points</th><th>figures</th></tr>",
        );
        for l in &s.layers {
            let _ = write!(
                h,
                "<tr><td>{}</td><td>layer of {}</td><td>{}</td><td>step {:+.1} mm, spread {:.1} mm</td></tr>",
                escape(&l.group),
                escape(&l.from),
                l.points,
                1000.0 * l.offset_m,
                1000.0 * l.spread_m
            );
        }
        for o in &s.objects {
            let _ = write!(
                h,
                "<tr><td>{}</td><td>object</td><td>{}</td><td>{:.2} m across</td></tr>",
                escape(&o.group),
                o.points,
                o.extent_m
            );
        }
        h.push_str("</table>");
    }
    if !s.targets.is_empty() {
        h.push_str(
            "<h2>Calibration targets</h2><table><tr><th>scan</th><th>centre</th><th>normal</th><th>radius m</th></tr>",
        );
        for t in &s.targets {
            let _ = write!(
                h,
                "<tr><td>{}</td><td>{:.3}, {:.3}, {:.3}</td><td>{:.3}, {:.3}, {:.3}</td><td>{:.3}</td></tr>",
                t.scan, t.centre[0], t.centre[1], t.centre[2], t.normal[0], t.normal[1], t.normal[2], t.radius_m
            );
        }
        h.push_str("</table>");
    }
    h.push_str("<h2>Time</h2><table>");
    for st in &s.stages {
        let _ = write!(h, "<tr><td>{}</td><td>{:.2} s</td></tr>", escape(&st.stage), st.seconds);
    }
    h.push_str("</table><h2>Views</h2>");
    for v in views {
        let name = v
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let _ = write!(h, "<p>{0}<br><img src=\"{0}\" alt=\"{0}\"></p>", escape(&name));
    }
    h
}
