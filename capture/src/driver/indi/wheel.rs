//! An INDI filter wheel as a [`FilterWheel`]: `FILTER_SLOT`'s
//! `FILTER_SLOT_VALUE` (1-based on the wire, 0-based here), the slot
//! count from its range (or from `FILTER_NAME`).

use std::time::Duration;

use super::client::{IndiClient, PropertyState};
use crate::device::{DeviceError, FilterWheel};

/// How long a wheel may take to turn.
pub const TURN_TIMEOUT: Duration = Duration::from_secs(60);

/// An INDI filter wheel.
#[derive(Debug)]
pub struct IndiWheel {
    client: IndiClient,
    device: String,
    slots: u8,
}

impl IndiWheel {
    /// Opens the filter wheel `device` on the INDI server at `server`.
    pub async fn open(server: &str, device: &str) -> Result<Self, DeviceError> {
        let client = IndiClient::connect(server).await?;
        client.connect_device(device).await?;
        let slot = client.defined(device, "FILTER_SLOT").await?;
        let from_range = slot.item("FILTER_SLOT_VALUE").and_then(|i| i.max).map(|m| m as i64);
        let from_names = client.property(device, "FILTER_NAME").map(|p| p.items.len() as i64);
        let slots = from_range.or(from_names).unwrap_or(0);
        if !(1..=u8::MAX as i64).contains(&slots) {
            return Err(DeviceError::Camera(format!(
                "INDI device {device:?}: FILTER_SLOT states {slots} slots; expected 1 to 255"
            )));
        }
        Ok(IndiWheel {
            client,
            device: device.to_owned(),
            slots: slots as u8,
        })
    }

    /// The INDI connection.
    pub fn client(&self) -> &IndiClient {
        &self.client
    }
}

impl FilterWheel for IndiWheel {
    fn slots(&self) -> u8 {
        self.slots
    }

    async fn select(&mut self, slot: u8) -> Result<(), DeviceError> {
        if slot >= self.slots {
            return Err(DeviceError::OutOfRange {
                what: "filter slot",
                requested: f64::from(slot),
                min: 0.0,
                max: f64::from(self.slots - 1),
            });
        }
        let device = self.device.clone();
        let target = f64::from(slot) + 1.0;
        self.client
            .set_numbers(&device, "FILTER_SLOT", &[("FILTER_SLOT_VALUE", target)])
            .await?;
        self.client
            .wait_for(&format!("{device:?} turning to slot {slot}"), TURN_TIMEOUT, |m| {
                let Some(p) = m.property(&device, "FILTER_SLOT") else {
                    return Ok(None);
                };
                match p.state {
                    PropertyState::Alert => Err(DeviceError::Camera(format!(
                        "INDI wheel {device:?} failed to turn to slot {slot}: {}",
                        m.last_message(&device).unwrap_or("no message")
                    ))),
                    PropertyState::Ok | PropertyState::Idle if p.number("FILTER_SLOT_VALUE") == Some(target) => {
                        Ok(Some(()))
                    }
                    _ => Ok(None),
                }
            })
            .await
    }

    async fn current(&mut self) -> Result<u8, DeviceError> {
        let device = self.device.clone();
        let value = self
            .client
            .wait_for(&format!("{device:?} reporting its slot"), TURN_TIMEOUT, |m| {
                Ok(m.property(&device, "FILTER_SLOT")
                    .filter(|p| p.state != PropertyState::Busy)
                    .and_then(|p| p.number("FILTER_SLOT_VALUE")))
            })
            .await?;
        let slot = value.round() as i64 - 1;
        u8::try_from(slot).map_err(|_| {
            DeviceError::Camera(format!(
                "INDI wheel {device:?} reports slot {value}, outside 1..={}",
                self.slots
            ))
        })
    }
}
