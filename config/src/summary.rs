//! Human-readable summaries of configuration files, as `campanile config
//! check` prints them.

use std::fmt::Write;

use crate::camera::{CameraDriver, DeviceRef, Focal};
use crate::document::{Document, Loaded, LoadedPlan};
use crate::plan::{Aim, Repeat, Step, Trigger};
use crate::scene::Scene;
use crate::station::Station;
use crate::validate::fmt_f64;

impl Document {
    /// A multi-line summary of what the file describes.
    pub fn summary(&self) -> String {
        match self {
            Document::Station(s) => station_summary(&s.value),
            Document::Plan(p) => plan_summary(p),
            Document::Scene(s) => scene_summary(s),
            Document::CameraCalibration(c) => calibration_summary(&c.value),
            Document::Targets(t) => targets_summary(&t.value),
        }
    }

    /// What kind of file it is.
    pub fn kind(&self) -> &'static str {
        match self {
            Document::Station(_) => "station",
            Document::Plan(_) => "plan",
            Document::Scene(_) => "scene",
            Document::CameraCalibration(_) => "camera calibration",
            Document::Targets(_) => "targets",
        }
    }
}

fn calibration_summary(c: &crate::camera_calibration::CameraCalibration) -> String {
    let (i, m) = (&c.intrinsics, &c.mount);
    let focal = i.focal.pixels_for(i.projection, c.resolution.width);
    let pp = i
        .principal_point_px
        .map_or("the image centre".to_owned(), |(x, y)| format!("({x:.2}, {y:.2}) px"));
    format!(
        "camera calibration for {}×{} px\n  lens       {:?}, focal {focal:.3} px, principal point {pp}, k1 {:.6}, k2 {:.6}\n  mount      pan 0 faces azimuth {:.4}°, tilt zero {:.4}°, roll {:.4}°, pitch {:.4}°\n",
        c.resolution.width,
        c.resolution.height,
        i.projection,
        i.distortion.0,
        i.distortion.1,
        m.pan_zero_azimuth_deg,
        m.tilt_zero_deg,
        m.level_roll_deg,
        m.level_pitch_deg
    )
}

fn station_summary(s: &Station) -> String {
    let mut o = String::new();
    let site = &s.site;
    let _ = writeln!(o, "station {:?}", s.name);
    let _ = writeln!(
        o,
        "  site       {} — {:.4}°{}, {:.4}°{}, {} m, {} mbar, {} °C, {}{}",
        site.name,
        site.latitude_deg.abs(),
        if site.latitude_deg >= 0.0 { "N" } else { "S" },
        site.longitude_deg.abs(),
        if site.longitude_deg >= 0.0 { "E" } else { "W" },
        fmt_f64(site.elevation_m),
        fmt_f64(site.pressure_mbar),
        fmt_f64(site.temperature_c),
        site.time_zone,
        site.delta_t_s
            .map_or(String::new(), |d| format!(", ΔT {} s", fmt_f64(d)))
    );
    let c = &s.camera;
    let driver = match c.driver {
        CameraDriver::Sim => "simulated".to_owned(),
        CameraDriver::V4l => "V4L2".to_owned(),
        CameraDriver::Nokhwa => "nokhwa".to_owned(),
        CameraDriver::Indi => "INDI".to_owned(),
        CameraDriver::Gphoto2 => "gphoto2".to_owned(),
        CameraDriver::Aravis => "GenICam (Aravis)".to_owned(),
    };
    let device = match &c.device {
        Some(DeviceRef::Path(p)) => format!(" at {p}"),
        Some(DeviceRef::Index(i)) => format!(" #{i}"),
        Some(DeviceRef::Indi { server, device, .. }) => format!(" {device:?} on {server}"),
        Some(DeviceRef::Aravis { id, pixel_format }) => match pixel_format {
            Some(f) => format!(" {id:?} in {f}"),
            None => format!(" {id:?}"),
        },
        None => String::new(),
    };
    let focal = c
        .intrinsics
        .focal
        .pixels_for(c.intrinsics.projection, c.resolution.width);
    let fov = match c.intrinsics.focal {
        Focal::HorizontalFovDeg(f) => f,
        Focal::Pixels(f) => {
            let theta = c.intrinsics.projection.angle(0.5 * f64::from(c.resolution.width) / f);
            2.0 * theta.unwrap_or(std::f64::consts::PI).to_degrees()
        }
    };
    let lens = match c.intrinsics.projection {
        crate::camera::Projection::Pinhole => "",
        crate::camera::Projection::Equidistant => " equidistant fisheye,",
        crate::camera::Projection::Equisolid => " equisolid fisheye,",
    };
    let _ = writeln!(
        o,
        "  camera     {driver}{device},{lens} {}×{} px, {}-bit, focal {focal:.1} px ({fov:.1}° across), exposure {}–{} s",
        c.resolution.width,
        c.resolution.height,
        c.bit_depth,
        fmt_f64(c.exposure.min_s),
        fmt_f64(c.exposure.max_s)
    );
    let h = &s.head;
    let _ = writeln!(
        o,
        "  head       {:?} on {} @ {} baud, pan [{}, {}]°, tilt [{}, {}]°, pan 0 faces azimuth {}°",
        h.protocol,
        h.link.port,
        h.link.baud,
        fmt_f64(h.limits.pan_min_deg),
        fmt_f64(h.limits.pan_max_deg),
        fmt_f64(h.limits.tilt_min_deg),
        fmt_f64(h.limits.tilt_max_deg),
        fmt_f64(h.mount.pan_zero_azimuth_deg)
    );
    match &s.filter_wheel {
        Some(w) => {
            let slots: Vec<_> = w.slots.iter().map(|s| s.name.as_str()).collect();
            let _ = writeln!(
                o,
                "  filters    {:?} on {}: {}",
                w.protocol,
                w.place(),
                slots.join(", ")
            );
        }
        None => o.push_str("  filters    none (sun shots are not possible)\n"),
    }
    match &s.lights {
        Some(l) => {
            let names: Vec<_> = l
                .channels
                .iter()
                .map(|c| format!("{} (ch {})", c.name, c.channel))
                .collect();
            let _ = writeln!(
                o,
                "  lights     {:?} on {}: {}",
                l.protocol,
                l.link.port,
                names.join(", ")
            );
        }
        None => o.push_str("  lights     none\n"),
    }
    if let Some(sim) = &s.simulation {
        let _ = writeln!(
            o,
            "  simulation seed {}, link drop {}, corrupt {}",
            sim.seed,
            fmt_f64(sim.link_drop_chance),
            fmt_f64(sim.link_corrupt_chance)
        );
    }
    o
}

fn trigger_text(t: &Trigger) -> String {
    match t {
        Trigger::Clock { time, day: 0 } => format!("at {time} UTC"),
        Trigger::Clock { time, day } => format!("at {time} UTC on day +{day}"),
        Trigger::SolarElevation { elevation_deg, motion } => {
            format!(
                "when the sun {} through {}° elevation",
                format!("{motion:?}").to_lowercase(),
                fmt_f64(*elevation_deg)
            )
        }
        Trigger::SolarAzimuth { azimuth_deg } => format!("when the sun reaches azimuth {}°", fmt_f64(*azimuth_deg)),
        Trigger::Face { face, becomes } => format!("when {face} becomes {}", format!("{becomes:?}").to_lowercase()),
    }
}

fn repeat_text(r: &Repeat) -> String {
    match r {
        Repeat::Once => "once".into(),
        Repeat::Daily { days } => format!("daily for {days} days"),
        Repeat::Every {
            interval_min,
            while_sun_above_deg,
            days,
        } => format!(
            "every {} min{} for {days} days",
            fmt_f64(*interval_min),
            while_sun_above_deg.map_or(String::new(), |e| format!(" while the sun is above {}°", fmt_f64(e)))
        ),
    }
}

fn step_text(s: &Step) -> String {
    let aim = |a: &Aim| match a {
        Aim::PanTilt { pan_deg, tilt_deg } => format!("pan {}° tilt {}°", fmt_f64(*pan_deg), fmt_f64(*tilt_deg)),
        Aim::Pose(p) => format!("pose {p}"),
        Aim::Sun => "the sun".into(),
    };
    let detail = match s {
        Step::Bracket {
            aim: a,
            exposures_s,
            filter,
            ..
        } => format!(
            "{} exposures at {}{}",
            exposures_s.len(),
            aim(a),
            filter.as_ref().map_or(String::new(), |f| format!(" through {f}"))
        ),
        Step::AutoBracket { aim: a, max_frames, .. } => format!("up to {max_frames} frames at {}", aim(a)),
        Step::SunShot { filters, triplet, .. } => {
            format!(
                "through {}{}",
                filters.join(" or "),
                if *triplet { ", triplet" } else { "" }
            )
        }
        Step::SkyScan {
            min_elevation_deg,
            aureole_bands_deg,
            ..
        } => format!(
            "from {}° up, {} aureole bands",
            fmt_f64(*min_elevation_deg),
            aureole_bands_deg.len()
        ),
        Step::EnvironmentTiles {
            min_elevation_deg,
            max_elevation_deg,
            ..
        } => {
            format!("{}° to {}°", fmt_f64(*min_elevation_deg), fmt_f64(*max_elevation_deg))
        }
        Step::Views { poses, .. } => poses.join(", "),
        Step::LightSequence {
            lights, all_on, poses, ..
        } => format!(
            "{}{} from {}",
            lights.join(", "),
            if *all_on { ", then all" } else { "" },
            poses.join(", ")
        ),
    };
    let p = s.on_error();
    format!(
        "{} ({detail}); on error retry {}, then {:?}",
        s.kind(),
        p.retries,
        p.then
    )
}

fn plan_summary(p: &LoadedPlan) -> String {
    let plan = &p.plan.value;
    let mut o = String::new();
    let _ = writeln!(o, "plan {:?} from {} (UTC)", plan.name, plan.start_date);
    if let Some(scene) = &p.scene {
        let _ = writeln!(
            o,
            "  scene      {:?} ({})",
            scene.value.name,
            scene.source.path.display()
        );
    }
    for s in &plan.sessions {
        let _ = writeln!(
            o,
            "  session {:?}{}: {}, {}",
            s.name,
            if s.held_out { " (held out)" } else { "" },
            trigger_text(&s.trigger),
            repeat_text(&s.repeat)
        );
        for step in &s.steps {
            let _ = writeln!(o, "    - {}", step_text(step));
        }
    }
    o
}

fn targets_summary(t: &crate::targets::Targets) -> String {
    let mut o = String::new();
    match t.kind.circle_radius_m() {
        Some(r) => {
            let _ = writeln!(o, "targets: {} circles of radius {r} m", t.targets.len());
        }
        None => {
            let _ = writeln!(o, "targets: {} {:?} tags", t.targets.len(), t.family);
        }
    }
    let ids: Vec<String> = t.targets.iter().map(|t| t.id.to_string()).collect();
    let _ = writeln!(o, "  ids        {}", ids.join(", "));
    o
}

fn scene_summary(s: &Loaded<Scene>) -> String {
    let sc = &s.value;
    let mut o = String::new();
    let _ = writeln!(o, "scene {:?}, geometry {}", sc.name, sc.geometry.display());
    let mats: Vec<_> = sc
        .materials
        .iter()
        .map(|m| format!("{} ({:?})", m.name, m.model))
        .collect();
    let _ = writeln!(o, "  materials  {}", mats.join(", "));
    let surf: Vec<_> = sc.surfaces.iter().map(|m| m.name.as_str()).collect();
    let _ = writeln!(o, "  surfaces   {}", surf.join(", "));
    let poses: Vec<_> = sc.poses.iter().map(|m| m.name.as_str()).collect();
    let _ = writeln!(o, "  poses      {}", poses.join(", "));
    o
}
