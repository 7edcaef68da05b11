//! A tethered DSLR or mirrorless body through libgphoto2 (cargo feature
//! `gphoto2`, crate `gphoto2`, Debian `libgphoto2-dev`).
//!
//! **This backend has never met a camera.** Debian's libgphoto2 has no
//! virtual camera (`vusb`), so what is tested is the settings mapping
//! ([`gphoto_settings`], every build: real choice lists, real EXIF files)
//! and that opening with no camera attached is a clear
//! [`DeviceError`]; the capture path below follows libgphoto2's documented
//! use (`gphoto2 --capture-image-and-download`, the bulb recipes of
//! gphoto.org/doc/remote) and is untried.
//!
//! Opening finds the camera (the first one libgphoto2 detects, or the one
//! the station's `device` names by port, model or index), reads its
//! `shutterspeed` (Nikon's exact `shutterspeed2` when present), `iso`,
//! `aperture` (`f-number` on Nikon) and `imageformat` (`imagequality`)
//! choices, sets the image format the station's `file_format` asks for
//! (largest finest JPEG for `Jpeg`, plain RAW for `Dng`, the camera's own
//! for `Png`), and captures to the camera's RAM when it offers that
//! (`capturetarget`). The camera must be in manual (M) exposure mode.
//!
//! Each capture snaps the exposure to the camera's table
//! ([`ShutterTable::plan`]): a timed speed is set and `gp_camera_capture`
//! takes the frame; beyond the longest timed speed, bulb is set and the
//! shutter held open for the planned time (`eosremoterelease` Press Full /
//! Release Full on Canon, the `bulb` toggle elsewhere), after which the new
//! file is awaited. A camera that takes a shutter setting only a notch at a
//! time (it reads back another speed than was set) is stepped there
//! ([`ShutterTable::notches`]). The gain sets the ISO ([`IsoTable`]). The
//! file is downloaded into [`Frame::file`] byte for byte, decoded to codes
//! for metering, and the frame's exposure time is the file's EXIF; a time
//! more than ⅙ stop from the speed set is logged as a warning (the journal
//! keeps both the requested and the actual time), and so is an f-number or
//! ISO in the file other than the camera was set to
//! ([`settings_mismatches`]). The file is then deleted from the camera.
//!
//! The RAW file (DNG, CR2, CR3, NEF, ARW, RAF, RW2, ORF, PEF, SRW) is kept
//! under its own format and read through `rawler`, as `campanile hdr`
//! reads it; only DNG has been read here from a file (the repository holds
//! no maker's RAW).
//!
//! Not done: RAW+JPEG pairs, live view, the sensor's temperature, mirror
//! lock-up, choosing the aperture.

use super::camera_thread::{BlockingCamera, ThreadedCamera};
use super::gphoto_settings::{
    self, IsoTable, MISMATCH_STOPS, ShutterPlan, ShutterTable, WantedFile, decode_delivered, exposure_mismatch_stops,
    settings_mismatches,
};
use crate::device::{CameraInfo, CaptureSettings, DeviceError, ExposureTime, Frame, Gain, GainRange};
use campanile_config::camera::{Camera as CameraConfig, DeviceRef, FrameFileFormat};
use gphoto2::camera::CameraEvent;
use gphoto2::list::CameraDescriptor;
use gphoto2::widget::{RadioWidget, ToggleWidget};
use gphoto2::{Camera, Context};
use std::time::{Duration, Instant};

/// gphoto2 port prefixes (`gphoto2 --list-ports`): a device string that
/// starts with one names a port, anything else a model.
const PORT_PREFIXES: [&str; 7] = [
    "usb:",
    "ptpip:",
    "ip:",
    "serial:",
    "disk:",
    "usbdiskdirect:",
    "usbscsi:",
];

/// How long after the exposure (timed or bulb) a new file may take to
/// arrive.
const FILE_TIMEOUT: Duration = Duration::from_secs(30);

/// Open the station's gphoto2 camera on its own thread, as a
/// [`Camera`](crate::device::Camera).
pub fn open(config: &CameraConfig) -> Result<ThreadedCamera, DeviceError> {
    let config = config.clone();
    let name = format!("gphoto2 {}", device_label(config.device.as_ref()));
    ThreadedCamera::spawn(&name, move || Gphoto2Camera::open(&config))
}

fn device_label(device: Option<&DeviceRef>) -> String {
    match device {
        None => "(first camera found)".into(),
        Some(DeviceRef::Path(p)) => p.clone(),
        Some(DeviceRef::Index(i)) => format!("camera number {i}"),
        Some(DeviceRef::Indi { device, .. }) => device.clone(),
    }
}

/// The camera `device` names among those detected.
fn pick<'a>(found: &'a [CameraDescriptor], device: Option<&DeviceRef>) -> Result<&'a CameraDescriptor, DeviceError> {
    let listed = || {
        let l: Vec<String> = found.iter().map(|d| format!("{} at {}", d.model, d.port)).collect();
        if l.is_empty() { "none".to_owned() } else { l.join(", ") }
    };
    let chosen = match device {
        None => found.first(),
        Some(DeviceRef::Index(i)) => found.get(*i as usize),
        Some(DeviceRef::Path(p)) if PORT_PREFIXES.iter().any(|pre| p.starts_with(pre)) => {
            found.iter().find(|d| d.port == *p)
        }
        Some(DeviceRef::Path(model)) => found.iter().find(|d| d.model == *model),
        Some(DeviceRef::Indi { .. }) => {
            return Err(DeviceError::Camera(
                "an INDI device names no gphoto2 camera: use driver Indi, or a port or model".into(),
            ));
        }
    };
    chosen.ok_or_else(|| {
        let what = match device {
            None => String::new(),
            Some(_) => format!(" matching {}", device_label(device)),
        };
        DeviceError::Camera(format!(
            "gphoto2 finds no camera{what} (cameras found: {}); check that it is connected, switched on, \
             in PTP/PC mode, and not held by another program (a desktop's gvfs mounts cameras: `gio mount -s gphoto2`)",
            listed()
        ))
    })
}

fn gp_error(what: &str) -> impl Fn(gphoto2::Error) -> DeviceError + '_ {
    move |e| DeviceError::Camera(format!("gphoto2: {what}: {e}"))
}

/// The first of `keys` the camera has as a radio (or menu) widget.
fn radio(camera: &Camera, keys: &[&'static str]) -> Option<(&'static str, RadioWidget)> {
    keys.iter()
        .find_map(|k| camera.config_key::<RadioWidget>(k).wait().ok().map(|w| (*k, w)))
}

fn choices(w: &RadioWidget) -> Vec<String> {
    w.choices_iter().collect()
}

/// How the camera's bulb is worked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum BulbControl {
    /// Canon EOS: `eosremoterelease` Press Full, then Release Full.
    EosRemoteRelease,
    /// Nikon, Olympus and others: the `bulb` toggle on, then off.
    Toggle,
}

/// An open gphoto2 camera (blocking; see [`open`]).
pub struct Gphoto2Camera {
    camera: Camera,
    name: String,
    shutter_key: &'static str,
    shutter: ShutterTable,
    iso: Option<IsoTable>,
    bulb: Option<BulbControl>,
    longest_s: f64,
    /// The f-number the camera stayed at, when it states one.
    aperture: Option<f64>,
    info: CameraInfo,
    sequence: u64,
}

impl std::fmt::Debug for Gphoto2Camera {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Gphoto2Camera")
            .field("name", &self.name)
            .field("shutter_key", &self.shutter_key)
            .finish_non_exhaustive()
    }
}

impl Gphoto2Camera {
    /// Find, open and set up the camera `config` names (on the calling
    /// thread). With no camera attached this is a [`DeviceError::Camera`]
    /// saying what to check.
    pub fn open(config: &CameraConfig) -> Result<Self, DeviceError> {
        let context = Context::new().map_err(gp_error("cannot start libgphoto2"))?;
        let found: Vec<CameraDescriptor> = context
            .list_cameras()
            .wait()
            .map_err(gp_error("cannot list cameras"))?
            .collect();
        let desc = pick(&found, config.device.as_ref())?.clone();
        let name = format!("{} at {}", desc.model, desc.port);
        let camera = context
            .get_camera(&desc)
            .wait()
            .map_err(|e| DeviceError::Camera(format!("gphoto2: cannot open {name}: {e}")))?;

        let (shutter_key, shutter_widget) = radio(&camera, &["shutterspeed2", "shutterspeed"]).ok_or_else(|| {
            DeviceError::Camera(format!(
                "{name}: has no shutterspeed setting, so manual exposure is impossible (put it in manual, M, mode)"
            ))
        })?;
        let shutter = ShutterTable::from_choices(&choices(&shutter_widget))?;
        for s in shutter.skipped() {
            tracing::info!(camera = %name, "shutterspeed choice skipped: {s}");
        }
        let iso = match radio(&camera, &["iso", "isospeed"]) {
            Some((_, w)) => Some(IsoTable::from_choices(&choices(&w))?),
            None => None,
        };
        let aperture = radio(&camera, &["aperture", "f-number"]).and_then(|(key, w)| {
            tracing::info!(camera = %name, setting = key, aperture = %w.choice(), "aperture kept as the camera has it");
            gphoto_settings::parse_aperture(&w.choice()).ok().flatten()
        });
        let want = match config.file_format {
            FrameFileFormat::Jpeg => Some(WantedFile::Jpeg),
            FrameFileFormat::Dng => Some(WantedFile::Raw),
            FrameFileFormat::Png => None,
        };
        if let Some(want) = want {
            let (key, w) = radio(&camera, &["imageformat", "imagequality"]).ok_or_else(|| {
                DeviceError::Camera(format!(
                    "{name}: has no imageformat setting, so the station's file_format cannot be set; leave file_format out"
                ))
            })?;
            let choice = gphoto_settings::image_format_choice(&choices(&w), want)?;
            set_choice(&camera, &w, &choice).map_err(|e| DeviceError::Camera(format!("{name}: {key}: {e}")))?;
        }
        if let Some((_, w)) = radio(&camera, &["capturetarget"])
            && let Some(ram) = choices(&w).into_iter().find(|c| c.to_ascii_lowercase().contains("ram"))
            && let Err(e) = set_choice(&camera, &w, &ram)
        {
            tracing::warn!(camera = %name, "cannot capture to the camera's RAM ({e}); frames go to its card and are deleted after download");
        }
        let bulb = shutter.bulb().and_then(|_| {
            if camera.config_key::<RadioWidget>("eosremoterelease").wait().is_ok() {
                Some(BulbControl::EosRemoteRelease)
            } else if camera.config_key::<ToggleWidget>("bulb").wait().is_ok() {
                Some(BulbControl::Toggle)
            } else {
                tracing::warn!(camera = %name, "lists bulb but has neither eosremoterelease nor a bulb toggle: exposures end at its longest timed speed");
                None
            }
        });
        // Without a way to work bulb, the table stops at the timed speeds.
        let longest_s = if bulb.is_some() { config.exposure.max_s } else { 0.0 };
        let table = shutter.exposure_table(longest_s);
        let gain = iso.as_ref().map_or(
            GainRange {
                min: Gain::UNITY,
                max: Gain::UNITY,
                step_db: 0.0,
            },
            IsoTable::range,
        );
        // A JPEG's codes are 8-bit, a RAW's the 16-bit logarithmic codes of
        // linear_codes; with the camera's own format, the first frame tells.
        let bits = match want {
            Some(WantedFile::Raw) => campanile_process::hdr::linear_codes::LOG_CODE_BITS,
            _ => 8,
        };
        if want.is_some() && bits != config.bit_depth {
            tracing::warn!(camera = %name, configured = config.bit_depth, delivered = bits, "the camera's frames have another bit depth than the station config says");
        }
        let info = CameraInfo {
            model: name.clone(),
            width: config.resolution.width as usize,
            height: config.resolution.height as usize,
            bits,
            exposure: table.range(),
            gain,
            exposure_table: Some(table),
        };
        tracing::info!(camera = %name, shutter = shutter_key, speeds = shutter.timed().len(), bulb = ?bulb, "gphoto2 camera open");
        Ok(Self {
            camera,
            name,
            shutter_key,
            shutter,
            iso,
            bulb,
            longest_s,
            aperture,
            info,
            sequence: 0,
        })
    }

    fn failed(&self, what: &str, e: impl std::fmt::Display) -> DeviceError {
        DeviceError::Camera(format!("{}: {what}: {e}", self.name))
    }

    fn shutter_widget(&self) -> Result<RadioWidget, DeviceError> {
        self.camera
            .config_key::<RadioWidget>(self.shutter_key)
            .wait()
            .map_err(|e| self.failed("reading the shutter speed", e))
    }

    /// Sets the shutter to `label`, stepping a notch at a time if the
    /// camera only moves that way.
    fn set_shutter(&self, label: &str) -> Result<(), DeviceError> {
        let w = self.shutter_widget()?;
        set_choice(&self.camera, &w, label).map_err(|e| self.failed("setting the shutter speed", e))?;
        let mut now = self.shutter_widget()?.choice();
        if now == label {
            return Ok(());
        }
        let target = self
            .shutter
            .choice(label)
            .and_then(|c| ExposureTime::from_seconds(c.seconds))
            .ok_or_else(|| self.failed("setting the shutter speed", format!("{label:?} is no timed speed")))?;
        let notches = self.shutter.notches(&now, target)?;
        tracing::info!(camera = %self.name, from = %now, to = label, notches, "the shutter steps a notch at a time");
        for _ in 0..notches.unsigned_abs() {
            let i = self.shutter.timed().iter().position(|c| c.label == now).unwrap_or(0);
            let next = if notches > 0 { i + 1 } else { i.saturating_sub(1) };
            let Some(next) = self.shutter.timed().get(next) else {
                break;
            };
            let w = self.shutter_widget()?;
            set_choice(&self.camera, &w, &next.label).map_err(|e| self.failed("stepping the shutter speed", e))?;
            now = self.shutter_widget()?.choice();
        }
        if now == label {
            Ok(())
        } else {
            Err(self.failed(
                "setting the shutter speed",
                format!(
                    "asked for {label:?}, the camera reads {now:?} after {} notches",
                    notches.unsigned_abs()
                ),
            ))
        }
    }

    /// Sets the ISO for `gain`; the gain applied and the ISO set (`None`
    /// for a camera without an ISO setting).
    fn set_iso(&self, gain: Gain) -> Result<(Gain, Option<f64>), DeviceError> {
        let Some(table) = &self.iso else {
            self.info.gain.applied(gain)?;
            return Ok((Gain::UNITY, None));
        };
        let (label, iso, applied) = table.choice_for(gain)?;
        let (_, w) = radio(&self.camera, &["iso", "isospeed"])
            .ok_or_else(|| self.failed("setting the ISO", "the iso setting has gone"))?;
        set_choice(&self.camera, &w, label).map_err(|e| self.failed("setting the ISO", e))?;
        Ok((applied, Some(iso)))
    }

    /// Holds the shutter open for `hold` in bulb and returns the new
    /// file's folder and name.
    fn bulb_exposure(&self, choice: &str, hold: Duration) -> Result<(String, String), DeviceError> {
        let control = self
            .bulb
            .ok_or_else(|| self.failed("bulb", "the camera offers no way to hold the shutter open"))?;
        let w = self.shutter_widget()?;
        set_choice(&self.camera, &w, choice).map_err(|e| self.failed("setting bulb", e))?;
        let press = |on: bool| -> Result<(), DeviceError> {
            match control {
                BulbControl::EosRemoteRelease => {
                    let w = self
                        .camera
                        .config_key::<RadioWidget>("eosremoterelease")
                        .wait()
                        .map_err(|e| self.failed("eosremoterelease", e))?;
                    let v = if on { "Press Full" } else { "Release Full" };
                    set_choice(&self.camera, &w, v).map_err(|e| self.failed("eosremoterelease", e))
                }
                BulbControl::Toggle => {
                    let w = self
                        .camera
                        .config_key::<ToggleWidget>("bulb")
                        .wait()
                        .map_err(|e| self.failed("bulb", e))?;
                    w.set_toggled(on);
                    self.camera.set_config(&w).wait().map_err(|e| self.failed("bulb", e))
                }
            }
        };
        let opened = Instant::now();
        press(true)?;
        std::thread::sleep(hold.saturating_sub(opened.elapsed()));
        press(false)?;
        tracing::debug!(camera = %self.name, held_s = opened.elapsed().as_secs_f64(), "bulb closed");
        self.await_new_file()
    }

    fn await_new_file(&self) -> Result<(String, String), DeviceError> {
        let deadline = Instant::now() + FILE_TIMEOUT;
        while Instant::now() < deadline {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.camera.wait_event(left).wait() {
                Ok(CameraEvent::NewFile(path)) => return Ok((path.folder().into_owned(), path.name().into_owned())),
                Ok(CameraEvent::Timeout) => break,
                Ok(_) => {}
                Err(e) => return Err(self.failed("waiting for the file", e)),
            }
        }
        Err(DeviceError::Timeout(format!(
            "{}: no new file within {:?} of the exposure's end",
            self.name, FILE_TIMEOUT
        )))
    }

    fn download(&self, folder: &str, file: &str) -> Result<Vec<u8>, DeviceError> {
        let fs = self.camera.fs();
        let f = fs
            .download(folder, file)
            .wait()
            .map_err(|e| self.failed(&format!("downloading {folder}/{file}"), e))?;
        let data = f
            .get_data(&self.camera)
            .wait()
            .map_err(|e| self.failed(&format!("reading {folder}/{file}"), e))?;
        if let Err(e) = fs.delete_file(folder, file).wait() {
            tracing::info!(camera = %self.name, file = %format!("{folder}/{file}"), "left on the camera: {e}");
        }
        Ok(data.into_vec())
    }
}

fn set_choice(camera: &Camera, w: &RadioWidget, choice: &str) -> Result<(), gphoto2::Error> {
    w.set_choice(choice)?;
    camera.set_config(w).wait()
}

impl BlockingCamera for Gphoto2Camera {
    fn info(&self) -> CameraInfo {
        self.info.clone()
    }

    fn capture(&mut self, settings: CaptureSettings) -> Result<Frame, DeviceError> {
        let plan = self.shutter.plan(settings.exposure, self.longest_s)?;
        let (gain, iso) = self.set_iso(settings.gain)?;
        let sequence = self.sequence;
        self.sequence += 1;
        let timestamp = chrono::Utc::now();
        let (folder, file) = match &plan {
            ShutterPlan::Timed(choice) => {
                self.set_shutter(&choice.label)?;
                let path = self
                    .camera
                    .capture_image()
                    .wait()
                    .map_err(|e| self.failed("capturing", e))?;
                (path.folder().into_owned(), path.name().into_owned())
            }
            ShutterPlan::Bulb { choice, hold } => self.bulb_exposure(choice, hold.duration())?,
        };
        let bytes = self.download(&folder, &file)?;
        let delivered = decode_delivered(&file, bytes)?;
        let off = exposure_mismatch_stops(&plan, delivered.exposure.time_s);
        if off > MISMATCH_STOPS {
            tracing::warn!(
                camera = %self.name,
                file = %file,
                set_s = plan.nominal().seconds(),
                exif_s = delivered.exposure.time_s,
                off_stops = off,
                "the file's exposure time is not the speed set; the frame keeps the file's"
            );
        }
        for m in settings_mismatches(self.aperture, iso, &delivered.exposure) {
            tracing::warn!(camera = %self.name, file = %file, "{m}");
        }
        let (w, h) = (delivered.codes.width, delivered.codes.height);
        if (w, h) != (self.info.width, self.info.height) {
            return Err(self.failed(
                "frame size",
                format!(
                    "the camera delivered {w}×{h}, the station's camera resolution is {}×{}; set it to what the camera gives",
                    self.info.width, self.info.height
                ),
            ));
        }
        let actual = ExposureTime::from_seconds(delivered.exposure.time_s).unwrap_or_else(|| plan.nominal());
        Ok(Frame {
            width: w,
            height: h,
            bits: delivered.codes.bits,
            data: delivered.codes.data,
            exposure_requested: settings.exposure,
            exposure_actual: actual,
            gain,
            sequence,
            timestamp,
            temperature_c: None,
            file: Some(delivered.file),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn descriptors() -> Vec<CameraDescriptor> {
        vec![
            CameraDescriptor {
                model: "Canon EOS 5D Mark II".into(),
                port: "usb:001,004".into(),
            },
            CameraDescriptor {
                model: "Nikon DSC D7000".into(),
                port: "usb:001,007".into(),
            },
        ]
    }

    #[test]
    fn the_device_picks_by_port_model_or_index() {
        let found = descriptors();
        assert_eq!(pick(&found, None).unwrap().model, "Canon EOS 5D Mark II");
        let by_port = pick(&found, Some(&DeviceRef::Path("usb:001,007".into()))).unwrap();
        assert_eq!(by_port.model, "Nikon DSC D7000");
        let by_model = pick(&found, Some(&DeviceRef::Path("Nikon DSC D7000".into()))).unwrap();
        assert_eq!(by_model.port, "usb:001,007");
        assert_eq!(pick(&found, Some(&DeviceRef::Index(1))).unwrap().port, "usb:001,007");
        let err = pick(&found, Some(&DeviceRef::Index(2))).unwrap_err().to_string();
        assert!(
            err.contains("camera number 2") && err.contains("Nikon DSC D7000 at usb:001,007"),
            "{err}"
        );
        let err = pick(&[], None).unwrap_err().to_string();
        assert!(
            err.starts_with("camera failure: gphoto2 finds no camera (cameras found: none); check")
                && err.contains("PTP"),
            "{err}"
        );
    }

    /// No camera is attached where the tests run: opening is a clear error,
    /// not a panic, whether the camera is asked for by default, port or
    /// model.
    #[test]
    fn opening_with_no_camera_attached_is_a_clear_error() {
        let station = campanile_config::load_station(
            &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/real-station.ron"),
        )
        .unwrap()
        .value;
        let mut cfg = station.camera.clone();
        cfg.driver = campanile_config::camera::CameraDriver::Gphoto2;
        for device in [
            None,
            Some(DeviceRef::Path("usb:999,999".into())),
            Some(DeviceRef::Path("Canon EOS 5D Mark II".into())),
        ] {
            cfg.device = device.clone();
            let err = Gphoto2Camera::open(&cfg).unwrap_err();
            assert!(matches!(err, DeviceError::Camera(_)), "{device:?}: {err:?}");
            let msg = err.to_string();
            assert!(
                msg.starts_with("camera failure: gphoto2 finds no camera"),
                "{device:?}: {msg}"
            );
            assert!(msg.contains("(cameras found: none)"), "{device:?}: {msg}");
            if let Some(DeviceRef::Path(p)) = &device {
                assert!(msg.contains(&format!("matching {p} ")), "{device:?}: {msg}");
            }
            // Through the camera thread too.
            let err = open(&cfg).unwrap_err().to_string();
            assert_eq!(err, msg, "{device:?}");
        }
    }
}
