//! The simulated pan-tilt head: a firmware emulator for the protocol the
//! station config names, with the config's limits and dynamics, and the
//! host driver from `capture` that talks to it.
//!
//! | protocol | unit (count) | speeds | notes |
//! | --- | --- | --- | --- |
//! | CampanileLink | 1 µrad | pan and tilt separately | reports "moving" through the settle time |
//! | PelcoD | 0.01° | the pan speed for both axes (the emulator sets one speed per move) | limits clamped to ±179.99° pan, ±90° tilt; idle = position equals target |
//! | FlirPtu | 0.01° per step (36″) | pan and tilt separately | `A` (await) waits through the settle time |
//!
//! Home is pan 0, tilt 0 (clamped into the limits), as every driver
//! assumes. With encoder noise the Pelco-D and FLIR drivers, which call a
//! head idle only when its reported position equals the target, rarely see
//! it idle: use campanile-link for noisy heads.

use super::port::{DevicePort, HostStream};
use crate::error::SimError;
use crate::seed::Purpose;
use campanile_capture::device::{DeviceError, HeadStatus, PanTilt, PanTiltLimits, Pose};
use campanile_capture::driver::flir_ptu::FlirHead;
use campanile_capture::driver::link::LinkController;
use campanile_capture::driver::pelco_d::PelcoHead;
use campanile_config::head::{HeadProtocol, PanTiltHead};
use campanile_firmware_link::flir_ptu::device::{PtuConfig, PtuDevice};
use campanile_firmware_link::link::device::{DeviceConfig, LinkDevice};
use campanile_firmware_link::link::host::{LinkStats, RetryPolicy};
use campanile_firmware_link::motion::{Dynamics, Head};
use campanile_firmware_link::pelco_d::device::{PelcoConfig, PelcoDevice};
use campanile_firmware_link::transport::fault::FaultConfig;
use campanile_process::pose::HeadPose;
use std::time::Duration;

/// Counts per radian of campanile-link (µrad).
const LINK_COUNTS_PER_RAD: f64 = 1e6;
/// Counts per radian of Pelco-D and of the simulated PTU (0.01°).
const CENTIDEG_PER_RAD: f64 = 18_000.0 / std::f64::consts::PI;
/// The simulated PTU's resolution, 1/10000 arc-second per step (36″ = 0.01°).
const PTU_RESOLUTION_E4_ARCSEC: u32 = 360_000;

/// Head imperfections the station config does not describe.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct HeadImperfections {
    /// Standard deviation of the encoder noise, degrees (0: none).
    pub encoder_noise_deg: f64,
    /// Backlash width, degrees (0: none).
    pub backlash_deg: f64,
    /// Seed of the encoder noise.
    pub seed: u64,
}

/// The head's firmware, whichever protocol it speaks.
#[derive(Debug, Clone)]
pub enum HeadPort {
    /// campanile-link.
    Link(DevicePort<LinkDevice>),
    /// Pelco-D.
    Pelco(DevicePort<PelcoDevice>, u8, PanTiltHead),
    /// FLIR PTU.
    Flir(DevicePort<PtuDevice>),
}

fn counts(deg: f64, per_rad: f64) -> i32 {
    (deg.to_radians() * per_rad).round() as i32
}

fn speed(deg_s: f64, per_rad: f64) -> u32 {
    (deg_s.to_radians() * per_rad).round().clamp(1.0, f64::from(u32::MAX)) as u32
}

fn configure(head: &mut Head, cfg: &PanTiltHead, imp: &HeadImperfections, per_rad: f64) {
    let d = cfg.dynamics;
    let dynamics = Dynamics {
        accel: speed(d.acceleration_deg_s2, per_rad),
        settle_ms: (d.settle_s * 1000.0).round().clamp(0.0, 60_000.0) as u32,
        backlash: imp.backlash_deg.to_radians() * per_rad,
        encoder_sigma: imp.encoder_noise_deg.to_radians() * per_rad,
    };
    head.pan.dynamics = dynamics;
    head.tilt.dynamics = dynamics;
    head.tilt.speed = speed(d.tilt_speed_deg_s, per_rad);
    head.seed_encoder(imp.seed);
}

impl HeadPort {
    /// Power on the head the config describes.
    pub fn new(cfg: &PanTiltHead, imp: &HeadImperfections, tick: Duration, faults: FaultConfig) -> Self {
        let l = cfg.limits;
        let name = cfg.link.port.as_str();
        match cfg.protocol {
            HeadProtocol::CampanileLink => {
                let r = |lo: f64, hi: f64| (counts(lo, LINK_COUNTS_PER_RAD), counts(hi, LINK_COUNTS_PER_RAD));
                let pan_range = r(l.pan_min_deg, l.pan_max_deg);
                let tilt_range = r(l.tilt_min_deg, l.tilt_max_deg);
                let mut dev = LinkDevice::new(DeviceConfig {
                    pan_range,
                    tilt_range,
                    home: (0.clamp(pan_range.0, pan_range.1), 0.clamp(tilt_range.0, tilt_range.1)),
                    speed: speed(cfg.dynamics.pan_speed_deg_s, LINK_COUNTS_PER_RAD),
                    accel: speed(cfg.dynamics.acceleration_deg_s2, LINK_COUNTS_PER_RAD),
                    filter_slots: 0,
                    light_channels: 0,
                    firmware: [1, 0, 0],
                });
                configure(dev.head_mut(), cfg, imp, LINK_COUNTS_PER_RAD);
                HeadPort::Link(DevicePort::new(name, dev, tick, faults, Purpose::HeadLink))
            }
            HeadProtocol::PelcoD => {
                let c = |deg: f64, lim: i32| counts(deg, CENTIDEG_PER_RAD).clamp(-lim, lim);
                let mut dev = PelcoDevice::new(PelcoConfig {
                    address: cfg.address,
                    pan_range: (c(l.pan_min_deg, 17_999), c(l.pan_max_deg, 17_999)),
                    tilt_range: (c(l.tilt_min_deg, 9_000), c(l.tilt_max_deg, 9_000)),
                    speed: speed(cfg.dynamics.pan_speed_deg_s, CENTIDEG_PER_RAD),
                });
                configure(dev.head_mut(), cfg, imp, CENTIDEG_PER_RAD);
                HeadPort::Pelco(
                    DevicePort::new(name, dev, tick, faults, Purpose::HeadLink),
                    cfg.address,
                    cfg.clone(),
                )
            }
            HeadProtocol::FlirPtu => {
                let r = |lo: f64, hi: f64| (counts(lo, CENTIDEG_PER_RAD), counts(hi, CENTIDEG_PER_RAD));
                let mut dev = PtuDevice::new(PtuConfig {
                    pan_range: r(l.pan_min_deg, l.pan_max_deg),
                    tilt_range: r(l.tilt_min_deg, l.tilt_max_deg),
                    resolution_e4_arcsec: PTU_RESOLUTION_E4_ARCSEC,
                    speed: speed(cfg.dynamics.pan_speed_deg_s, CENTIDEG_PER_RAD),
                });
                configure(dev.head_mut(), cfg, imp, CENTIDEG_PER_RAD);
                HeadPort::Flir(DevicePort::new(name, dev, tick, faults, Purpose::HeadLink))
            }
        }
    }

    /// The port name.
    pub fn name(&self) -> &str {
        match self {
            HeadPort::Link(p) => p.name(),
            HeadPort::Pelco(p, ..) => p.name(),
            HeadPort::Flir(p) => p.name(),
        }
    }

    /// Open the port and connect the host driver (campanile-link drivers
    /// retry with `policy`).
    pub async fn connect(&self, policy: RetryPolicy) -> Result<SimHead, SimError> {
        let port = self.name().to_string();
        let open = |r: std::io::Result<HostStream>| {
            r.map_err(|source| SimError::Open {
                port: port.clone(),
                error: source,
            })
        };
        let connect = |source| SimError::Connect {
            port: port.clone(),
            error: source,
        };
        match self {
            HeadPort::Link(p) => {
                let io = open(p.open())?;
                let c = LinkController::connect(io, policy, 1).await.map_err(connect)?;
                Ok(SimHead::Link(Box::new(c)))
            }
            HeadPort::Pelco(p, address, cfg) => {
                let io = open(p.open())?;
                let l = cfg.limits;
                let clampd = |d: f64, lim: f64| d.clamp(-lim, lim);
                Ok(SimHead::Pelco(Box::new(PelcoHead::new(
                    io,
                    *address,
                    (clampd(l.pan_min_deg, 179.99), clampd(l.pan_max_deg, 179.99)),
                    (clampd(l.tilt_min_deg, 90.0), clampd(l.tilt_max_deg, 90.0)),
                    Pose::default(),
                ))))
            }
            HeadPort::Flir(p) => {
                let io = open(p.open())?;
                Ok(SimHead::Flir(Box::new(FlirHead::connect(io).await.map_err(connect)?)))
            }
        }
    }

    /// Disconnect the head for `duration`.
    pub fn disconnect(&self, duration: Duration) {
        match self {
            HeadPort::Link(p) => p.disconnect(duration),
            HeadPort::Pelco(p, ..) => p.disconnect(duration),
            HeadPort::Flir(p) => p.disconnect(duration),
        }
    }

    fn with_head<R>(&self, f: impl FnOnce(&Head) -> R) -> (R, f64) {
        match self {
            HeadPort::Link(p) => (f(p.firmware().head()), LINK_COUNTS_PER_RAD),
            HeadPort::Pelco(p, ..) => (f(p.firmware().head()), CENTIDEG_PER_RAD),
            HeadPort::Flir(p) => (f(p.firmware().head()), CENTIDEG_PER_RAD),
        }
    }

    /// The head's true mechanical angles (after backlash, without encoder
    /// noise), in its own reading frame.
    pub fn true_pose(&self) -> HeadPose {
        let ((p, t), per_rad) = self.with_head(|h| (h.pan.true_position(), h.tilt.true_position()));
        HeadPose {
            pan_rad: p / per_rad,
            tilt_rad: t / per_rad,
        }
    }

    /// The commanded angles (the axes' targets).
    pub fn commanded_pose(&self) -> HeadPose {
        let ((p, t), per_rad) = self.with_head(|h| (f64::from(h.pan.target), f64::from(h.tilt.target)));
        HeadPose {
            pan_rad: p / per_rad,
            tilt_rad: t / per_rad,
        }
    }

    /// Whether the head is travelling or settling.
    pub fn moving(&self) -> bool {
        self.with_head(Head::moving).0
    }
}

/// The host driver of the simulated head, whichever protocol it speaks.
#[derive(Debug)]
pub enum SimHead {
    /// campanile-link.
    Link(Box<LinkController<HostStream>>),
    /// Pelco-D.
    Pelco(Box<PelcoHead<HostStream>>),
    /// FLIR PTU.
    Flir(Box<FlirHead<HostStream>>),
}

impl SimHead {
    /// The campanile-link client's counters (requests, retries), for a
    /// campanile-link head.
    pub fn link_stats(&mut self) -> Option<LinkStats> {
        match self {
            SimHead::Link(c) => Some(c.client().stats()),
            _ => None,
        }
    }
}

impl PanTilt for SimHead {
    fn limits(&self) -> PanTiltLimits {
        match self {
            SimHead::Link(h) => h.limits(),
            SimHead::Pelco(h) => h.limits(),
            SimHead::Flir(h) => h.limits(),
        }
    }

    async fn move_to(&mut self, pose: Pose) -> Result<(), DeviceError> {
        match self {
            SimHead::Link(h) => h.move_to(pose).await,
            SimHead::Pelco(h) => h.move_to(pose).await,
            SimHead::Flir(h) => h.move_to(pose).await,
        }
    }

    async fn status(&mut self) -> Result<HeadStatus, DeviceError> {
        match self {
            SimHead::Link(h) => h.status().await,
            SimHead::Pelco(h) => h.status().await,
            SimHead::Flir(h) => h.status().await,
        }
    }

    async fn wait_idle(&mut self, limit: Duration) -> Result<Pose, DeviceError> {
        match self {
            SimHead::Link(h) => h.wait_idle(limit).await,
            SimHead::Pelco(h) => h.wait_idle(limit).await,
            SimHead::Flir(h) => h.wait_idle(limit).await,
        }
    }

    async fn home(&mut self) -> Result<(), DeviceError> {
        match self {
            SimHead::Link(h) => h.home().await,
            SimHead::Pelco(h) => h.home().await,
            SimHead::Flir(h) => h.home().await,
        }
    }

    async fn stop(&mut self) -> Result<Pose, DeviceError> {
        match self {
            SimHead::Link(h) => h.stop().await,
            SimHead::Pelco(h) => h.stop().await,
            SimHead::Flir(h) => h.stop().await,
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::camera::UniformSource;
    use crate::station::fixture::example_station;
    use crate::station::{SimOptions, SimStation};
    use campanile_capture::conformance::pan_tilt::{Options, run};
    use campanile_capture::device::{Angle, DeviceError, PanTilt, Pose};
    use campanile_capture::driver::POLL;
    use campanile_config::head::HeadProtocol;
    use std::sync::Arc;
    use std::time::Duration;
    use tokio::time::Instant;

    use super::HeadImperfections;

    async fn station(protocol: HeadProtocol, head: HeadImperfections) -> SimStation<UniformSource> {
        let mut st = example_station();
        st.head.protocol = protocol;
        let source = Arc::new(UniformSource { radiance: [0.1; 3] });
        let options = SimOptions {
            head,
            ..SimOptions::default()
        };
        SimStation::start(&st, source, options).await.unwrap()
    }

    const PROTOCOLS: [HeadProtocol; 3] = [HeadProtocol::CampanileLink, HeadProtocol::PelcoD, HeadProtocol::FlirPtu];

    /// capture's pan-tilt conformance suite passes against the simulated
    /// head (with the example's acceleration and settle time) for each
    /// protocol.
    #[tokio::test(start_paused = true)]
    async fn conformance_suite_passes_for_every_head_protocol() {
        for p in PROTOCOLS {
            let mut sim = station(p, HeadImperfections::default()).await;
            let report = run(&mut sim.head, Options::default()).await;
            assert!(report.passed(), "{p:?}:\n{report}");
        }
    }

    /// 90° of pan at 60°/s with 120°/s² and 0.2 s settle: the trapezoid
    /// takes v/a + d/v = 0.5 + 1.5 = 2.0 s, so the firmware reports idle at
    /// 2.2 s, within one emulator tick (2 ms) plus the 1 ms we poll it at;
    /// the driver sees it within one more poll period (20 ms).
    #[tokio::test(start_paused = true)]
    async fn ninety_degree_pan_is_idle_at_the_analytic_time() {
        let mut sim = station(HeadProtocol::CampanileLink, HeadImperfections::default()).await;
        let truth = sim.truth();
        let port = truth.head.as_ref().unwrap();
        sim.head.move_to(Pose::from_degrees(90.0, 0.0)).await.unwrap();
        let t0 = Instant::now();
        while port.moving() {
            tokio::time::sleep(Duration::from_millis(1)).await;
        }
        let firmware_idle = t0.elapsed().as_secs_f64();
        assert!((firmware_idle - 2.2).abs() <= 0.003, "{firmware_idle} s");

        sim.head.move_to(Pose::from_degrees(0.0, 0.0)).await.unwrap();
        let t0 = Instant::now();
        sim.head.wait_idle(Duration::from_secs(10)).await.unwrap();
        let driver_idle = t0.elapsed().as_secs_f64();
        let slack = POLL.as_secs_f64() + 0.003;
        assert!(
            driver_idle >= 2.2 - 0.003 && driver_idle <= 2.2 + slack,
            "{driver_idle} s"
        );
    }

    /// Encoder noise of σ = 0.01°: 2000 status reads of a head at rest have
    /// a standard deviation of 0.01° within 10% (the estimate's own spread
    /// is σ/√(2n) ≈ 1.6%; rounding to 1 µrad adds nothing visible), and the
    /// true pose stays exactly where it was sent.
    #[tokio::test(start_paused = true)]
    async fn reported_positions_scatter_with_the_configured_sigma() {
        let imp = HeadImperfections {
            encoder_noise_deg: 0.01,
            ..HeadImperfections::default()
        };
        let mut sim = station(HeadProtocol::CampanileLink, imp).await;
        sim.head.move_to(Pose::from_degrees(20.0, 10.0)).await.unwrap();
        sim.head.wait_idle(Duration::from_secs(10)).await.unwrap();
        let n = 2000;
        let mut pans = Vec::with_capacity(n);
        for _ in 0..n {
            pans.push(sim.head.status().await.unwrap().pose.pan.degrees());
        }
        let mean = pans.iter().sum::<f64>() / n as f64;
        let sd = (pans.iter().map(|p| (p - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt();
        assert!((sd / 0.01 - 1.0).abs() < 0.1, "sd {sd}°");
        assert!((mean - 20.0).abs() < 0.001, "mean {mean}°");
        assert!((sim.true_head_pose().pan_rad.to_degrees() - 20.0).abs() < 1e-4);
    }

    /// Backlash of 0.5°: after a move in the negative direction the output
    /// sits on the command; after the reversal to +20° it stops 0.5° short
    /// (the known dead band), while the motor encoder reports 20°.
    #[tokio::test(start_paused = true)]
    async fn backlash_shows_after_a_reversal() {
        let imp = HeadImperfections {
            backlash_deg: 0.5,
            ..HeadImperfections::default()
        };
        let mut sim = station(HeadProtocol::CampanileLink, imp).await;
        let res = sim.head.limits().resolution;
        sim.head.move_to(Pose::from_degrees(-10.0, 0.0)).await.unwrap();
        sim.head.wait_idle(Duration::from_secs(10)).await.unwrap();
        assert!((sim.true_head_pose().pan_rad.to_degrees() + 10.0).abs() < 1e-4);
        sim.head.move_to(Pose::from_degrees(20.0, 0.0)).await.unwrap();
        let reported = sim.head.wait_idle(Duration::from_secs(10)).await.unwrap();
        assert!(reported.within(&Pose::from_degrees(20.0, 0.0), res));
        let commanded = sim.commanded_head_pose().unwrap().pan_rad.to_degrees();
        let lag = commanded - sim.true_head_pose().pan_rad.to_degrees();
        assert!((lag - 0.5).abs() < 1e-4, "lag {lag}°");
    }

    /// Beyond the config's tilt limit (90°) a move is refused with
    /// OutOfRange and the head does not move; `home` brings it back to
    /// (0, 0) within one resolution step, for each protocol.
    #[tokio::test(start_paused = true)]
    async fn limits_refuse_and_home_returns_home() {
        for p in PROTOCOLS {
            let mut sim = station(p, HeadImperfections::default()).await;
            let res = sim.head.limits().resolution;
            sim.head.move_to(Pose::from_degrees(45.0, 20.0)).await.unwrap();
            sim.head.wait_idle(Duration::from_secs(10)).await.unwrap();
            let before = sim.true_head_pose();
            let r = sim.head.move_to(Pose::from_degrees(45.0, 95.0)).await;
            assert!(matches!(r, Err(DeviceError::OutOfRange { .. })), "{p:?}: {r:?}");
            tokio::time::sleep(Duration::from_secs(1)).await;
            assert_eq!(sim.true_head_pose(), before, "{p:?}");
            sim.head.home().await.unwrap();
            let at = sim.head.wait_idle(Duration::from_secs(10)).await.unwrap();
            assert!(at.within(&Pose::default(), res), "{p:?}: {at:?}");
            let t = sim.true_head_pose();
            let tol = Angle::from_degrees(0.01).radians();
            assert!(t.pan_rad.abs() <= tol && t.tilt_rad.abs() <= tol, "{p:?}: {t:?}");
        }
    }
}
