//! `campanile segment`: range scans to a scene (thesis chapter 2).

use std::path::PathBuf;

use anyhow::Result;
use campanile_scan::mesh::MeshOptions;
use campanile_scan::scene_from_scans::{SceneRequest, scene_from_scans};
use campanile_scan::segment::Verdict;
use campanile_scan::segment::params::Overrides;
use campanile_session::progress::bar;
use clap::Args;

use super::exit::{EXIT_OK, EXIT_QUALITY, bad_input};

/// Range scans to a scene: surface groups by normalized cuts (thesis §2.3),
/// a mesh per group (§2.4), and the scene file that `campanile igi`,
/// `process` and `render` take.
///
/// SCANS are PLY (ascii or binary; positions, and normals, intensity,
/// colour and a scanner grid when present), E57 (every scan in the file,
/// its pose applied, its grid kept) or LAS/LAZ files, already registered in
/// one scene frame (metres, z up). Normals are estimated where a file has
/// none.
///
/// The segmenter's parameters (cluster radius, σ_w and σ_c of eqs. 2.3 and
/// 2.4, E of eq. 2.5, T_cut, the fine pass) are derived from the scans'
/// measured noise and point spacing; --params fixes any of them (a RON
/// file of the fields of `Overrides`, e.g. `(t_cut: Some(0.05))`), and the
/// report says which were derived and from what.
///
/// --out gets scene.obj (one group per surface group, faces toward the
/// scanner), scene.ron (the scene skeleton: one surface and material per
/// group), segmentation.ply (every point coloured by its group),
/// groups-N.png (each scan's points in their groups' colours),
/// segment-report.json and mesh-report.json (every figure), and
/// report.html. Groups are named surface_0, surface_1, … (largest first);
/// `campanile edit` merges them into named objects.
///
/// Verdict: the worse of the segmentation's (failed over 10 % of points in
/// no group, poor over 2 %) and the meshes' (a group with no triangles, or
/// with --truth a mesh farther than 10 cm from it, failed; 3 cm poor).
/// Exit status: 0 ok or poor, 3 failed (the files are still written),
/// 2 bad input, 1 failure while working.
///
/// Example:
///   cargo run -p campanile-sim --example range_scans -- scans/
///   campanile segment scans/room-*.ply --out room-scene/
///   campanile edit room-scene/scene.ron edits.ron --out edited/
#[derive(Debug, Args)]
#[command(verbatim_doc_comment)]
pub struct SegmentArgs {
    /// Scan files (PLY, E57, LAS, LAZ).
    #[arg(required = true, value_name = "SCANS")]
    scans: Vec<PathBuf>,
    /// Output directory.
    #[arg(long, value_name = "DIR")]
    out: PathBuf,
    /// Segmentation parameters to fix (RON, the fields of `Overrides`).
    #[arg(long, value_name = "PARAMS.ron")]
    params: Option<PathBuf>,
    /// The true geometry (an OBJ whose groups are named as the groups are), to measure the meshes against.
    #[arg(long, value_name = "TRUTH.obj")]
    truth: Option<PathBuf>,
}

pub fn run(args: SegmentArgs) -> Result<u8> {
    let overrides = match &args.params {
        Some(path) => {
            let text = std::fs::read_to_string(path).map_err(|e| bad_input(format!("{}: {e}", path.display())))?;
            ron::from_str::<Overrides>(&text).map_err(|e| {
                bad_input(format!(
                    "{}:{}: {} (expected the fields of Overrides, e.g. `(t_cut: Some(0.05))`)",
                    path.display(),
                    e.span.start,
                    e.code
                ))
            })?
        }
        None => Overrides::default(),
    };
    let request = SceneRequest {
        scans: args.scans,
        overrides,
        mesh: MeshOptions {
            truth: args.truth,
            ..MeshOptions::default()
        },
        out: args.out,
    };
    let progress = bar(0, "segment");
    let run = scene_from_scans(&request, &|p| {
        progress.set_message(p.stage);
        progress.set_length(p.total as u64);
        progress.set_position(p.done as u64);
    });
    progress.finish_and_clear();
    let run = match run {
        Ok(run) => run,
        Err(e) if e.is_bad_input() => return Err(bad_input(e.to_string())),
        Err(e) => return Err(e.into()),
    };
    let s = &run.segmentation;
    let m = &run.meshes;
    println!(
        "read {} points from {} scan(s); {} groups, {} unassigned; {} calibration target(s)",
        run.points.iter().sum::<usize>(),
        run.points.len(),
        s.groups,
        s.unassigned,
        s.targets.len()
    );
    for c in &s.parameters {
        println!("  {} = {:.4} ({})", c.name, c.value, c.reason);
    }
    for g in &m.groups {
        println!(
            "  {}: {} points, {:?}, {} triangles, {:.2} m², {:?}{}",
            g.name,
            g.points,
            g.method,
            g.triangles_after,
            g.area_m2,
            g.verdict,
            if g.note.is_empty() {
                String::new()
            } else {
                format!(" ({})", g.note)
            }
        );
    }
    println!("segmentation: {:?} ({})", s.verdict, s.verdict_reason);
    println!(
        "meshes: {:?} ({} triangles, {} before simplification{})",
        m.verdict,
        m.triangles_after,
        m.triangles_before,
        m.worst_hausdorff_m.map_or(String::new(), |h| format!(
            "; worst Hausdorff distance to the truth {:.1} mm",
            h * 1e3
        ))
    );
    println!("written to {}", request.out.display());
    Ok(if run.verdict == Verdict::Failed {
        EXIT_QUALITY
    } else {
        EXIT_OK
    })
}
