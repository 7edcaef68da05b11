//! Conformance suite for any [`PanTilt`]: query, move, limits, home, stop,
//! and the error on an out-of-range move.
//!
//! Tolerance: a reported pose must be within one resolution step of the
//! requested one (the device rounds to the nearest step). The stop check
//! needs a head whose move across half its pan range takes longer than a
//! couple of command round trips, which holds for every real head.

use super::Report;
use crate::device::{Angle, DeviceError, PanTilt, PanTiltLimits, Pose};
use std::time::Duration;

/// Suite settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// Longest a single move may take.
    pub move_limit: Duration,
    /// How long a stopped head must stay put.
    pub settle: Duration,
}

impl Default for Options {
    /// 60 s per move, 300 ms settle.
    fn default() -> Self {
        Self {
            move_limit: Duration::from_secs(60),
            settle: Duration::from_millis(300),
        }
    }
}

fn lerp(lo: Angle, hi: Angle, t: f64) -> Angle {
    // Clamped, so that t = 1 gives exactly `hi` despite rounding.
    let (a, b) = (lo.radians(), hi.radians());
    let v = a + (b - a) * t;
    Angle::from_radians(v.clamp(a.min(b), a.max(b)))
}

fn at(l: &PanTiltLimits, u: f64, v: f64) -> Pose {
    Pose {
        pan: lerp(l.pan.min, l.pan.max, u),
        tilt: lerp(l.tilt.min, l.tilt.max, v),
    }
}

fn tol(l: &PanTiltLimits) -> Angle {
    Angle::from_radians(l.resolution.radians() * 1.01)
}

fn show(p: &Pose) -> String {
    format!("({:.4}°, {:.4}°)", p.pan.degrees(), p.tilt.degrees())
}

async fn goto<P: PanTilt>(head: &mut P, pose: Pose, o: &Options) -> Result<Pose, String> {
    head.move_to(pose)
        .await
        .map_err(|e| format!("move to {}: {e}", show(&pose)))?;
    head.wait_idle(o.move_limit)
        .await
        .map_err(|e| format!("waiting for {}: {e}", show(&pose)))
}

async fn arrive<P: PanTilt>(head: &mut P, pose: Pose, o: &Options) -> Result<(), String> {
    let l = head.limits();
    let got = goto(head, pose, o).await?;
    if !got.within(&pose, tol(&l)) {
        return Err(format!("asked for {}, rested at {}", show(&pose), show(&got)));
    }
    let s = head.status().await.map_err(|e| e.to_string())?;
    if s.moving || !s.pose.within(&pose, tol(&l)) {
        return Err(format!(
            "after the move, status says {} (moving: {})",
            show(&s.pose),
            s.moving
        ));
    }
    Ok(())
}

async fn check_query<P: PanTilt>(head: &mut P, o: &Options) -> Result<(), String> {
    let l = head.limits();
    if !(l.pan.min < l.pan.max && l.tilt.min < l.tilt.max) || l.resolution.radians() <= 0.0 {
        return Err(format!("implausible limits {l:?}"));
    }
    let a = head.wait_idle(o.move_limit).await.map_err(|e| e.to_string())?;
    let b = head.status().await.map_err(|e| e.to_string())?;
    if !l.contains(&b.pose) {
        return Err(format!("reported pose {} is outside the limits", show(&b.pose)));
    }
    if b.moving || !a.within(&b.pose, tol(&l)) {
        return Err(format!(
            "at rest at {} but status says {} (moving: {})",
            show(&a),
            show(&b.pose),
            b.moving
        ));
    }
    Ok(())
}

async fn check_moves<P: PanTilt>(head: &mut P, o: &Options) -> Result<(), String> {
    let l = head.limits();
    for (u, v) in [(0.25, 0.25), (0.75, 0.6), (0.1, 0.9), (0.5, 0.5)] {
        arrive(head, at(&l, u, v), o).await?;
    }
    Ok(())
}

async fn check_limits<P: PanTilt>(head: &mut P, o: &Options) -> Result<(), String> {
    let l = head.limits();
    for (u, v) in [(0.0, 0.0), (1.0, 1.0), (0.0, 1.0), (1.0, 0.0)] {
        arrive(head, at(&l, u, v), o).await?;
    }
    Ok(())
}

async fn check_out_of_range<P: PanTilt>(head: &mut P, o: &Options) -> Result<(), String> {
    let l = head.limits();
    let start = at(&l, 0.4, 0.4);
    arrive(head, start, o).await?;
    let beyond = Angle::from_radians(l.resolution.radians() * 10.0 + 1e-3);
    let outside = [
        Pose {
            pan: Angle::from_radians(l.pan.max.radians() + beyond.radians()),
            ..start
        },
        Pose {
            pan: Angle::from_radians(l.pan.min.radians() - beyond.radians()),
            ..start
        },
        Pose {
            tilt: Angle::from_radians(l.tilt.max.radians() + beyond.radians()),
            ..start
        },
        Pose {
            tilt: Angle::from_radians(l.tilt.min.radians() - beyond.radians()),
            ..start
        },
    ];
    for p in outside {
        match head.move_to(p).await {
            Err(DeviceError::OutOfRange { .. }) => {}
            Err(e) => return Err(format!("move to {} failed with {e}, not OutOfRange", show(&p))),
            Ok(()) => return Err(format!("move to {} was accepted", show(&p))),
        }
        let s = head.status().await.map_err(|e| e.to_string())?;
        if s.moving || !s.pose.within(&start, tol(&l)) {
            return Err(format!(
                "after the refused move to {}, the head is at {} (moving: {})",
                show(&p),
                show(&s.pose),
                s.moving
            ));
        }
    }
    Ok(())
}

async fn check_home<P: PanTilt>(head: &mut P, o: &Options) -> Result<(), String> {
    let l = head.limits();
    arrive(head, at(&l, 0.8, 0.2), o).await?;
    head.home().await.map_err(|e| e.to_string())?;
    let got = head.wait_idle(o.move_limit).await.map_err(|e| e.to_string())?;
    if !got.within(&l.home, tol(&l)) {
        return Err(format!(
            "home is {} but the head rested at {}",
            show(&l.home),
            show(&got)
        ));
    }
    Ok(())
}

async fn check_stop<P: PanTilt>(head: &mut P, o: &Options) -> Result<(), String> {
    let l = head.limits();
    let (a, b) = (at(&l, 0.05, 0.5), at(&l, 0.95, 0.5));
    arrive(head, a, o).await?;
    head.move_to(b).await.map_err(|e| e.to_string())?;
    let stopped = head.stop().await.map_err(|e| e.to_string())?;
    tokio::time::sleep(o.settle).await;
    let s = head.status().await.map_err(|e| e.to_string())?;
    let t = tol(&l);
    if s.moving || !s.pose.within(&stopped, t) {
        return Err(format!(
            "stopped at {} but then at {} (moving: {})",
            show(&stopped),
            show(&s.pose),
            s.moving
        ));
    }
    let (lo, hi) = (a.pan.radians() - t.radians(), b.pan.radians() + t.radians());
    let pan = s.pose.pan.radians();
    // A head whose pan range is a whole turn may take the other arc,
    // across the wrap (a Pelco-D head told 18° → 342° on a 0–360° station
    // turns down through 0°, and a stop that lands late leaves it at 17°).
    let full_turn = l.pan.max.radians() - l.pan.min.radians() >= std::f64::consts::TAU - 2.0 * t.radians();
    let other_arc = full_turn && (pan <= a.pan.radians() + t.radians() || pan >= b.pan.radians() - t.radians());
    if !((lo..=hi).contains(&pan) || other_arc) {
        return Err(format!(
            "stopped at {}, off the path from {} to {}",
            show(&s.pose),
            show(&a),
            show(&b)
        ));
    }
    if s.pose.within(&b, t) {
        return Err(format!("the head reached {} despite the stop", show(&b)));
    }
    Ok(())
}

/// Run every check against `head`; it moves across its whole range.
pub async fn run<P: PanTilt>(head: &mut P, options: Options) -> Report {
    let mut r = Report::default();
    r.record(
        "query: status at rest, within limits",
        check_query(head, &options).await,
    );
    r.record("move: reaches requested poses", check_moves(head, &options).await);
    r.record("limits: reaches every corner", check_limits(head, &options).await);
    r.record(
        "out of range: refused with OutOfRange, head stays",
        check_out_of_range(head, &options).await,
    );
    r.record("home: returns to the home pose", check_home(head, &options).await);
    r.record("stop: halts on the path and stays", check_stop(head, &options).await);
    r
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::device::HeadStatus;
    use crate::driver::flir_ptu::FlirHead;
    use crate::driver::link::LinkController;
    use crate::driver::pelco_d::PelcoHead;
    use campanile_firmware_link::emulator::Emulator;
    use campanile_firmware_link::flir_ptu::device::{PtuConfig, PtuDevice};
    use campanile_firmware_link::link::device::{DeviceConfig, LinkDevice};
    use campanile_firmware_link::link::host::RetryPolicy;
    use campanile_firmware_link::pelco_d::device::{PelcoConfig, PelcoDevice};
    use campanile_firmware_link::transport::memory::duplex;

    const TICK: Duration = Duration::from_millis(5);

    #[tokio::test(start_paused = true)]
    async fn campanile_link_head_conforms() {
        let (host, dev) = duplex(4096);
        let _emu = Emulator::spawn(LinkDevice::new(DeviceConfig::default()), dev, TICK);
        let mut head = LinkController::connect(host, RetryPolicy::default(), 9).await.unwrap();
        let report = run(&mut head, Options::default()).await;
        assert!(report.passed(), "{report}");
        assert_eq!(report.checks.len(), 6);
    }

    #[tokio::test(start_paused = true)]
    async fn pelco_d_head_conforms() {
        let (host, dev) = duplex(4096);
        let _emu = Emulator::spawn(PelcoDevice::new(PelcoConfig::default()), dev, TICK);
        let mut head = PelcoHead::new(host, 1, (-179.99, 179.99), (-90.0, 90.0), Pose::default());
        let report = run(&mut head, Options::default()).await;
        assert!(report.passed(), "{report}");
    }

    #[tokio::test(start_paused = true)]
    async fn flir_ptu_conforms() {
        let (host, dev) = duplex(4096);
        let _emu = Emulator::spawn(PtuDevice::new(PtuConfig::default()), dev, TICK);
        let mut head = FlirHead::connect(host).await.unwrap();
        let report = run(&mut head, Options::default()).await;
        assert!(report.passed(), "{report}");
    }

    /// A head with one seeded defect; the suite must catch each.
    #[derive(Clone, Copy)]
    enum Defect {
        /// Lands 0.1° off in pan.
        Drift,
        /// Accepts moves beyond its limits.
        NoLimitCheck,
        /// Jumps to its target at once, so stop has no effect.
        NoStop,
        /// Turns the other way round (down through the wrap), so a stop
        /// halts it 1° below where it started.
        OtherArc,
    }

    /// Moves complete in `wait_idle`; a stop halts halfway.
    struct Broken {
        pose: Pose,
        target: Pose,
        limits: PanTiltLimits,
        defect: Defect,
    }

    impl PanTilt for Broken {
        fn limits(&self) -> PanTiltLimits {
            self.limits
        }
        async fn move_to(&mut self, pose: Pose) -> Result<(), DeviceError> {
            if !matches!(self.defect, Defect::NoLimitCheck) {
                self.limits.check(&pose)?;
            }
            self.target = pose;
            if let Defect::Drift = self.defect {
                self.target.pan = Angle::from_radians(pose.pan.radians() + 0.1f64.to_radians());
            }
            Ok(())
        }
        async fn status(&mut self) -> Result<HeadStatus, DeviceError> {
            Ok(HeadStatus {
                pose: self.pose,
                moving: self.pose != self.target,
            })
        }
        async fn wait_idle(&mut self, _limit: Duration) -> Result<Pose, DeviceError> {
            self.pose = self.target;
            Ok(self.pose)
        }
        async fn home(&mut self) -> Result<(), DeviceError> {
            self.target = self.limits.home;
            Ok(())
        }
        async fn stop(&mut self) -> Result<Pose, DeviceError> {
            if let Defect::OtherArc = self.defect {
                self.target = Pose {
                    pan: Angle::from_degrees(self.pose.pan.degrees() - 1.0),
                    tilt: self.pose.tilt,
                };
            } else if !matches!(self.defect, Defect::NoStop) {
                self.target = Pose {
                    pan: lerp(self.pose.pan, self.target.pan, 0.5),
                    tilt: lerp(self.pose.tilt, self.target.tilt, 0.5),
                };
            }
            self.pose = self.target;
            Ok(self.pose)
        }
    }

    async fn failures_of(defect: Defect) -> Vec<&'static str> {
        failures_over(defect, (-170.0, 170.0)).await
    }

    async fn failures_over(defect: Defect, (pan_min, pan_max): (f64, f64)) -> Vec<&'static str> {
        let limits = PanTiltLimits {
            pan: crate::device::AxisRange {
                min: Angle::from_degrees(pan_min),
                max: Angle::from_degrees(pan_max),
            },
            tilt: crate::device::AxisRange {
                min: Angle::from_degrees(-30.0),
                max: Angle::from_degrees(90.0),
            },
            resolution: Angle::from_degrees(0.01),
            home: Pose::default(),
        };
        let mut head = Broken {
            pose: Pose::default(),
            target: Pose::default(),
            limits,
            defect,
        };
        let report = run(&mut head, Options::default()).await;
        report.failures().iter().map(|c| c.name).collect()
    }

    #[tokio::test(start_paused = true)]
    async fn broken_heads_fail_the_suite() {
        assert_eq!(
            failures_of(Defect::NoLimitCheck).await,
            ["out of range: refused with OutOfRange, head stays"]
        );
        assert_eq!(failures_of(Defect::NoStop).await, ["stop: halts on the path and stays"]);
        // Stopped 1° short of where it set out: off the path on a head of
        // 340°, on the other arc of one that turns a whole way round.
        assert_eq!(
            failures_of(Defect::OtherArc).await,
            ["stop: halts on the path and stays"]
        );
        assert!(failures_over(Defect::OtherArc, (0.0, 359.99)).await.is_empty());
        let drift = failures_of(Defect::Drift).await;
        assert!(drift.contains(&"move: reaches requested poses"), "{drift:?}");
        assert!(drift.contains(&"limits: reaches every corner"), "{drift:?}");
    }
}
