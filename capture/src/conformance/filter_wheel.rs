//! Conformance suite for any [`FilterWheel`]: every slot is reached and
//! reported, and a slot past the last is refused with the wheel left
//! where it was.

use super::Report;
use crate::device::{DeviceError, FilterWheel};

async fn check_every_slot<W: FilterWheel>(wheel: &mut W) -> Result<(), String> {
    let n = wheel.slots();
    if n == 0 {
        return Err("the wheel reports no slots".into());
    }
    // Forward, then back to the first (a wheel that turns one way only
    // must still get there).
    for slot in (0..n).chain([0]) {
        wheel
            .select(slot)
            .await
            .map_err(|e| format!("select slot {slot}: {e}"))?;
        let at = wheel
            .current()
            .await
            .map_err(|e| format!("after selecting {slot}: {e}"))?;
        if at != slot {
            return Err(format!("selected slot {slot}, the wheel reports {at}"));
        }
    }
    Ok(())
}

async fn check_out_of_range<W: FilterWheel>(wheel: &mut W) -> Result<(), String> {
    let n = wheel.slots();
    let before = wheel.current().await.map_err(|e| e.to_string())?;
    match wheel.select(n).await {
        Err(DeviceError::OutOfRange { .. }) => {}
        Ok(()) => return Err(format!("slot {n} of a {n}-slot wheel was accepted")),
        Err(e) => return Err(format!("slot {n}: expected OutOfRange, got {e}")),
    }
    let after = wheel.current().await.map_err(|e| e.to_string())?;
    if after != before {
        return Err(format!("the refused select moved the wheel from {before} to {after}"));
    }
    Ok(())
}

/// Run every check on `wheel`.
pub async fn run<W: FilterWheel>(wheel: &mut W) -> Report {
    let mut r = Report::default();
    r.record("slots: each selected and reported", check_every_slot(wheel).await);
    r.record(
        "out of range: refused with OutOfRange, wheel stays",
        check_out_of_range(wheel).await,
    );
    r
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::driver::fw102c::Fw102cWheel;
    use campanile_firmware_link::emulator::Emulator;
    use campanile_firmware_link::fw102c::device::WheelDevice;
    use campanile_firmware_link::transport::memory::duplex;
    use std::time::Duration;

    #[tokio::test(start_paused = true)]
    async fn fw102c_conforms() {
        let (host, dev) = duplex(1024);
        let _emu = Emulator::spawn(WheelDevice::new(6), dev, Duration::from_millis(5));
        let mut w = Fw102cWheel::connect(host).await.unwrap();
        let report = run(&mut w).await;
        assert!(report.passed(), "{report}");
        assert_eq!(report.checks.len(), 2);
    }

    /// A wheel that reports one slot off fails the slot check, naming it.
    #[tokio::test]
    async fn an_off_by_one_wheel_fails() {
        struct OffByOne(u8);
        impl FilterWheel for OffByOne {
            fn slots(&self) -> u8 {
                4
            }
            async fn select(&mut self, slot: u8) -> Result<(), DeviceError> {
                self.0 = slot;
                Ok(())
            }
            async fn current(&mut self) -> Result<u8, DeviceError> {
                Ok((self.0 + 1) % 4)
            }
        }
        let report = run(&mut OffByOne(0)).await;
        assert!(!report.passed());
        assert_eq!(
            report.checks[0].failure.as_deref(),
            Some("selected slot 0, the wheel reports 1")
        );
        assert_eq!(
            report.checks[1].failure.as_deref(),
            Some("slot 4 of a 4-slot wheel was accepted")
        );
    }
}
