//! A real station's devices, built from its configuration: each serial
//! device opened on its configured port with the driver its protocol
//! names, and reopened with exponential backoff when its link drops.
//!
//! ```no_run
//! # async fn demo(station: campanile_config::Station, camera: impl campanile_capture::device::Camera) {
//! use campanile_capture::station::{SerialOpener, StationOptions, StationRig};
//! let rig = StationRig::connect(&station, SerialOpener, camera, StationOptions::default()).await;
//! # }
//! ```
//!
//! [`StationRig`] is the controller's [`Rig`] for hardware: its
//! [`Rig::reconnect`] reopens the device's port and redoes the driver's
//! handshake under [`StationOptions::backoff`] (the controller calls it,
//! with its own doubling waits between calls, when a device call fails
//! with a link error). The ports come from a [`PortOpener`]: the real
//! serial ports ([`SerialOpener`]), or emulators in tests.
//!
//! Each device needs its own port: a campanile-link controller serving
//! head, wheel and lights on one line is refused ([`StationError::SharedPort`]).

pub mod camera;
pub mod devices;
pub mod port;

pub use camera::{StationCamera, driver_built, open_camera, open_station_camera};
pub use devices::{AnyHead, AnyLights, AnyWheel};
pub use port::{PortOpener, SerialOpener};

use crate::controller::{DeviceKind, Rig};
use crate::device::{Angle, Camera, DeviceError, LightChannel, Pose};
use crate::driver::backoff::{Backoff, reopen};
use crate::driver::enttec::DmxLights;
use crate::driver::flir_ptu::FlirHead;
use crate::driver::fw102c::Fw102cWheel;
use crate::driver::indi::IndiWheel;
use crate::driver::link::LinkController;
use crate::driver::pelco_d::PelcoHead;
use campanile_config::Station;
use campanile_config::filter_wheel::{FilterWheel as WheelConfig, WheelProtocol};
use campanile_config::head::{HeadProtocol, PanTiltHead};
use campanile_config::lights::{LightProtocol, Lights as LightsConfig};
use campanile_config::link::SerialLink;
use campanile_firmware_link::driver_error::DriverError;
use campanile_firmware_link::link::host::RetryPolicy;
use thiserror::Error;

/// Why a station's devices could not be set up.
#[derive(Debug, Error)]
pub enum StationError {
    /// A device's port is a simulator port.
    #[error(
        "port {port:?} of the {device} is a simulated port; a real station needs device paths such as /dev/ttyUSB0 (`campanile devices` lists them)"
    )]
    SimulatedPort {
        /// Which device.
        device: DeviceKind,
        /// Its configured port.
        port: String,
    },
    /// Two devices name the same port.
    #[error("the {first} and the {second} both use port {port:?}; each device needs a port of its own")]
    SharedPort {
        /// One device.
        first: DeviceKind,
        /// The other.
        second: DeviceKind,
        /// The port.
        port: String,
    },
    /// A device did not connect, after every try.
    #[error("connecting the {device} on {port}: {source}")]
    Connect {
        /// Which device.
        device: DeviceKind,
        /// Its port.
        port: String,
        /// The last failure.
        #[source]
        source: DeviceError,
    },
}

/// How a real station connects and reconnects.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StationOptions {
    /// Tries and waits when a port is opened or reopened.
    pub backoff: Backoff,
    /// How campanile-link drivers retry a request.
    pub link_retry: RetryPolicy,
    /// First campanile-link sequence number; each connection starts 4096
    /// further on, so a reconnected client does not reuse numbers the
    /// device still holds in its replay cache. Pick it from the clock in a
    /// program that may restart.
    pub link_seq: u16,
}

impl Default for StationOptions {
    /// [`Backoff::default`], [`RetryPolicy::default`], sequence numbers from 1.
    fn default() -> Self {
        Self {
            backoff: Backoff::default(),
            link_retry: RetryPolicy::default(),
            link_seq: 1,
        }
    }
}

fn link_error(e: std::io::Error) -> DeviceError {
    DeviceError::Link(DriverError::Io(e))
}

/// The configured ports, checked: real, and one per device.
pub fn check_ports(station: &Station) -> Result<(), StationError> {
    let mut ports: Vec<(DeviceKind, &SerialLink)> = vec![(DeviceKind::Head, &station.head.link)];
    if let Some(link) = station.filter_wheel.as_ref().and_then(|w| w.link.as_ref()) {
        ports.push((DeviceKind::Wheel, link));
    }
    if let Some(l) = &station.lights {
        ports.push((DeviceKind::Lights, &l.link));
    }
    for (i, (device, link)) in ports.iter().enumerate() {
        if link.is_simulated() {
            return Err(StationError::SimulatedPort {
                device: *device,
                port: link.port.clone(),
            });
        }
        if let Some((first, _)) = ports[..i].iter().find(|(_, l)| l.port == link.port) {
            return Err(StationError::SharedPort {
                first: *first,
                second: *device,
                port: link.port.clone(),
            });
        }
    }
    Ok(())
}

/// The pose a Pelco-D head calls home: (0°, 0°), moved into its limits.
fn pelco_home(cfg: &PanTiltHead) -> Pose {
    let l = &cfg.limits;
    Pose {
        pan: Angle::from_degrees(0f64.clamp(l.pan_min_deg, l.pan_max_deg)),
        tilt: Angle::from_degrees(0f64.clamp(l.tilt_min_deg, l.tilt_max_deg)),
    }
}

/// Open the head's port and connect its driver (one try).
pub async fn connect_head<O: PortOpener>(
    cfg: &PanTiltHead,
    opener: &O,
    link_retry: RetryPolicy,
    link_seq: u16,
) -> Result<AnyHead<O::Port>, DeviceError> {
    let io = opener.open(&cfg.link).await.map_err(link_error)?;
    let l = &cfg.limits;
    Ok(match cfg.protocol {
        HeadProtocol::PelcoD => AnyHead::PelcoD(
            PelcoHead::connect(
                io,
                cfg.address,
                (l.pan_min_deg, l.pan_max_deg),
                (l.tilt_min_deg, l.tilt_max_deg),
                pelco_home(cfg),
            )
            .await?,
        ),
        HeadProtocol::FlirPtu => AnyHead::FlirPtu(FlirHead::connect(io).await?),
        HeadProtocol::CampanileLink => AnyHead::Link(LinkController::connect(io, link_retry, link_seq).await?),
    })
}

/// Open the wheel's port and connect its driver (one try).
pub async fn connect_wheel<O: PortOpener>(
    cfg: &WheelConfig,
    opener: &O,
    link_retry: RetryPolicy,
    link_seq: u16,
) -> Result<AnyWheel<O::Port>, DeviceError> {
    if let (WheelProtocol::Indi, Some(indi)) = (cfg.protocol, &cfg.indi) {
        return Ok(AnyWheel::Indi(IndiWheel::open(&indi.server, &indi.device).await?));
    }
    let link = cfg.link.as_ref().ok_or_else(|| {
        link_error(std::io::Error::new(
            std::io::ErrorKind::NotFound,
            "the filter wheel has no serial link configured",
        ))
    })?;
    let io = opener.open(link).await.map_err(link_error)?;
    Ok(match cfg.protocol {
        WheelProtocol::Fw102c => AnyWheel::Fw102c(Fw102cWheel::connect(io).await?),
        WheelProtocol::CampanileLink | WheelProtocol::Indi => {
            AnyWheel::Link(LinkController::connect(io, link_retry, link_seq).await?)
        }
    })
}

/// Open the light controller's port and connect its driver (one try).
pub async fn connect_lights<O: PortOpener>(
    cfg: &LightsConfig,
    opener: &O,
    link_retry: RetryPolicy,
    link_seq: u16,
) -> Result<AnyLights<O::Port>, DeviceError> {
    let io = opener.open(&cfg.link).await.map_err(link_error)?;
    Ok(match cfg.protocol {
        LightProtocol::DmxEnttec => {
            let top = cfg.channels.iter().map(|c| c.channel).max().unwrap_or(1);
            AnyLights::Dmx(DmxLights::connect(io, top).await?)
        }
        LightProtocol::CampanileLink => AnyLights::Link(LinkController::connect(io, link_retry, link_seq).await?),
    })
}

/// The trait channel of the config's `index`-th lamp: DMX channels are
/// 1-based in the config and 0-based in the trait; campanile-link
/// channels are the same in both.
pub fn light_channel(cfg: &LightsConfig, index: usize) -> Option<LightChannel> {
    let c = cfg.channels.get(index)?.channel;
    Some(match cfg.protocol {
        LightProtocol::DmxEnttec => LightChannel(c.checked_sub(1)?),
        LightProtocol::CampanileLink => LightChannel(c),
    })
}

/// A real station: its camera and its serial devices, reconnectable.
#[derive(Debug)]
pub struct StationRig<O: PortOpener, C> {
    station: Station,
    opener: O,
    options: StationOptions,
    connections: u16,
    camera: C,
    head: AnyHead<O::Port>,
    wheel: Option<AnyWheel<O::Port>>,
    lights: Option<AnyLights<O::Port>>,
}

impl<O: PortOpener, C: Camera> StationRig<O, C> {
    /// Check the ports and connect every serial device of `station`, each
    /// under [`StationOptions::backoff`]; `camera` is already open.
    pub async fn connect(
        station: &Station,
        opener: O,
        camera: C,
        options: StationOptions,
    ) -> Result<Self, StationError> {
        check_ports(station)?;
        let mut connections = 0u16;
        let mut seq = || {
            connections = connections.wrapping_add(1);
            options
                .link_seq
                .wrapping_add(connections.wrapping_sub(1).wrapping_mul(4096))
        };
        let fail = |device, port: String| move |source| StationError::Connect { device, port, source };
        let (retry, backoff) = (options.link_retry, options.backoff);
        let s = seq();
        let head = reopen("head", backoff, || connect_head(&station.head, &opener, retry, s))
            .await
            .map_err(fail(DeviceKind::Head, station.head.link.port.clone()))?;
        let wheel = match &station.filter_wheel {
            Some(cfg) => {
                let s = seq();
                Some(
                    reopen("filter wheel", backoff, || connect_wheel(cfg, &opener, retry, s))
                        .await
                        .map_err(fail(DeviceKind::Wheel, cfg.place()))?,
                )
            }
            None => None,
        };
        let lights = match &station.lights {
            Some(cfg) => {
                let s = seq();
                Some(
                    reopen("lights", backoff, || connect_lights(cfg, &opener, retry, s))
                        .await
                        .map_err(fail(DeviceKind::Lights, cfg.link.port.clone()))?,
                )
            }
            None => None,
        };
        Ok(Self {
            station: station.clone(),
            opener,
            options,
            connections,
            camera,
            head,
            wheel,
            lights,
        })
    }

    fn next_seq(&mut self) -> u16 {
        self.connections = self.connections.wrapping_add(1);
        self.options
            .link_seq
            .wrapping_add(self.connections.wrapping_sub(1).wrapping_mul(4096))
    }

    /// The port opener (a test bench's ground truth).
    pub fn opener(&self) -> &O {
        &self.opener
    }

    /// How many connections were made, reconnections included.
    pub fn connections(&self) -> u16 {
        self.connections
    }
}

impl<O: PortOpener, C: Camera> Rig for StationRig<O, C> {
    type Camera = C;
    type Head = AnyHead<O::Port>;
    type Wheel = AnyWheel<O::Port>;
    type Lights = AnyLights<O::Port>;

    fn camera(&mut self) -> &mut C {
        &mut self.camera
    }

    fn head(&mut self) -> &mut Self::Head {
        &mut self.head
    }

    fn wheel(&mut self) -> Option<&mut Self::Wheel> {
        self.wheel.as_mut()
    }

    fn lights(&mut self) -> Option<&mut Self::Lights> {
        self.lights.as_mut()
    }

    fn light_channel(&self, index: usize) -> Option<LightChannel> {
        self.station.lights.as_ref().and_then(|l| light_channel(l, index))
    }

    /// Reopen the device's port and redo its handshake, under
    /// [`StationOptions::backoff`]. The camera is not reopened (its
    /// failures are retried by the controller as they are).
    async fn reconnect(&mut self, device: DeviceKind) -> Result<(), DeviceError> {
        let (retry, backoff) = (self.options.link_retry, self.options.backoff);
        let seq = self.next_seq();
        match device {
            DeviceKind::Camera => {
                // The camera reopens itself in place (an INDI camera
                // connects to its server anew), under the same backoff.
                let mut n = 0;
                loop {
                    tokio::time::sleep(backoff.wait_before(n)).await;
                    match self.camera.reconnect().await {
                        Ok(()) => return Ok(()),
                        Err(e) if n + 1 < backoff.attempts.max(1) => {
                            tracing::warn!(device = "camera", attempt = n + 1, error = %e, "reopening the camera failed");
                        }
                        Err(e) => return Err(e),
                    }
                    n += 1;
                }
            }
            DeviceKind::Head => {
                let (cfg, opener) = (&self.station.head, &self.opener);
                self.head = reopen("head", backoff, || connect_head(cfg, opener, retry, seq)).await?;
                Ok(())
            }
            DeviceKind::Wheel => {
                let (Some(cfg), opener) = (&self.station.filter_wheel, &self.opener) else {
                    return Ok(());
                };
                self.wheel = Some(reopen("filter wheel", backoff, || connect_wheel(cfg, opener, retry, seq)).await?);
                Ok(())
            }
            DeviceKind::Lights => {
                let (Some(cfg), opener) = (&self.station.lights, &self.opener) else {
                    return Ok(());
                };
                self.lights = Some(reopen("lights", backoff, || connect_lights(cfg, opener, retry, seq)).await?);
                Ok(())
            }
        }
    }
}
