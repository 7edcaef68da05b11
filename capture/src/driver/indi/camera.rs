//! An INDI `CCD` device as a [`Camera`]: exposure through `CCD_EXPOSURE`,
//! the frame as a FITS BLOB on `CCD1`, the exposure, start time and sensor
//! temperature from the FITS header (what the camera reports, not what was
//! asked). DSLRs reach INDI through `indi_gphoto_ccd`, so this covers them.
//!
//! On opening: the device is connected, its images are asked for (BLOBs,
//! uploaded to the client, FITS, uncompressed, light frames, no binning),
//! and the frame is set to the configured resolution, centred on the sensor
//! (`CCD_FRAME`). Gain stays as the device has it: INDI gains are in each
//! driver's own units, not dB, so the camera states unity gain only.

use std::time::Duration;

use chrono::{DateTime, NaiveDateTime, Utc};

use super::client::{IndiClient, PropertyState};
use crate::device::{
    Camera, CameraInfo, CaptureSettings, DeviceError, ExposureRange, ExposureTime, Frame, FrameFile, FrameFormat, Gain,
    GainRange,
};
use campanile_process::hdr::fits_file::read_fits;

/// How long a frame may take beyond its exposure (read-out, download).
pub const READOUT_TIMEOUT: Duration = Duration::from_secs(60);

/// An INDI CCD.
#[derive(Debug)]
pub struct IndiCamera {
    client: IndiClient,
    server: String,
    device: String,
    resolution: Option<(u32, u32)>,
    sensor: CcdSettings,
    info: CameraInfo,
    sequence: u64,
}

/// The sensor's gain or ISO, held for the whole session (INDI's units are
/// each driver's own, so they are set as the driver states them, not in
/// dB; the frames' FITS headers record them, e.g. `GAIN`).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CcdSettings {
    /// `CCD_GAIN.GAIN`, in the driver's units, within its stated range.
    pub gain: Option<f64>,
    /// A `CCD_ISO` switch (a DSLR through `indi_gphoto_ccd`), by its name
    /// or label, e.g. "100" or "ISO 100".
    pub iso: Option<String>,
}

impl IndiCamera {
    /// Opens the CCD `device` on the INDI server at `server` (`host:port`),
    /// its frame `resolution` (width, height) centred on the sensor, or the
    /// whole sensor when `None`, at the driver's own gain.
    pub async fn open(server: &str, device: &str, resolution: Option<(u32, u32)>) -> Result<Self, DeviceError> {
        Self::open_with(server, device, resolution, &CcdSettings::default()).await
    }

    /// [`IndiCamera::open`], then the gain or ISO of `sensor` set; a value
    /// the device does not offer is refused, naming what it offers.
    pub async fn open_with(
        server: &str,
        device: &str,
        resolution: Option<(u32, u32)>,
        sensor: &CcdSettings,
    ) -> Result<Self, DeviceError> {
        let client = IndiClient::connect(server).await?;
        client.connect_device(device).await?;
        client.defined(device, "CCD_INFO").await?;
        let exposure = client.defined(device, "CCD_EXPOSURE").await?;
        client.defined(device, "CCD1").await?;
        client.enable_blobs(device).await?;
        // What a station needs, where the device offers it.
        for (property, item) in [
            ("UPLOAD_MODE", "UPLOAD_CLIENT"),
            ("CCD_TRANSFER_FORMAT", "FORMAT_FITS"),
            ("CCD_COMPRESSION", "INDI_DISABLED"),
            ("CCD_FRAME_TYPE", "FRAME_LIGHT"),
        ] {
            if client.property(device, property).is_some() {
                client.switch_on(device, property, item).await?;
            }
        }
        if client.property(device, "CCD_BINNING").is_some() {
            client
                .set_numbers(device, "CCD_BINNING", &[("HOR_BIN", 1.0), ("VER_BIN", 1.0)])
                .await?;
        }
        // The sensor as the connected device states it. Drivers define
        // CCD_INFO with defaults once connected, then set the sensor's
        // values: ask until two answers in a row agree.
        let mut info = client.fresh(device, "CCD_INFO").await?;
        for _ in 0..8 {
            let again = client.fresh(device, "CCD_INFO").await?;
            let settled = again.items == info.items;
            info = again;
            if settled {
                break;
            }
        }
        // By now the driver has defined what it defines on connecting.
        set_sensor(&client, device, sensor).await?;
        let missing = |what: &str| DeviceError::Camera(format!("INDI device {device:?}: CCD_INFO has no {what}"));
        let max_x = info.number("CCD_MAX_X").ok_or_else(|| missing("CCD_MAX_X"))? as u32;
        let max_y = info.number("CCD_MAX_Y").ok_or_else(|| missing("CCD_MAX_Y"))? as u32;
        let bits = info.number("CCD_BITSPERPIXEL").unwrap_or(16.0).clamp(8.0, 16.0) as u8;
        let (width, height) = resolution.unwrap_or((max_x, max_y));
        if width == 0 || height == 0 || width > max_x || height > max_y {
            return Err(DeviceError::Camera(format!(
                "INDI device {device:?}: the configured resolution {width}×{height} does not fit its {max_x}×{max_y} sensor"
            )));
        }
        if client.property(device, "CCD_FRAME").is_some() {
            let (x, y) = ((max_x - width) / 2, (max_y - height) / 2);
            client
                .set_numbers(
                    device,
                    "CCD_FRAME",
                    &[
                        ("X", f64::from(x)),
                        ("Y", f64::from(y)),
                        ("WIDTH", f64::from(width)),
                        ("HEIGHT", f64::from(height)),
                    ],
                )
                .await?;
            client
                .wait_for(
                    "the frame to take the configured size",
                    super::client::ANSWER_TIMEOUT,
                    |m| {
                        let f = m.property(device, "CCD_FRAME");
                        Ok(f.filter(|f| {
                            f.number("WIDTH") == Some(f64::from(width)) && f.number("HEIGHT") == Some(f64::from(height))
                        })
                        .map(|_| ()))
                    },
                )
                .await?;
        }
        let value = exposure.item("CCD_EXPOSURE_VALUE").ok_or_else(|| {
            DeviceError::Camera(format!(
                "INDI device {device:?}: CCD_EXPOSURE has no CCD_EXPOSURE_VALUE"
            ))
        })?;
        let seconds =
            |x: Option<f64>, default: f64| ExposureTime::from_seconds(x.filter(|v| *v > 0.0).unwrap_or(default));
        // INDI's `step` is a client's spinner increment (the CCD simulator
        // states 1 s), not the camera's resolution: exposures go over the
        // wire as decimal seconds, and the camera's FITS header says what it
        // applied. Asked times are kept to the microsecond.
        let range = ExposureRange {
            min: seconds(value.min, 1e-3).unwrap_or(ExposureTime::from_micros(1000).expect("1 ms")),
            max: seconds(value.max, 3600.0).unwrap_or(ExposureTime::from_micros(3_600_000_000).expect("1 h")),
            step: ExposureTime::from_micros(1).expect("1 µs"),
        };
        let driver = client
            .property(device, "DRIVER_INFO")
            .and_then(|p| p.item("DRIVER_EXEC").map(|i| i.value.clone()))
            .unwrap_or_default();
        Ok(IndiCamera {
            info: CameraInfo {
                model: format!("INDI {device} ({driver} on {server})"),
                width: width as usize,
                height: height as usize,
                bits,
                exposure: range,
                gain: GainRange {
                    min: Gain::UNITY,
                    max: Gain::UNITY,
                    step_db: 0.0,
                },
                exposure_table: None,
                linear: true,
            },
            client,
            server: server.to_owned(),
            device: device.to_owned(),
            resolution,
            sensor: sensor.clone(),
            sequence: 0,
        })
    }

    /// The INDI connection.
    pub fn client(&self) -> &IndiClient {
        &self.client
    }
}

/// Sets the gain and ISO of `sensor` on `device`, each checked against what
/// the device states (`CCD_GAIN`'s range, `CCD_ISO`'s switches).
async fn set_sensor(client: &IndiClient, device: &str, sensor: &CcdSettings) -> Result<(), DeviceError> {
    if let Some(gain) = sensor.gain {
        let offered = client
            .property(device, "CCD_GAIN")
            .and_then(|p| p.item("GAIN").cloned());
        let Some(item) = offered else {
            return Err(DeviceError::Camera(format!(
                "INDI device {device:?} has no CCD_GAIN: leave `gain` out for this camera"
            )));
        };
        let (lo, hi) = (item.min.unwrap_or(f64::NEG_INFINITY), item.max.unwrap_or(f64::INFINITY));
        if !(lo..=hi).contains(&gain) {
            return Err(DeviceError::OutOfRange {
                what: "INDI CCD_GAIN",
                requested: gain,
                min: lo,
                max: hi,
            });
        }
        client.set_numbers(device, "CCD_GAIN", &[("GAIN", gain)]).await?;
    }
    if let Some(iso) = &sensor.iso {
        let Some(property) = client.property(device, "CCD_ISO") else {
            return Err(DeviceError::Camera(format!(
                "INDI device {device:?} has no CCD_ISO: leave `iso` out for this camera"
            )));
        };
        let wanted = iso.trim();
        let item = property.items.iter().find(|i| {
            i.name.eq_ignore_ascii_case(wanted)
                || i.label.eq_ignore_ascii_case(wanted)
                || i.label.trim_start_matches("ISO").trim() == wanted.trim_start_matches("ISO").trim()
        });
        let Some(item) = item else {
            let offered: Vec<&str> = property.items.iter().map(|i| i.label.as_str()).collect();
            return Err(DeviceError::Camera(format!(
                "INDI device {device:?} offers no ISO {wanted:?}: it offers {}",
                offered.join(", ")
            )));
        };
        let name = item.name.clone();
        client.switch_on(device, "CCD_ISO", &name).await?;
    }
    Ok(())
}

/// A FITS `DATE-OBS` (UTC, `YYYY-MM-DDThh:mm:ss[.s…]`).
fn date_obs(text: &str) -> Option<DateTime<Utc>> {
    NaiveDateTime::parse_from_str(text.trim().trim_end_matches('Z'), "%Y-%m-%dT%H:%M:%S%.f")
        .ok()
        .map(|t| t.and_utc())
}

impl Camera for IndiCamera {
    fn info(&self) -> CameraInfo {
        self.info.clone()
    }

    async fn capture(&mut self, settings: CaptureSettings) -> Result<Frame, DeviceError> {
        let applied = self.info.exposure_applied(settings.exposure)?;
        let gain = self.info.gain.applied(settings.gain)?;
        self.sequence += 1;
        let device = self.device.clone();
        self.client.with(|m| m.blobs.retain(|b| b.device != device));
        let started = Utc::now();
        self.client
            .set_numbers(&device, "CCD_EXPOSURE", &[("CCD_EXPOSURE_VALUE", applied.seconds())])
            .await?;
        let wait = Duration::from_secs_f64(applied.seconds()) + READOUT_TIMEOUT;
        let blob = self
            .client
            .wait_for(&format!("a frame from {device:?}"), wait, |m| {
                if let Some(i) = m.blobs.iter().position(|b| b.device == device && b.property == "CCD1") {
                    return Ok(m.blobs.remove(i));
                }
                match m.property(&device, "CCD_EXPOSURE") {
                    Some(p) if p.state == PropertyState::Alert => Err(DeviceError::Camera(format!(
                        "INDI device {device:?} failed the exposure: {}",
                        m.last_message(&device).unwrap_or("no message")
                    ))),
                    _ => Ok(None),
                }
            })
            .await?;
        if !blob.format.eq_ignore_ascii_case(".fits") {
            return Err(DeviceError::Camera(format!(
                "INDI device {device:?} sent a {:?} image: expected \".fits\" (uncompressed FITS; turn off CCD_COMPRESSION)",
                blob.format
            )));
        }
        let label = format!("{device} frame {}", self.sequence);
        let fits = read_fits(&blob.bytes, &label).map_err(|e| DeviceError::Camera(e.to_string()))?;
        if (fits.image.width, fits.image.height) != (self.info.width, self.info.height) {
            return Err(DeviceError::Camera(format!(
                "{label} is {}×{}, the camera was set to {}×{}",
                fits.image.width, fits.image.height, self.info.width, self.info.height
            )));
        }
        let top = (1u32 << self.info.bits) - 1;
        if let Some(v) = fits.image.data.iter().find(|&&v| u32::from(v) > top) {
            return Err(DeviceError::Camera(format!(
                "{label} holds code {v}, more than its {} bits (CCD_BITSPERPIXEL) allow",
                self.info.bits
            )));
        }
        let exposure_actual = fits
            .number("EXPTIME")
            .or_else(|| fits.number("EXPOSURE"))
            .and_then(ExposureTime::from_seconds)
            .unwrap_or(applied);
        Ok(Frame {
            width: fits.image.width,
            height: fits.image.height,
            bits: self.info.bits,
            timestamp: fits.value("DATE-OBS").and_then(date_obs).unwrap_or(started),
            temperature_c: fits.number("CCD-TEMP"),
            data: fits.image.data,
            exposure_requested: settings.exposure,
            exposure_actual,
            gain,
            sequence: self.sequence,
            file: Some(FrameFile {
                format: FrameFormat::Fits,
                bytes: blob.bytes,
            }),
        })
    }

    /// Connects to the server anew and sets the device up as
    /// [`IndiCamera::open`] did; the frame counter goes on where it was.
    async fn reconnect(&mut self) -> Result<(), DeviceError> {
        let fresh = IndiCamera::open_with(&self.server, &self.device, self.resolution, &self.sensor).await?;
        if fresh.info != self.info {
            tracing::warn!(before = ?self.info, after = ?fresh.info, "the INDI camera came back different");
        }
        let sequence = self.sequence;
        *self = fresh;
        self.sequence = sequence;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn date_obs_reads_fits_times() {
        let t = date_obs("2026-11-26T23:10:00.500").unwrap();
        assert_eq!(t.to_rfc3339(), "2026-11-26T23:10:00.500+00:00");
        assert!(date_obs("2026-11-26").is_none());
    }
}
