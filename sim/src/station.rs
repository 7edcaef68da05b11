//! A whole simulated station assembled from a station config: the camera,
//! the head, the filter wheel and the lights, each an emulator behind the
//! same byte protocol as the real device and driven by `capture`'s real
//! host driver, plus ground-truth accessors.
//!
//! ```no_run
//! # async fn demo(station: campanile_config::Station) -> Result<(), campanile_sim::error::SimError> {
//! use campanile_capture::device::{Camera, PanTilt, Pose};
//! use campanile_sim::camera::UniformSource;
//! use campanile_sim::station::{SimOptions, SimStation};
//! use std::sync::Arc;
//! let source = Arc::new(UniformSource { radiance: [0.2; 3] });
//! let mut sim = SimStation::start(&station, source, SimOptions::default()).await?;
//! sim.head.move_to(Pose::from_degrees(30.0, 10.0)).await.ok();
//! println!("true head pose: {:?}", sim.true_head_pose());
//! # Ok(()) }
//! ```
//!
//! Each config device is its own emulator on its own port, even when two
//! campanile-link devices name the same port (a real controller would
//! serve both on one line). The simulated calendar starts at
//! [`SimOptions::origin`] when the station starts.

use crate::camera::{CameraOptions, FrameSource, SimCamera};
use crate::clock::SimClock;
use crate::devices::DeviceTruth;
use crate::devices::head::{HeadImperfections, HeadPort, SimHead};
use crate::devices::lights::{LightsPort, SimLights};
use crate::devices::wheel::{SimWheel, WheelPort};
use crate::error::SimError;
use crate::faults::{Device, FaultPlan, LinkFaults};
use crate::seed::{Purpose, derive};
use campanile_capture::device::LightChannel;
use campanile_config::Station;
use campanile_firmware_link::link::host::RetryPolicy;
use campanile_firmware_link::link::soak::PROVEN_POLICY;
use campanile_process::pose::HeadPose;
use chrono::{DateTime, Utc};
use std::sync::Arc;
use std::time::Duration;

/// Simulation settings beyond the station config.
#[derive(Debug, Clone, PartialEq)]
pub struct SimOptions {
    /// The calendar time at which the station starts.
    pub origin: DateTime<Utc>,
    /// Where the head stands, world frame (x east, y north, z up), metres.
    pub position_m: [f64; 3],
    /// How often a busy emulator is advanced.
    pub tick: Duration,
    /// Head imperfections (encoder noise, backlash); the seed is replaced
    /// by one derived from the station seed.
    pub head: HeadImperfections,
    /// The camera.
    pub camera: CameraOptions,
    /// Faults (camera faults, outages, link-fault overrides).
    pub faults: FaultPlan,
    /// How the campanile-link drivers retry, at start-up and after. Left
    /// at the driver's default (20 attempts of 100 ms, which a link with a
    /// few percent of byte faults can exhaust) on a link with byte faults,
    /// the station uses [`PROVEN_POLICY`], which the link soak proves up to
    /// [`PROVEN_FAULT_CHANCE`](campanile_firmware_link::link::soak::PROVEN_FAULT_CHANCE)
    /// of drop and of corruption.
    pub retry: RetryPolicy,
}

impl Default for SimOptions {
    /// 2024-06-21 19:00 UTC (local noon in California), at the origin, 2 ms
    /// ticks, a perfect head, the default camera, no faults beyond the
    /// config's link faults.
    fn default() -> Self {
        Self {
            origin: DateTime::from_timestamp(1_718_996_400, 0).unwrap_or_default(),
            position_m: [0.0; 3],
            tick: Duration::from_millis(2),
            head: HeadImperfections::default(),
            camera: CameraOptions::default(),
            faults: FaultPlan::default(),
            retry: RetryPolicy::default(),
        }
    }
}

/// A running simulated station. The driver handles are public fields, so a
/// controller can borrow them while a test reads ground truth.
#[derive(Debug)]
pub struct SimStation<S> {
    /// The camera.
    pub camera: SimCamera<S>,
    /// The head's host driver.
    pub head: SimHead,
    /// The filter wheel's host driver.
    pub wheel: Option<SimWheel>,
    /// The lights' host driver.
    pub lights: Option<SimLights>,
    truth: DeviceTruth,
    clock: SimClock,
    retry: RetryPolicy,
    home_m: [f64; 3],
    /// Where the head truly stands whatever the plan's poses say (the
    /// simulation's `true_camera.head_position_m`: a tripod set up away from
    /// the scene's poses, which the station does not know).
    true_position_m: Option<[f64; 3]>,
}

impl<S: FrameSource> SimStation<S> {
    /// Power on every device of `station`, connect the host drivers, and
    /// schedule the fault plan's outages.
    pub async fn start(station: &Station, source: Arc<S>, options: SimOptions) -> Result<Self, SimError> {
        let clock = SimClock::start(options.origin);
        let (seed, config_faults) = match &station.simulation {
            Some(s) => (
                s.seed,
                LinkFaults {
                    drop_chance: s.link_drop_chance,
                    corrupt_chance: s.link_corrupt_chance,
                },
            ),
            None => (0, LinkFaults::default()),
        };
        let link = options.faults.link.unwrap_or(config_faults).config(seed);
        let faulty = link.drop_chance > 0.0 || link.corrupt_chance > 0.0;
        let retry = if faulty && options.retry == RetryPolicy::default() {
            PROVEN_POLICY
        } else {
            options.retry
        };
        let imperfections = HeadImperfections {
            seed: derive(seed, Purpose::Encoder, 0),
            ..options.head
        };
        let head_port = HeadPort::new(&station.head, &imperfections, options.tick, link);
        let wheel_port = station
            .filter_wheel
            .as_ref()
            .map(|w| WheelPort::new(w, options.tick, link))
            .transpose()?;
        let lights_port = station
            .lights
            .as_ref()
            .map(|l| LightsPort::new(l, options.tick, link))
            .transpose()?;
        let head = head_port.connect(retry).await?;
        let wheel = match &wheel_port {
            Some(p) => Some(p.connect(retry).await?),
            None => None,
        };
        let lights = match &lights_port {
            Some(p) => Some(p.connect(retry).await?),
            None => None,
        };
        let truth = DeviceTruth {
            head: Some(head_port),
            wheel: wheel_port,
            lights: lights_port,
        };
        for outage in &options.faults.outages {
            let truth = truth.clone();
            let o = *outage;
            let at = clock.origin() + o.after;
            tokio::spawn(async move {
                tokio::time::sleep_until(at).await;
                disconnect(&truth, o.device, o.duration);
            });
        }
        let true_position_m = station
            .simulation
            .as_ref()
            .and_then(|s| s.true_camera.as_ref())
            .and_then(|c| c.head_position_m)
            .map(|(x, y, z)| [x, y, z]);
        let home_m = true_position_m.unwrap_or(options.position_m);
        let filters = station
            .filter_wheel
            .as_ref()
            .map(|w| w.slots.iter().map(|s| s.transmittance()).collect())
            .unwrap_or_default();
        let camera = SimCamera::new(
            source,
            &station.camera,
            filters,
            truth.clone(),
            clock,
            home_m,
            seed,
            options.camera,
        );
        Ok(Self {
            camera,
            head,
            wheel,
            lights,
            truth,
            clock,
            retry,
            home_m,
            true_position_m,
        })
    }

    /// The simulated calendar.
    pub fn clock(&self) -> SimClock {
        self.clock
    }

    /// Where the station stands when not at a named pose
    /// ([`SimOptions::position_m`], or the true camera's head position).
    pub fn home_position(&self) -> [f64; 3] {
        self.home_m
    }

    /// Where the camera stands for a view aimed from `pose_position_m`: the
    /// pose's place, unless the simulation puts the tripod somewhere the
    /// station does not know (`true_camera.head_position_m`), which then
    /// holds for every frame.
    pub fn position_for(&self, pose_position_m: Option<[f64; 3]>) -> [f64; 3] {
        self.true_position_m.or(pose_position_m).unwrap_or(self.home_m)
    }

    /// The devices' ground truth (shareable).
    pub fn truth(&self) -> DeviceTruth {
        self.truth.clone()
    }

    /// The head's true mechanical angles (after backlash, without encoder noise).
    pub fn true_head_pose(&self) -> HeadPose {
        self.truth.head_pose()
    }

    /// The head's commanded angles.
    pub fn commanded_head_pose(&self) -> Option<HeadPose> {
        self.truth.head.as_ref().map(HeadPort::commanded_pose)
    }

    /// The filter slot in place, 0-based.
    pub fn wheel_slot(&self) -> Option<usize> {
        self.truth.wheel_slot()
    }

    /// Light levels, 0..=1, in the config's channel order.
    pub fn light_levels(&self) -> Vec<f64> {
        self.truth.light_levels()
    }

    /// The trait channel driving the config's `index`-th lamp.
    pub fn light_channel(&self, index: usize) -> Option<LightChannel> {
        self.truth.lights.as_ref().and_then(|l| l.trait_channel(index))
    }

    /// Frames the camera has delivered.
    pub fn frames_taken(&self) -> usize {
        self.camera.frames_taken()
    }

    /// Disconnect `device` now for `duration` (its driver's link fails).
    pub fn disconnect(&self, device: Device, duration: Duration) {
        disconnect(&self.truth, device, duration);
    }

    /// Reconnect the head: open its port anew and connect a fresh driver,
    /// which replaces [`SimStation::head`]. Fails while it is disconnected.
    pub async fn reconnect_head(&mut self) -> Result<(), SimError> {
        if let Some(p) = &self.truth.head {
            self.head = p.connect(self.retry).await?;
        }
        Ok(())
    }

    /// Reconnect the filter wheel (see [`SimStation::reconnect_head`]).
    pub async fn reconnect_wheel(&mut self) -> Result<(), SimError> {
        if let Some(p) = &self.truth.wheel {
            self.wheel = Some(p.connect(self.retry).await?);
        }
        Ok(())
    }

    /// Reconnect the lights (see [`SimStation::reconnect_head`]).
    pub async fn reconnect_lights(&mut self) -> Result<(), SimError> {
        if let Some(p) = &self.truth.lights {
            self.lights = Some(p.connect(self.retry).await?);
        }
        Ok(())
    }
}

fn disconnect(truth: &DeviceTruth, device: Device, duration: Duration) {
    match device {
        Device::Head => {
            if let Some(p) = &truth.head {
                p.disconnect(duration);
            }
        }
        Device::Wheel => {
            if let Some(p) = &truth.wheel {
                p.disconnect(duration);
            }
        }
        Device::Lights => {
            if let Some(p) = &truth.lights {
                p.disconnect(duration);
            }
        }
    }
}

#[cfg(test)]
pub(crate) mod fixture {
    //! The example station with small frames, for tests.
    use campanile_config::Station;
    use campanile_config::camera::Resolution;
    use std::path::Path;

    /// `examples/sim-station.ron` with 32×24 frames.
    pub(crate) fn example_station() -> Station {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/sim-station.ron");
        let mut s = campanile_config::load_station(&path)
            .expect("the example station loads")
            .value;
        s.camera.resolution = Resolution { width: 32, height: 24 };
        s
    }
}

#[cfg(test)]
mod tests {
    use super::fixture::example_station;
    use super::*;
    use crate::camera::UniformSource;
    use crate::faults::Outage;
    use campanile_capture::device::{
        Camera, CaptureSettings, DeviceError, ExposureTime, FilterWheel, Gain, Level, Lights, PanTilt, Pose,
    };
    use campanile_config::station::Simulation;
    use tokio::time::Instant;

    fn source() -> Arc<UniformSource> {
        Arc::new(UniformSource {
            radiance: [0.2, 0.3, 0.4],
        })
    }

    /// 2% drop and 2% corruption on every link: 50 head moves complete
    /// through the campanile-link driver's retries, each ending where it
    /// was sent (true pose within 1 µrad, the protocol unit).
    #[tokio::test(start_paused = true)]
    async fn head_completes_50_moves_through_a_faulty_link() {
        let mut st = example_station();
        st.simulation = Some(Simulation {
            seed: 11,
            link_drop_chance: 0.02,
            link_corrupt_chance: 0.02,
            true_camera: None,
        });
        // The soak test's policy: 30 ms per attempt, up to 500 attempts.
        let options = SimOptions {
            retry: RetryPolicy {
                timeout: Duration::from_millis(30),
                max_attempts: 500,
            },
            ..SimOptions::default()
        };
        let mut sim = SimStation::start(&st, source(), options).await.unwrap();
        for i in 0..50 {
            let pose = Pose::from_degrees(f64::from(i * 37 % 300) - 150.0, f64::from(i * 13 % 100) - 20.0);
            sim.head.move_to(pose).await.unwrap();
            sim.head.wait_idle(Duration::from_secs(60)).await.unwrap();
            let truth = sim.true_head_pose();
            assert!(
                (truth.pan_rad - pose.pan.radians()).abs() < 1.5e-6,
                "move {i}: {truth:?}"
            );
            assert!(
                (truth.tilt_rad - pose.tilt.radians()).abs() < 1.5e-6,
                "move {i}: {truth:?}"
            );
        }
        let stats = sim.head.link_stats().unwrap();
        let faults = match &sim.truth().head {
            Some(HeadPort::Link(p)) => p.fault_counts(),
            _ => unreachable!("the example head speaks campanile-link"),
        };
        println!("link: {stats:?}; faults [bytes, dropped, corrupted, ..]: {faults:?}");
        assert!(stats.retries > 0, "{stats:?}");
        assert!(faults[1] > 0 && faults[2] > 0, "{faults:?}");
    }

    /// The head disconnects for 5 simulated seconds: its driver fails with a
    /// link error, reconnecting fails while it is away, and works after.
    #[tokio::test(start_paused = true)]
    async fn head_disconnects_for_5_s_and_reconnects() {
        let st = example_station();
        let options = SimOptions {
            faults: FaultPlan {
                outages: vec![Outage {
                    device: Device::Head,
                    after: Duration::from_secs(10),
                    duration: Duration::from_secs(5),
                }],
                ..FaultPlan::default()
            },
            ..SimOptions::default()
        };
        let mut sim = SimStation::start(&st, source(), options).await.unwrap();
        sim.head.move_to(Pose::from_degrees(30.0, 0.0)).await.unwrap();
        sim.head.wait_idle(Duration::from_secs(5)).await.unwrap();
        tokio::time::sleep(Duration::from_secs(11)).await;
        assert!(matches!(sim.head.status().await, Err(DeviceError::Link(_))));
        assert!(matches!(sim.reconnect_head().await, Err(SimError::Open { .. })));
        tokio::time::sleep(Duration::from_secs(4)).await;
        sim.reconnect_head().await.unwrap();
        let s = sim.head.status().await.unwrap();
        // The head kept its pose while away.
        assert!(
            s.pose
                .within(&Pose::from_degrees(30.0, 0.0), sim.head.limits().resolution)
        );
        sim.head.move_to(Pose::from_degrees(-10.0, 5.0)).await.unwrap();
        let p = sim.head.wait_idle(Duration::from_secs(5)).await.unwrap();
        assert!(p.within(&Pose::from_degrees(-10.0, 5.0), sim.head.limits().resolution));
    }

    /// A whole simulated day: every 10 minutes for 24 h, a head move, a
    /// filter change, a light level and a capture: 144 frames, stamped 10
    /// minutes apart on the simulated calendar.
    #[tokio::test(start_paused = true)]
    async fn a_simulated_day_of_activity() {
        let st = example_station();
        let mut sim = SimStation::start(&st, source(), SimOptions::default()).await.unwrap();
        let start = Instant::now();
        let step = Duration::from_secs(600);
        let lamp = sim.light_channel(0).unwrap();
        for i in 0..144u32 {
            tokio::time::sleep_until(start + step * i).await;
            let pose = Pose::from_degrees(f64::from(i % 36) * 10.0 - 175.0, f64::from(i % 9) * 10.0);
            sim.head.move_to(pose).await.unwrap();
            sim.head.wait_idle(Duration::from_secs(30)).await.unwrap();
            let slot = (i % 6) as u8;
            let wheel = sim.wheel.as_mut().unwrap();
            wheel.select(slot).await.unwrap();
            let lights = sim.lights.as_mut().unwrap();
            lights
                .set_level(lamp, Level::new(f64::from(i % 5) / 4.0).unwrap())
                .await
                .unwrap();
            let frame = sim
                .camera
                .capture(CaptureSettings {
                    exposure: ExposureTime::from_seconds(0.01).unwrap(),
                    gain: Gain::UNITY,
                })
                .await
                .unwrap();
            assert_eq!(frame.sequence, u64::from(i));
            assert_eq!(sim.wheel_slot(), Some(usize::from(slot)));
            assert!((sim.light_levels()[0] - f64::from(i % 5) / 4.0).abs() < 1e-4);
            let truth = sim.camera.last_truth().unwrap();
            assert_eq!(truth.filter_slot, Some(usize::from(slot)));
            assert!((truth.view.head.pan_rad - pose.pan.radians()).abs() < 1e-6);
        }
        assert_eq!(sim.frames_taken(), 144);
        // Each frame starts within 30 s after its 10-minute mark (a move
        // takes at most 7 s, a filter change and a light level moments).
        let origin = SimOptions::default().origin;
        for (i, t) in sim.camera.truth_log().iter().enumerate() {
            let after = (t.view.time - origin).num_milliseconds() - 600_000 * i as i64;
            assert!((0..30_000).contains(&after), "frame {i}: {after} ms after its mark");
        }
    }
}
