//! `campanile process` on a room session (thesis §4.7.2): the merged
//! frames taken with every lamp on become a `campanile igi` scene file
//! (rectified EXR views with masks, calibrated cameras, the lamps
//! triangulated from their bulbs), which inverse global illumination then
//! solves for each surface's Ward BRDF and albedo map (ch. 4).
//!
//! Which frames: the light sequence's "all on" state at each pose, and the
//! brackets taken at scene poses after a sequence that ended all on (the
//! controller leaves the lamps as the last step set them). The first group
//! at a pose is used. Bulbs: around each lamp's configured position
//! (the station file's, a tape-measure prior) a window of
//! [`BULB_WINDOW_M`] is cut out of every such view in which the bulb is in
//! frame, unclipped and brighter than the room; at least two views per
//! lamp are needed. The triangulated lamps carry the camera's own units,
//! so the recovered reflectances do not depend on its absolute gauge.

use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::Result;
use anyhow::{Context, anyhow};
use campanile_config::Plan;
use campanile_config::plan::Step;
use campanile_process::igi::scene_file::{BulbImageEntry, CameraEntry, IgiScene, ImageEntry, LightEntry, SurfaceGroup};
use campanile_process::pipeline::room_views::{RectifiedView, bulb_window, rectified_camera, rectify};
use campanile_process::pipeline::{MergedGroup, Purpose};
use campanile_process::quality::{ProductQuality, gates};
use campanile_process::report::{Figure, Section, Table, tonemapped_png};
use nalgebra::Vector3;
use serde::Serialize;

use super::Processed;
use crate::igi::{Recovered, recover_scene, write_exr};

/// Radius around a lamp's configured position cut out as its bulb's
/// image, metres: the bulb plus the uncertainty of a measured position.
pub const BULB_WINDOW_M: f64 = 0.2;

/// A bulb must be this many times brighter than the median of the view
/// to count as seen (not hidden behind something).
const BULB_CONTRAST: f64 = 20.0;

/// Whether a plan is a room session: it has a light sequence.
pub fn is_room_session(plan: &Plan) -> bool {
    plan.sessions
        .iter()
        .any(|s| s.steps.iter().any(|st| matches!(st, Step::LightSequence { .. })))
}

/// Settings of the room stage.
#[derive(Debug, Clone, Copy)]
pub struct RoomOptions {
    /// Rectified views' size relative to the camera's frames (box-filtered).
    pub scale: f64,
    /// The solver's faster, coarser settings.
    pub quick: bool,
}

/// One view handed to the solver.
#[derive(Debug, Clone, Serialize)]
pub struct RoomView {
    /// The pose (the camera's name in the scene file).
    pub pose: String,
    /// The merged group it came from.
    pub group: String,
    /// Rectified size, pixels.
    pub size: (usize, usize),
    /// Fraction of pixels valid (in frame, no tap clipped).
    pub valid_fraction: f64,
}

/// What the room stage made.
pub struct RoomProducts {
    /// The scene file written.
    pub scene_file: PathBuf,
    /// The views.
    pub views: Vec<RoomView>,
    /// Per lamp, its configured position and the poses its bulb was cut from.
    pub bulbs: Vec<(String, Vector3<f64>, Vec<String>)>,
    /// The solver's result.
    pub recovered: Recovered,
    /// Seconds per stage.
    pub seconds: Vec<(String, f64)>,
}

/// The verdicts of a room session: the response and radiance maps', then
/// each surface's BRDF, inheriting the response's.
pub fn room_quality(p: &Processed, products: &RoomProducts) -> Vec<ProductQuality> {
    let mut quality = p.quality.clone();
    let response = p.quality.iter().find(|q| q.product == "response");
    quality.extend(products.recovered.result.surfaces.iter().map(|s| {
        let mut q = gates::brdf(s, &p.thresholds);
        if let Some(r) = response {
            q.inherit(r);
        }
        q
    }));
    quality
}

/// The step index of a group key `"{occurrence}/s{step}/t{target}"`.
fn step_of(key: &str) -> Option<usize> {
    key.split('/').nth(1)?.strip_prefix('s')?.parse().ok()
}

/// The merged groups taken with every lamp on, one per pose, in session order.
fn all_on_groups(p: &Processed) -> Vec<(&str, &MergedGroup)> {
    let lit = |levels: &[f64]| levels.iter().filter(|l| **l > 0.0).count();
    let most = p
        .merged
        .iter()
        .filter_map(|g| match &g.purpose {
            Purpose::Lights { levels, .. } => Some(lit(levels)),
            _ => None,
        })
        .max()
        .unwrap_or(0);
    let scene_pose = |name: &str| p.inputs.scene.as_ref().is_some_and(|(s, _)| s.pose(name).is_some());
    let mut out: Vec<(&str, &MergedGroup)> = Vec::new();
    for g in &p.merged {
        let pose = match &g.purpose {
            Purpose::Lights { pose, levels } if lit(levels) == most && most > 0 => pose.as_str(),
            Purpose::View { pose } if scene_pose(pose) => {
                // After a light sequence that ended with every lamp on?
                let after_all_on = p.inputs.session_of(&g.occurrence).is_some_and(|s| {
                    let step = step_of(&g.key).unwrap_or(0);
                    s.steps[..step.min(s.steps.len())]
                        .iter()
                        .any(|st| matches!(st, Step::LightSequence { all_on: true, .. }))
                });
                if !after_all_on {
                    continue;
                }
                pose.as_str()
            }
            _ => continue,
        };
        if !out.iter().any(|(p, _)| *p == pose) {
            out.push((pose, g));
        }
    }
    out
}

fn median_radiance(v: &RectifiedView) -> f64 {
    let mut l: Vec<f32> = (0..v.valid.len())
        .filter(|&k| v.valid[k])
        .map(|k| v.image.data[k * 3..k * 3 + 3].iter().sum::<f32>())
        .collect();
    if l.is_empty() {
        return 0.0;
    }
    let mid = l.len() / 2;
    l.select_nth_unstable_by(mid, f32::total_cmp);
    f64::from(l[mid])
}

fn camera_entry(name: &str, c: &campanile_process::igi::ViewCamera) -> CameraEntry {
    let t3 = |v: &Vector3<f64>| (v.x, v.y, v.z);
    CameraEntry {
        name: name.to_owned(),
        position_m: Some(t3(&c.position)),
        look: Some(t3(&c.look)),
        up: Some(t3(&c.up)),
        vfov_deg: Some(c.vfov_rad.to_degrees()),
        hfov_deg: None,
        radiance_view: None,
        width: c.width,
        height: c.height,
    }
}

fn write_mask(valid: &[bool], (w, h): (usize, usize), path: &Path) -> Result<()> {
    let bytes: Vec<u8> = valid.iter().map(|v| if *v { 255 } else { 0 }).collect();
    image::GrayImage::from_raw(w as u32, h as u32, bytes)
        .ok_or_else(|| anyhow!("{}: mask size", path.display()))?
        .save(path)
        .with_context(|| format!("writing {}", path.display()))?;
    Ok(())
}

/// Writes `OUT/room/scene.ron` (with the OBJ, `images/` and masks) from
/// the session's merged frames and solves it into `OUT/room/igi/`.
pub fn room_stage(p: &Processed, out: &Path, opts: &RoomOptions) -> Result<RoomProducts> {
    let mut seconds = Vec::new();
    let t = Instant::now();
    let dir = out.join("room");
    let images = dir.join("images");
    std::fs::create_dir_all(&images).with_context(|| format!("creating {}", images.display()))?;
    let Some((scene, _)) = &p.inputs.scene else {
        bail!("a room session needs its scene (OBJ geometry and poses): pass --scene");
    };
    let obj = p
        .inputs
        .geometry()?
        .ok_or_else(|| anyhow!("the room's scene has no geometry"))?;
    std::fs::copy(&obj, dir.join("room.obj")).with_context(|| format!("copying {}", obj.display()))?;

    let chosen = all_on_groups(p);
    if chosen.is_empty() {
        bail!(
            "{}: no view was taken with every lamp on (a LightSequence with all_on: true at scene poses)",
            p.inputs.reader.dir().display()
        );
    }
    let rectified: Vec<(String, &MergedGroup, RectifiedView)> = {
        use rayon::prelude::*;
        chosen
            .par_iter()
            .map(|(pose, g)| (pose.to_string(), *g, rectify(g, &g.mount(&p.optics.mount), opts.scale)))
            .collect()
    };
    let mut cameras = Vec::new();
    let mut entries = Vec::new();
    let mut views = Vec::new();
    for (pose, g, v) in &rectified {
        let exr = format!("images/{pose}.exr");
        let mask = format!("images/{pose}-mask.png");
        write_exr(&v.image, &dir.join(&exr))?;
        write_mask(&v.valid, (v.camera.width, v.camera.height), &dir.join(&mask))?;
        cameras.push(camera_entry(pose, &v.camera));
        entries.push(ImageEntry {
            camera: pose.clone(),
            image: exr.into(),
            mask: Some(mask.into()),
        });
        views.push(RoomView {
            pose: pose.clone(),
            group: g.key.clone(),
            size: (v.camera.width, v.camera.height),
            valid_fraction: v.valid_fraction(),
        });
    }

    // Bulbs around the lamps' configured positions.
    // The lamps lit in the all-on state (levels in the station's channel order).
    let on: Vec<f64> = chosen
        .iter()
        .find_map(|(_, g)| match &g.purpose {
            Purpose::Lights { levels, .. } => Some(levels.clone()),
            _ => None,
        })
        .unwrap_or_default();
    let lamps: Vec<_> = p
        .inputs
        .station
        .lights
        .as_ref()
        .map(|l| l.channels.clone())
        .unwrap_or_default()
        .into_iter()
        .enumerate()
        .filter(|(i, _)| on.get(*i).is_some_and(|l| *l > 0.0))
        .map(|(_, c)| c)
        .collect();
    if lamps.is_empty() {
        bail!(
            "no lamp is on in the views with every lamp on: a room session's lamps are the station's `lights` channels its light sequence switches"
        );
    }
    // Bulbs are small: cut them from views rectified at the frames' full
    // size, rectifying again only the views in which some lamp's configured
    // position falls inside the frame.
    let priors: Vec<Vector3<f64>> = lamps
        .iter()
        .map(|l| Vector3::new(l.position_m.0, l.position_m.1, l.position_m.2))
        .collect();
    let full: Vec<(String, RectifiedView)> = {
        use rayon::prelude::*;
        chosen
            .par_iter()
            .filter(|(_, g)| {
                let cam = rectified_camera(
                    &g.pinhole,
                    (g.map.width, g.map.height),
                    &g.mount(&p.optics.mount),
                    g.head,
                    g.position_m,
                    1.0,
                );
                priors.iter().any(|prior| {
                    cam.project(prior).is_some_and(|(u, v)| {
                        (0.0..cam.width as f64).contains(&u) && (0.0..cam.height as f64).contains(&v)
                    })
                })
            })
            .map(|(pose, g)| {
                let v = if opts.scale == 1.0 {
                    rectified.iter().find(|(p, _, _)| p == pose).map(|(_, _, v)| v.clone())
                } else {
                    None
                };
                (
                    pose.to_string(),
                    v.unwrap_or_else(|| rectify(g, &g.mount(&p.optics.mount), 1.0)),
                )
            })
            .collect()
    };
    let medians: Vec<f64> = full.iter().map(|(_, v)| median_radiance(v)).collect();
    let mut lights = Vec::new();
    let mut bulbs = Vec::new();
    for (lamp, prior) in lamps.iter().zip(&priors) {
        let mut seen = Vec::new();
        let mut list = Vec::new();
        for ((pose, v), median) in full.iter().zip(&medians) {
            let Some(img) = bulb_window(v, prior, lamp.radius_m, lamp.radius_m + BULB_WINDOW_M) else {
                continue;
            };
            let peak = img
                .data
                .chunks(3)
                .map(|p| f64::from(p.iter().sum::<f32>()))
                .fold(0.0, f64::max);
            if peak < BULB_CONTRAST * median {
                continue;
            }
            let path = format!("images/bulb-{}-{pose}.exr", lamp.name);
            write_exr(&img, &dir.join(&path))?;
            let camera = if v.camera.width == img.width && opts.scale == 1.0 {
                pose.clone()
            } else {
                let name = format!("{pose}-full");
                if !cameras.iter().any(|c: &CameraEntry| c.name == name) {
                    cameras.push(camera_entry(&name, &v.camera));
                }
                name
            };
            list.push(BulbImageEntry {
                camera,
                image: path.into(),
            });
            seen.push(pose.clone());
        }
        if list.len() < 2 {
            bail!(
                "lamp {:?}: its bulb is seen unclipped in {} view(s) ({}), at least 2 are needed to triangulate it; add brackets at poses that see it (e.g. an AutoBracket after the light sequence)",
                lamp.name,
                list.len(),
                if seen.is_empty() {
                    "none".to_owned()
                } else {
                    seen.join(", ")
                }
            );
        }
        lights.push(LightEntry::Bulb {
            name: lamp.name.clone(),
            images: list,
        });
        bulbs.push((lamp.name.clone(), *prior, seen));
    }

    // Surfaces: the OBJ groups of each material (they share specular parameters, §4.4).
    // In the scene's order of materials.
    let surfaces: Vec<SurfaceGroup> = scene
        .materials
        .iter()
        .map(|m| SurfaceGroup {
            name: m.name.clone(),
            groups: scene
                .surfaces
                .iter()
                .filter(|s| s.material == m.name)
                .flat_map(|s| s.groups.iter().cloned())
                .collect(),
        })
        .filter(|g| !g.groups.is_empty())
        .collect();
    let file = IgiScene {
        geometry: "room.obj".into(),
        surfaces,
        cameras,
        lights,
        images: entries,
        ward_variant: None,
        interreflection: None,
    };
    let scene_file = dir.join("scene.ron");
    let text = ron::ser::to_string_pretty(&file, ron::ser::PrettyConfig::default())?;
    std::fs::write(&scene_file, text).with_context(|| format!("writing {}", scene_file.display()))?;
    seconds.push((
        format!("room: {} views rectified, scene file", views.len()),
        t.elapsed().as_secs_f64(),
    ));

    let t = Instant::now();
    let recovered =
        recover_scene(&scene_file, opts.quick).with_context(|| format!("solving {}", scene_file.display()))?;
    seconds.push((
        "room: lamps, BRDFs, albedo maps (inverse GI)".into(),
        t.elapsed().as_secs_f64(),
    ));
    Ok(RoomProducts {
        scene_file,
        views,
        bulbs,
        recovered,
        seconds,
    })
}

/// The report section of a room (no truth: see the demo for that).
pub fn room_section(r: &RoomProducts) -> Result<Section> {
    let rec = &r.recovered;
    let mut views = Table {
        caption: "Views handed to the solver (every lamp on), rectified".into(),
        header: ["pose", "merged group", "size", "valid pixels"]
            .map(String::from)
            .to_vec(),
        rows: Vec::new(),
    };
    for v in &r.views {
        views.rows.push(vec![
            v.pose.clone(),
            v.group.clone(),
            format!("{}×{}", v.size.0, v.size.1),
            format!("{:.1} %", 100.0 * v.valid_fraction),
        ]);
    }
    let mut lamps = Table {
        caption: "Lamps triangulated from their bulbs (§4.7.2); intensity in the camera's radiance units".into(),
        header: [
            "lamp",
            "configured at (m)",
            "triangulated at (m)",
            "offset",
            "radius",
            "intensity R/G/B (W/sr)",
            "ray RMS",
            "views",
        ]
        .map(String::from)
        .to_vec(),
        rows: Vec::new(),
    };
    for (name, prior, seen) in &r.bulbs {
        let Some((_, t)) = rec.loaded.triangulated.iter().find(|(n, _)| n == name) else {
            continue;
        };
        let p = t.light.position;
        lamps.rows.push(vec![
            name.clone(),
            format!("({:.3}, {:.3}, {:.3})", prior.x, prior.y, prior.z),
            format!("({:.4}, {:.4}, {:.4})", p.x, p.y, p.z),
            format!("{:.1} mm", (p - prior).norm() * 1e3),
            format!("{:.4} m", t.light.radius),
            format!(
                "{:.3} / {:.3} / {:.3}",
                t.light.intensity[0], t.light.intensity[1], t.light.intensity[2]
            ),
            format!("{:.2} mm", t.ray_rms_m * 1e3),
            seen.join(", "),
        ]);
    }
    let mut materials = Table {
        caption: "Recovered materials (thesis Table 4.1's quantities; ρ per channel R/G/B)".into(),
        header: ["surface", "model (why)", "ρd", "ρs", "αx", "αy", "γ"]
            .map(String::from)
            .to_vec(),
        rows: Vec::new(),
    };
    for s in &rec.result.surfaces {
        let rgb = |v: [f64; 3]| format!("{:.3} / {:.3} / {:.3}", v[0], v[1], v[2]);
        let (rho_d, lobe) = s.material.map_or((None, None), |m| (Some(m.rho_d), m.lobe));
        materials.rows.push(vec![
            s.name.clone(),
            format!("{:?} ({})", s.model, s.reason),
            rho_d.map_or("—".into(), rgb),
            lobe.map_or("—".into(), |l| rgb(l.rho_s)),
            lobe.map_or("—".into(), |l| format!("{:.4}", l.alpha_x)),
            lobe.map_or("—".into(), |l| format!("{:.4}", l.alpha_y)),
            lobe.map_or("—".into(), |l| format!("{:.1}°", l.gamma_rad.to_degrees())),
        ]);
    }
    let mut figures = Vec::new();
    for v in rec.loaded.input.views.iter().take(3) {
        let img = &v.image;
        let mut sorted: Vec<f32> = img.data.iter().copied().filter(|x| x.is_finite()).collect();
        sorted.sort_by(f32::total_cmp);
        let white = f64::from(sorted.get(sorted.len() * 95 / 100).copied().unwrap_or(1.0)).max(1e-9);
        figures.push(Figure::Png {
            bytes: tonemapped_png(&v.name, img.width, img.height, &img.data, 1.0 / white)
                .map_err(|e| anyhow!("{e}"))?,
            caption: format!("{}: the merged, rectified view (every lamp on)", v.name),
        });
    }
    Ok(Section {
        title: "Indoor: the room (inverse global illumination, §4.7.2)".into(),
        paragraphs: vec![format!(
            "{} views with every lamp on were merged to HDR, rectified and written as a scene file ({}); {} lamps were triangulated from their bulbs; {} surfaces sharing specular parameters were solved for their Ward BRDFs (§4.4, App. A) and albedo maps (§4.6).",
            r.views.len(),
            r.scene_file.display(),
            r.bulbs.len(),
            rec.result.surfaces.len()
        )],
        tables: vec![views, lamps, materials],
        figures,
    })
}
