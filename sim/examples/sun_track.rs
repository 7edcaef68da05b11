//! One clear day's sun shots of a simulated fixed sky camera, as the CSV
//! `campanile sky calibrate` reads (time, u_px, v_px): rendered through the
//! station's true camera (its `simulation.true_camera`) with the head at
//! the zenith, the disc measured from each frame.
//!
//! ```text
//! cargo run --release -p campanile-sim --example sun_track -- \
//!     examples/sky-fisheye-sim-station.ron 2026-06-21 15 shots.csv
//! ```
//!
//! Arguments: the station file, the UTC date, the minutes between shots,
//! the CSV to write. The scene is `examples/sky-scene.ron` (open ground).

use campanile_process::pose::HeadPose;
use campanile_sim::world::sun_track::sun_shots;
use campanile_sim::world::{World, examples_dir, load_scene};
use chrono::{DateTime, Duration, NaiveDate, Utc};
use std::fmt::Write as _;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [station, date, every_min, out] = args.as_slice() else {
        return Err("usage: sun_track STATION.ron YYYY-MM-DD MINUTES OUT.csv".into());
    };
    let station = campanile_config::load_station(station.as_ref())?.value;
    let mut world = World::new(&station, load_scene(&examples_dir().join("sky-scene.ron"))?);
    world.quality.samples_per_pixel = 1;
    world.quality.max_bounces = 0;
    let day: NaiveDate = date.parse()?;
    let start: DateTime<Utc> = day.and_hms_opt(0, 0, 0).ok_or("a date")?.and_utc();
    let step: i64 = every_min.parse()?;
    let times: Vec<DateTime<Utc>> = (0..24 * 60 / step.max(1))
        .map(|k| start + Duration::minutes(k * step))
        .collect();
    let zenith = HeadPose {
        pan_rad: 0.0,
        tilt_rad: std::f64::consts::FRAC_PI_2,
    };
    let clock = std::time::Instant::now();
    let (shots, missed) = sun_shots(&world, zenith, &times, 1e-5, 1)?;
    let mut csv = String::from("time,u_px,v_px,true_u_px,true_v_px\n");
    for s in &shots {
        let (u, v) = s.sighting.centroid_px;
        let _ = writeln!(
            csv,
            "{},{u:.4},{v:.4},{:.4},{:.4}",
            s.sighting.time.to_rfc3339_opts(chrono::SecondsFormat::Secs, true),
            s.true_pixel.0,
            s.true_pixel.1
        );
    }
    std::fs::write(out, csv)?;
    let not_down = missed
        .iter()
        .filter(|m| !m.reason.starts_with("the sun is down"))
        .count();
    eprintln!(
        "{} sun shots in {:.1} s to {out}; {} times with the sun down, {not_down} others missed",
        shots.len(),
        clock.elapsed().as_secs_f64(),
        missed.len() - not_down
    );
    for m in missed.iter().filter(|m| !m.reason.starts_with("the sun is down")) {
        eprintln!("  {}: {}", m.time.to_rfc3339(), m.reason);
    }
    Ok(())
}
