//! The simulated light controller: a campanile-link or Enttec DMX USB Pro
//! emulator, and its host driver.
//!
//! Channel numbers are the config's: campanile-link channel `c` is the
//! trait's `LightChannel(c)` (so the emulated controller has
//! `max(c) + 1` ≤ 8 channels); DMX channel `c` is `LightChannel(c − 1)`.
//! [`LightsPort::trait_channel`] does the mapping.

use super::port::{DevicePort, HostStream};
use crate::error::SimError;
use crate::seed::Purpose;
use campanile_capture::device::{DeviceError, Level, LightChannel, Lights};
use campanile_capture::driver::enttec::DmxLights;
use campanile_capture::driver::link::LinkController;
use campanile_config::lights::{LightProtocol, Lights as LightsConfig};
use campanile_firmware_link::enttec::device::DmxDevice;
use campanile_firmware_link::link::device::{DeviceConfig, LinkDevice};
use campanile_firmware_link::link::host::RetryPolicy;
use campanile_firmware_link::link::message::MAX_LIGHT_CHANNELS;
use campanile_firmware_link::transport::fault::FaultConfig;
use std::time::Duration;

/// The light controller's firmware, whichever protocol it speaks.
#[derive(Debug, Clone)]
pub enum LightsPort {
    /// campanile-link, with the config's channel numbers.
    Link(DevicePort<LinkDevice>, Vec<u16>),
    /// Enttec DMX USB Pro, with the config's DMX channel numbers.
    Dmx(DevicePort<DmxDevice>, Vec<u16>),
}

impl LightsPort {
    /// Power on the controller the config describes.
    pub fn new(cfg: &LightsConfig, tick: Duration, faults: FaultConfig) -> Result<Self, SimError> {
        let channels: Vec<u16> = cfg.channels.iter().map(|c| c.channel).collect();
        let top = channels.iter().copied().max().unwrap_or(0);
        let name = cfg.link.port.as_str();
        Ok(match cfg.protocol {
            LightProtocol::CampanileLink => {
                let count = u8::try_from(top + 1)
                    .ok()
                    .filter(|&n| usize::from(n) <= MAX_LIGHT_CHANNELS)
                    .ok_or_else(|| {
                        SimError::Unsupported(format!(
                            "campanile-link light channel {top} (at most {})",
                            MAX_LIGHT_CHANNELS - 1
                        ))
                    })?;
                let dev = LinkDevice::new(DeviceConfig {
                    filter_slots: 0,
                    light_channels: count,
                    ..DeviceConfig::default()
                });
                LightsPort::Link(DevicePort::new(name, dev, tick, faults, Purpose::LightsLink), channels)
            }
            LightProtocol::DmxEnttec => LightsPort::Dmx(
                DevicePort::new(name, DmxDevice::new(1), tick, faults, Purpose::LightsLink),
                channels,
            ),
        })
    }

    fn name(&self) -> &str {
        match self {
            LightsPort::Link(p, _) => p.name(),
            LightsPort::Dmx(p, _) => p.name(),
        }
    }

    /// The trait channel that drives the config's `index`-th lamp.
    pub fn trait_channel(&self, index: usize) -> Option<LightChannel> {
        match self {
            LightsPort::Link(_, ch) => ch.get(index).map(|&c| LightChannel(c)),
            LightsPort::Dmx(_, ch) => ch.get(index).map(|&c| LightChannel(c.saturating_sub(1))),
        }
    }

    /// Open the port and connect the host driver (campanile-link drivers
    /// retry with `policy`).
    pub async fn connect(&self, policy: RetryPolicy) -> Result<SimLights, SimError> {
        let port = self.name().to_string();
        let open = |r: std::io::Result<HostStream>| {
            r.map_err(|source| SimError::Open {
                port: port.clone(),
                error: source,
            })
        };
        match self {
            LightsPort::Link(p, _) => {
                let io = open(p.open())?;
                let c = LinkController::connect(io, policy, 1)
                    .await
                    .map_err(|source| SimError::Connect {
                        port: port.clone(),
                        error: source,
                    })?;
                Ok(SimLights::Link(Box::new(c)))
            }
            LightsPort::Dmx(p, ch) => {
                let io = open(p.open())?;
                let n = ch.iter().copied().max().unwrap_or(1);
                Ok(SimLights::Dmx(Box::new(DmxLights::new(io, n))))
            }
        }
    }

    /// Disconnect the controller for `duration`.
    pub fn disconnect(&self, duration: Duration) {
        match self {
            LightsPort::Link(p, _) => p.disconnect(duration),
            LightsPort::Dmx(p, _) => p.disconnect(duration),
        }
    }

    /// Each lamp's level, 0..=1, in the config's channel order (ground truth).
    pub fn levels(&self) -> Vec<f64> {
        match self {
            LightsPort::Link(p, ch) => {
                let fw = p.firmware();
                let l = fw.light_levels();
                ch.iter()
                    .map(|&c| l.get(usize::from(c)).map_or(0.0, |&v| f64::from(v) / 65_535.0))
                    .collect()
            }
            LightsPort::Dmx(p, ch) => {
                let fw = p.firmware();
                let u = fw.universe();
                ch.iter()
                    .map(|&c| {
                        usize::from(c)
                            .checked_sub(1)
                            .and_then(|i| u.get(i))
                            .map_or(0.0, |&v| f64::from(v) / 255.0)
                    })
                    .collect()
            }
        }
    }
}

/// The host driver of the simulated lights.
#[derive(Debug)]
pub enum SimLights {
    /// campanile-link.
    Link(Box<LinkController<HostStream>>),
    /// Enttec DMX USB Pro.
    Dmx(Box<DmxLights<HostStream>>),
}

impl Lights for SimLights {
    fn channels(&self) -> u16 {
        match self {
            SimLights::Link(l) => l.channels(),
            SimLights::Dmx(l) => l.channels(),
        }
    }

    async fn set_level(&mut self, channel: LightChannel, level: Level) -> Result<(), DeviceError> {
        match self {
            SimLights::Link(l) => l.set_level(channel, level).await,
            SimLights::Dmx(l) => l.set_level(channel, level).await,
        }
    }

    async fn all_off(&mut self) -> Result<(), DeviceError> {
        match self {
            SimLights::Link(l) => l.all_off().await,
            SimLights::Dmx(l) => l.all_off().await,
        }
    }
}
