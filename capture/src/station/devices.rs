//! One type per device role, whichever protocol the station's
//! configuration names: the device traits are generic, not object-safe,
//! so a runtime choice is an enum that forwards each call.

use crate::device::{DeviceError, FilterWheel, HeadStatus, Level, LightChannel, Lights, PanTilt, PanTiltLimits, Pose};
use crate::driver::enttec::DmxLights;
use crate::driver::flir_ptu::FlirHead;
use crate::driver::fw102c::Fw102cWheel;
use crate::driver::link::LinkController;
use crate::driver::pelco_d::PelcoHead;
use std::time::Duration;
use tokio::io::{AsyncRead, AsyncWrite};

/// A pan-tilt head of any supported protocol.
#[derive(Debug)]
pub enum AnyHead<T> {
    /// Pelco-D.
    PelcoD(PelcoHead<T>),
    /// FLIR PTU ASCII.
    FlirPtu(FlirHead<T>),
    /// campanile-link.
    Link(LinkController<T>),
}

/// A filter wheel of any supported protocol.
#[derive(Debug)]
pub enum AnyWheel<T> {
    /// Thorlabs FW102C.
    Fw102c(Fw102cWheel<T>),
    /// campanile-link.
    Link(LinkController<T>),
    /// A filter wheel on an INDI server.
    Indi(crate::driver::indi::IndiWheel),
}

/// A light controller of any supported protocol. (One of each exists per
/// station, so the DMX universe is held inline.)
#[derive(Debug)]
#[allow(clippy::large_enum_variant)]
pub enum AnyLights<T> {
    /// Enttec DMX USB Pro.
    Dmx(DmxLights<T>),
    /// campanile-link.
    Link(LinkController<T>),
}

macro_rules! each {
    ($self:ident, $d:ident => $e:expr, $($v:ident),+) => {
        match $self { $(Self::$v($d) => $e,)+ }
    };
}

impl<T: AsyncRead + AsyncWrite + Unpin + Send> PanTilt for AnyHead<T> {
    fn limits(&self) -> PanTiltLimits {
        each!(self, h => h.limits(), PelcoD, FlirPtu, Link)
    }

    async fn move_to(&mut self, pose: Pose) -> Result<(), DeviceError> {
        each!(self, h => h.move_to(pose).await, PelcoD, FlirPtu, Link)
    }

    async fn status(&mut self) -> Result<HeadStatus, DeviceError> {
        each!(self, h => h.status().await, PelcoD, FlirPtu, Link)
    }

    async fn wait_idle(&mut self, limit: Duration) -> Result<Pose, DeviceError> {
        each!(self, h => h.wait_idle(limit).await, PelcoD, FlirPtu, Link)
    }

    async fn home(&mut self) -> Result<(), DeviceError> {
        each!(self, h => h.home().await, PelcoD, FlirPtu, Link)
    }

    async fn stop(&mut self) -> Result<Pose, DeviceError> {
        each!(self, h => h.stop().await, PelcoD, FlirPtu, Link)
    }
}

impl<T: AsyncRead + AsyncWrite + Unpin + Send> FilterWheel for AnyWheel<T> {
    fn slots(&self) -> u8 {
        each!(self, w => w.slots(), Fw102c, Link, Indi)
    }

    async fn select(&mut self, slot: u8) -> Result<(), DeviceError> {
        each!(self, w => w.select(slot).await, Fw102c, Link, Indi)
    }

    async fn current(&mut self) -> Result<u8, DeviceError> {
        each!(self, w => w.current().await, Fw102c, Link, Indi)
    }
}

impl<T: AsyncRead + AsyncWrite + Unpin + Send> Lights for AnyLights<T> {
    fn channels(&self) -> u16 {
        each!(self, l => l.channels(), Dmx, Link)
    }

    async fn set_level(&mut self, channel: LightChannel, level: Level) -> Result<(), DeviceError> {
        each!(self, l => l.set_level(channel, level).await, Dmx, Link)
    }

    async fn all_off(&mut self) -> Result<(), DeviceError> {
        each!(self, l => l.all_off().await, Dmx, Link)
    }
}
