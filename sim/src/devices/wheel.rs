//! The simulated filter wheel: a campanile-link or FW102C emulator with the
//! config's slots, and its host driver.
//!
//! The emulated wheels turn instantly (firmware-link's wheel models have no
//! turn time), so a frame never sees a wheel between slots. An FW102C has 6
//! or 12 positions; positions beyond the configured slots are empty holes
//! (transmittance 1).

use super::port::{DevicePort, HostStream};
use crate::error::SimError;
use crate::seed::Purpose;
use campanile_capture::device::{DeviceError, FilterWheel};
use campanile_capture::driver::fw102c::Fw102cWheel;
use campanile_capture::driver::link::LinkController;
use campanile_config::filter_wheel::{FilterWheel as WheelConfig, WheelProtocol};
use campanile_firmware_link::fw102c::device::WheelDevice;
use campanile_firmware_link::link::device::{DeviceConfig, LinkDevice};
use campanile_firmware_link::link::host::RetryPolicy;
use campanile_firmware_link::transport::fault::FaultConfig;
use std::time::Duration;

/// The wheel's firmware, whichever protocol it speaks.
#[derive(Debug, Clone)]
pub enum WheelPort {
    /// campanile-link.
    Link(DevicePort<LinkDevice>),
    /// Thorlabs FW102C.
    Fw102c(DevicePort<WheelDevice>),
}

impl WheelPort {
    /// Power on the wheel the config describes.
    pub fn new(cfg: &WheelConfig, tick: Duration, faults: FaultConfig) -> Result<Self, SimError> {
        let n = u8::try_from(cfg.slots.len())
            .ok()
            .filter(|n| (1..=12).contains(n))
            .ok_or_else(|| SimError::Unsupported(format!("a filter wheel with {} slots", cfg.slots.len())))?;
        let name = match (&cfg.link, cfg.protocol) {
            (Some(link), WheelProtocol::CampanileLink | WheelProtocol::Fw102c) => link.port.as_str(),
            _ => {
                return Err(SimError::Unsupported(format!(
                    "a filter wheel at {}: the simulator emulates serial wheels on `sim:` ports",
                    cfg.place()
                )));
            }
        };
        Ok(match cfg.protocol {
            WheelProtocol::CampanileLink => WheelPort::Link(DevicePort::new(
                name,
                LinkDevice::new(DeviceConfig {
                    filter_slots: n,
                    light_channels: 0,
                    ..DeviceConfig::default()
                }),
                tick,
                faults,
                Purpose::WheelLink,
            )),
            WheelProtocol::Fw102c | WheelProtocol::Indi => WheelPort::Fw102c(DevicePort::new(
                name,
                WheelDevice::new(if n <= 6 { 6 } else { 12 }),
                tick,
                faults,
                Purpose::WheelLink,
            )),
        })
    }

    fn name(&self) -> &str {
        match self {
            WheelPort::Link(p) => p.name(),
            WheelPort::Fw102c(p) => p.name(),
        }
    }

    /// Open the port and connect the host driver (campanile-link drivers
    /// retry with `policy`).
    pub async fn connect(&self, policy: RetryPolicy) -> Result<SimWheel, SimError> {
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
            WheelPort::Link(p) => {
                let io = open(p.open())?;
                let c = LinkController::connect(io, policy, 1).await.map_err(connect)?;
                Ok(SimWheel::Link(Box::new(c)))
            }
            WheelPort::Fw102c(p) => {
                let io = open(p.open())?;
                Ok(SimWheel::Fw102c(Box::new(
                    Fw102cWheel::connect(io).await.map_err(connect)?,
                )))
            }
        }
    }

    /// Disconnect the wheel for `duration`.
    pub fn disconnect(&self, duration: Duration) {
        match self {
            WheelPort::Link(p) => p.disconnect(duration),
            WheelPort::Fw102c(p) => p.disconnect(duration),
        }
    }

    /// The slot in place, 0-based (ground truth).
    pub fn slot(&self) -> usize {
        match self {
            WheelPort::Link(p) => usize::from(p.firmware().filter_slot()),
            WheelPort::Fw102c(p) => usize::from(p.firmware().position().saturating_sub(1)),
        }
    }
}

/// The host driver of the simulated wheel.
#[derive(Debug)]
pub enum SimWheel {
    /// campanile-link.
    Link(Box<LinkController<HostStream>>),
    /// Thorlabs FW102C.
    Fw102c(Box<Fw102cWheel<HostStream>>),
}

impl FilterWheel for SimWheel {
    fn slots(&self) -> u8 {
        match self {
            SimWheel::Link(w) => w.slots(),
            SimWheel::Fw102c(w) => w.slots(),
        }
    }

    async fn select(&mut self, slot: u8) -> Result<(), DeviceError> {
        match self {
            SimWheel::Link(w) => w.select(slot).await,
            SimWheel::Fw102c(w) => w.select(slot).await,
        }
    }

    async fn current(&mut self) -> Result<u8, DeviceError> {
        match self {
            SimWheel::Link(w) => w.current().await,
            SimWheel::Fw102c(w) => w.current().await,
        }
    }
}
