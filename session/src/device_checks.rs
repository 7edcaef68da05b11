//! A station's devices: what this computer offers (serial ports and
//! cameras), and the conformance suites run against the devices a station
//! file names, real or simulated (`campanile devices`).

use std::io::Write;
use std::sync::Arc;
use std::time::Duration;

use anyhow::Context;
use campanile_capture::conformance::{self, Report};
use campanile_capture::device::LightChannel;
use campanile_capture::driver::backoff::Backoff;
use campanile_capture::station::camera::list_cameras;
use campanile_capture::station::{
    SerialOpener, connect_head, connect_lights, connect_wheel, driver_built, light_channel, open_camera,
    open_station_camera,
};
use campanile_config::Station;
use campanile_config::camera::CameraDriver;
use campanile_firmware_link::link::host::RetryPolicy;
use campanile_firmware_link::transport::serial;
use campanile_sim::camera::UniformSource;
use campanile_sim::station::{SimOptions, SimStation};

use crate::Result;

/// Writes the serial ports and cameras this computer offers to `out`.
pub fn list(out: &mut dyn Write) -> Result<()> {
    let ports = serial::list().context("listing serial ports")?;
    writeln!(out, "serial ports:")?;
    if ports.is_empty() {
        writeln!(out, "  (none found)")?;
    }
    for p in &ports {
        writeln!(out, "  {p}")?;
    }
    let cameras = list_cameras().context("listing cameras")?;
    writeln!(out, "cameras:")?;
    if cameras.is_empty() {
        writeln!(out, "  (none found)")?;
    }
    for c in &cameras {
        match &c.name {
            Some(n) => writeln!(out, "  {}  {n}", c.path.display())?,
            None => writeln!(out, "  {}", c.path.display())?,
        }
    }
    if !driver_built(CameraDriver::V4l) {
        writeln!(
            out,
            "note: built without the `v4l` feature: cameras are the /dev/video* nodes, named from /sys; \
             rebuild with `--features v4l` to open them"
        )?;
    }
    list_genicam(out, false)
}

/// Writes the GenICam cameras Aravis finds (with `fake`, Aravis's fake
/// camera too) to `out`, each with the id a station's `Aravis(id: …)`
/// takes; in a build without the `aravis` feature, a note saying so.
pub fn list_genicam(out: &mut dyn Write, fake: bool) -> Result<()> {
    match campanile_capture::station::camera::list_genicam_cameras(fake) {
        Some(found) => {
            writeln!(out, "GenICam cameras (Aravis):")?;
            if found.is_empty() {
                writeln!(out, "  (none found)")?;
            }
            for c in &found {
                writeln!(out, "  {:?}  {}", c.id, c.description)?;
            }
        }
        None => writeln!(
            out,
            "note: built without the `aravis` feature: GenICam cameras are not listed; \
             rebuild with `--features aravis` (needs libaravis-dev) to list and open them"
        )?,
    }
    Ok(())
}

/// What INDI's `DRIVER_INTERFACE` bits say a device is (INDI's
/// `DeviceInterface`), by bit.
const INDI_INTERFACES: [(u32, &str); 16] = [
    (0, "telescope"),
    (1, "CCD"),
    (2, "guider"),
    (3, "focuser"),
    (4, "filter wheel"),
    (5, "dome"),
    (6, "GPS"),
    (7, "weather"),
    (8, "adaptive optics"),
    (9, "dust cap"),
    (10, "light box"),
    (11, "detector"),
    (12, "rotator"),
    (13, "spectrograph"),
    (14, "correlator"),
    (15, "auxiliary"),
];

/// Writes the devices the INDI server at `server` offers to `out`: each
/// with its driver and what it is (a `CCD` is a station camera, a `filter
/// wheel` a station wheel).
pub fn list_indi(server: &str, out: &mut dyn Write) -> Result<()> {
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .context("starting the runtime")?;
    let devices = runtime.block_on(async {
        let client = campanile_capture::driver::indi::IndiClient::connect(server).await?;
        client
            .settled(Duration::from_millis(500), Duration::from_secs(10))
            .await;
        Ok::<_, campanile_capture::device::DeviceError>(
            client
                .devices()
                .into_iter()
                .map(|d| {
                    let info = client.property(&d, "DRIVER_INFO");
                    let exec = info
                        .as_ref()
                        .and_then(|p| p.item("DRIVER_EXEC").map(|i| i.value.clone()));
                    let bits = info
                        .as_ref()
                        .and_then(|p| p.number("DRIVER_INTERFACE"))
                        .map_or(0, |x| x as u32);
                    let kinds: Vec<&str> = INDI_INTERFACES
                        .iter()
                        .filter(|(bit, _)| bits & (1 << bit) != 0)
                        .map(|(_, k)| *k)
                        .collect();
                    (d, exec, kinds)
                })
                .collect::<Vec<_>>(),
        )
    });
    let devices = devices.with_context(|| format!("listing the devices of INDI server {server}"))?;
    writeln!(out, "INDI server {server}:")?;
    if devices.is_empty() {
        writeln!(out, "  (no devices)")?;
    }
    for (name, exec, kinds) in devices {
        writeln!(
            out,
            "  {name:?}  {}{}",
            if kinds.is_empty() {
                "general".to_owned()
            } else {
                kinds.join(", ")
            },
            exec.map_or(String::new(), |e| format!(" ({e})"))
        )?;
    }
    Ok(())
}

/// What a device's suite came to.
pub enum Outcome {
    /// The suite ran: its checks.
    Tested(Report),
    /// The device could not be connected.
    Failed(String),
    /// Not tested (no driver in this build), and why.
    Skipped(String),
}

/// Runs the conformance suites on every device of `station` (simulated
/// under paused time, or real with a short backoff), labelled by device.
pub fn run_suites(station: &Station, head_options: conformance::pan_tilt::Options) -> Result<Vec<(String, Outcome)>> {
    if station.uses_simulation() {
        test_simulated(station, head_options)
    } else {
        test_real(station, head_options)
    }
}

/// Writes each device's checks to `out`, then the totals; returns (checks,
/// failed), a device that could not connect counting as one failed check.
pub fn write_outcomes(outcomes: &[(String, Outcome)], out: &mut dyn Write) -> Result<(usize, usize)> {
    let (mut checks, mut failed) = (0, 0);
    for (device, outcome) in outcomes {
        writeln!(out, "{device}:")?;
        match outcome {
            Outcome::Tested(report) => {
                for line in report.to_string().lines() {
                    writeln!(out, "  {line}")?;
                }
                checks += report.checks.len();
                failed += report.failures().len();
            }
            Outcome::Failed(why) => {
                writeln!(out, "  FAIL  connect: {why}")?;
                checks += 1;
                failed += 1;
            }
            Outcome::Skipped(why) => writeln!(out, "  skipped: {why}")?,
        }
    }
    writeln!(out, "{checks} checks, {failed} failed")?;
    Ok((checks, failed))
}

fn wheel_label(w: &campanile_config::FilterWheel) -> String {
    match &w.indi {
        Some(i) => format!("filter wheel (INDI {:?} on {})", i.device, i.server),
        None => label("filter wheel", w.protocol, &w.place()),
    }
}

fn label(kind: &str, protocol: impl std::fmt::Debug, port: &str) -> String {
    format!("{kind} ({protocol:?} on {port})")
}

/// The station's real devices, one at a time, on the wall clock.
fn test_real(station: &Station, head_options: conformance::pan_tilt::Options) -> Result<Vec<(String, Outcome)>> {
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .context("starting the runtime")?;
    // A device that is not there is reported after a few tries, not 15 s.
    let backoff = Backoff {
        attempts: 3,
        first: Duration::from_millis(250),
        cap: Duration::from_secs(1),
    };
    let retry = RetryPolicy::default();
    let seq = (chrono::Utc::now().timestamp_subsec_micros() % 4096) as u16 + 1;
    let opener = SerialOpener;
    runtime.block_on(async {
        let mut out = Vec::new();
        let h = &station.head;
        let head =
            campanile_capture::driver::backoff::reopen("head", backoff, || connect_head(h, &opener, retry, seq)).await;
        out.push((
            label("head", h.protocol, &h.link.port),
            match head {
                Ok(mut head) => Outcome::Tested(conformance::pan_tilt::run(&mut head, head_options).await),
                Err(e) => Outcome::Failed(e.to_string()),
            },
        ));
        if let Some(w) = &station.filter_wheel {
            let wheel = campanile_capture::driver::backoff::reopen("filter wheel", backoff, || {
                connect_wheel(w, &opener, retry, seq.wrapping_add(4096))
            })
            .await;
            out.push((
                wheel_label(w),
                match wheel {
                    Ok(mut wheel) => Outcome::Tested(conformance::filter_wheel::run(&mut wheel).await),
                    Err(e) => Outcome::Failed(e.to_string()),
                },
            ));
        }
        if let Some(l) = &station.lights {
            let lights = campanile_capture::driver::backoff::reopen("lights", backoff, || {
                connect_lights(l, &opener, retry, seq.wrapping_add(8192))
            })
            .await;
            let channels: Vec<LightChannel> = (0..l.channels.len()).filter_map(|i| light_channel(l, i)).collect();
            out.push((
                label("lights", l.protocol, &l.link.port),
                match lights {
                    Ok(mut lights) => Outcome::Tested(conformance::lights::run(&mut lights, &channels).await),
                    Err(e) => Outcome::Failed(e.to_string()),
                },
            ));
        }
        let cam = &station.camera;
        // "camera (V4l on /dev/video0)", like the serial devices' labels.
        let camera_label = match &cam.device {
            Some(campanile_config::camera::DeviceRef::Path(p)) => format!("camera ({:?} on {p})", cam.driver),
            Some(campanile_config::camera::DeviceRef::Index(i)) => format!("camera ({:?} number {i})", cam.driver),
            Some(campanile_config::camera::DeviceRef::Indi { server, device, .. }) => {
                format!("camera (INDI {device:?} on {server})")
            }
            Some(campanile_config::camera::DeviceRef::Aravis { id, .. }) => format!("camera (GenICam {id:?})"),
            None => format!("camera ({:?}, its first device)", cam.driver),
        };
        let outcome = if cam.driver != CameraDriver::Sim && driver_built(cam.driver) {
            match open_station_camera(cam).await {
                Ok(mut camera) => Outcome::Tested(conformance::camera::run(&mut camera).await),
                Err(e) => Outcome::Failed(e.to_string()),
            }
        } else {
            Outcome::Skipped(
                open_camera(cam)
                    .err()
                    .map_or_else(|| "no driver".to_owned(), |e| e.to_string()),
            )
        };
        out.push((camera_label, outcome));
        Ok(out)
    })
}

/// A simulated station's devices: the emulators behind the same drivers,
/// under paused time, and the simulated camera on a uniform scene.
fn test_simulated(station: &Station, head_options: conformance::pan_tilt::Options) -> Result<Vec<(String, Outcome)>> {
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_time()
        .start_paused(true)
        .build()
        .context("starting the runtime")?;
    runtime.block_on(async {
        let source = Arc::new(UniformSource {
            radiance: [0.2, 0.2, 0.2],
        });
        let mut sim = SimStation::start(station, source, SimOptions::default())
            .await
            .context("starting the simulated station")?;
        let mut out = Vec::new();
        let h = &station.head;
        out.push((
            label("head", h.protocol, &h.link.port),
            Outcome::Tested(conformance::pan_tilt::run(&mut sim.head, head_options).await),
        ));
        if let (Some(w), Some(wheel)) = (&station.filter_wheel, sim.wheel.as_mut()) {
            out.push((
                wheel_label(w),
                Outcome::Tested(conformance::filter_wheel::run(wheel).await),
            ));
        }
        let channels: Vec<LightChannel> = station
            .lights
            .as_ref()
            .map(|l| (0..l.channels.len()).filter_map(|i| sim.light_channel(i)).collect())
            .unwrap_or_default();
        if let (Some(l), Some(lights)) = (&station.lights, sim.lights.as_mut()) {
            out.push((
                label("lights", l.protocol, &l.link.port),
                Outcome::Tested(conformance::lights::run(lights, &channels).await),
            ));
        }
        out.push((
            "camera (Sim)".to_owned(),
            Outcome::Tested(conformance::camera::run(&mut sim.camera).await),
        ));
        Ok(out)
    })
}
