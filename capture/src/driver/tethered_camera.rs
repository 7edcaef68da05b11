//! A tethered stills camera (a DSLR or mirrorless body on USB) as a
//! [`BlockingCamera`], over the few operations its library offers
//! ([`Tether`]: named settings with choices, toggles, capture, new-file
//! events, download). libgphoto2 is one such library (the `gphoto2`
//! driver); the camera logic here is built in every build and tested
//! against a scripted [`Tether`] that delivers real camera JPEGs.
//!
//! Opening reads the `shutterspeed` (Nikon's exact `shutterspeed2` when
//! present), `iso`, `aperture` (`f-number` on Nikon) and `imageformat`
//! (`imagequality`) choices, sets the image format the station's
//! `file_format` asks for (largest finest JPEG for `Jpeg`, plain RAW for
//! `Dng`, the camera's own for `Png`), and captures to the camera's RAM
//! when it offers that (`capturetarget`). The camera must be in manual (M)
//! exposure mode.
//!
//! Each capture snaps the exposure to the camera's table
//! ([`ShutterTable::plan`]): a timed speed is set and the camera takes the
//! frame; beyond the longest timed speed, bulb is set and the shutter held
//! open for the planned time, timed on the host clock from the command that
//! opens it to the one that closes it (`eosremoterelease` Immediate /
//! Release Full on Canon, the recipe libgphoto2's maintainer gives in
//! libgphoto2 issue 193; the `bulb` toggle elsewhere); then the new file is
//! awaited. A camera that takes a shutter setting only a notch at a time
//! (it reads back another speed than was set) is stepped there
//! ([`ShutterTable::notches`]). The gain sets the ISO ([`IsoTable`]). The
//! file is downloaded into [`Frame::file`] byte for byte, decoded to codes
//! for metering, and the frame's exposure time is the file's EXIF; a time
//! more than ⅙ stop from the speed set is logged as a warning (the journal
//! keeps both the requested and the actual time), and so is an f-number or
//! ISO in the file other than the camera was set to
//! ([`settings_mismatches`]).
//!
//! Not done: RAW+JPEG pairs, live view, the sensor's temperature, mirror
//! lock-up, choosing the aperture.

use super::camera_thread::BlockingCamera;
use super::gphoto_settings::{
    self, IsoTable, MISMATCH_STOPS, ShutterPlan, ShutterTable, WantedFile, decode_delivered, exposure_mismatch_stops,
    settings_mismatches,
};
use crate::device::{CameraInfo, CaptureSettings, DeviceError, ExposureTime, Frame, Gain, GainRange};
use campanile_config::camera::{Camera as CameraConfig, FrameFileFormat};
use std::time::{Duration, Instant};

/// How long after the exposure (timed or bulb) a new file may take to
/// arrive.
pub const FILE_TIMEOUT: Duration = Duration::from_secs(30);

/// A file on the camera.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CameraFile {
    /// Its folder, e.g. `/store_00020001/DCIM/100CANON`.
    pub folder: String,
    /// Its name, e.g. `IMG_0001.JPG`.
    pub name: String,
}

/// What a tethering library does with a camera (blocking calls).
pub trait Tether {
    /// The camera's model and port, for messages.
    fn name(&self) -> &str;

    /// The choices of the radio or menu setting `key`, in the camera's
    /// order; `None` if the camera has no such setting.
    fn choices(&mut self, key: &str) -> Option<Vec<String>>;

    /// The current choice of the setting `key`.
    fn current(&mut self, key: &str) -> Result<String, DeviceError>;

    /// Sets the setting `key` to `choice`.
    fn set(&mut self, key: &str, choice: &str) -> Result<(), DeviceError>;

    /// Whether the camera has the toggle `key`.
    fn has_toggle(&mut self, key: &str) -> bool;

    /// Sets the toggle `key`.
    fn set_toggle(&mut self, key: &str, on: bool) -> Result<(), DeviceError>;

    /// Takes a frame at the current settings and returns its file.
    fn capture(&mut self) -> Result<CameraFile, DeviceError>;

    /// Waits up to `timeout` for a new file (after a bulb exposure).
    fn await_new_file(&mut self, timeout: Duration) -> Result<CameraFile, DeviceError>;

    /// The file's bytes; the file is then deleted from the camera if it can
    /// be.
    fn download(&mut self, file: &CameraFile) -> Result<Vec<u8>, DeviceError>;
}

/// How the camera's bulb is worked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BulbControl {
    /// Canon EOS: `eosremoterelease` Immediate, then Release Full.
    EosRemoteRelease,
    /// Nikon, Olympus and others: the `bulb` toggle on, then off.
    Toggle,
}

/// An open tethered camera (see the module doc).
pub struct TetheredCamera<T: Tether> {
    tether: T,
    shutter_key: &'static str,
    shutter: ShutterTable,
    iso: Option<(&'static str, IsoTable)>,
    bulb: Option<BulbControl>,
    longest_s: f64,
    /// The f-number the camera stays at, when it states one.
    aperture: Option<f64>,
    info: CameraInfo,
    sequence: u64,
}

impl<T: Tether> std::fmt::Debug for TetheredCamera<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TetheredCamera")
            .field("camera", &self.tether.name())
            .field("shutter_key", &self.shutter_key)
            .field("bulb", &self.bulb)
            .finish_non_exhaustive()
    }
}

/// The first of `keys` the camera has as a setting with choices.
fn first_setting<T: Tether>(tether: &mut T, keys: &[&'static str]) -> Option<(&'static str, Vec<String>)> {
    keys.iter().find_map(|k| tether.choices(k).map(|c| (*k, c)))
}

impl<T: Tether> TetheredCamera<T> {
    /// Sets up the camera behind `tether` for the station's `config`.
    pub fn new(mut tether: T, config: &CameraConfig) -> Result<Self, DeviceError> {
        let name = tether.name().to_owned();
        let (shutter_key, shutter_choices) = first_setting(&mut tether, &["shutterspeed2", "shutterspeed"])
            .ok_or_else(|| {
                DeviceError::Camera(format!(
                    "{name}: has no shutterspeed setting, so manual exposure is impossible (put it in manual, M, mode)"
                ))
            })?;
        let shutter = ShutterTable::from_choices(&shutter_choices)?;
        for s in shutter.skipped() {
            tracing::info!(camera = %name, "shutterspeed choice skipped: {s}");
        }
        let iso = match first_setting(&mut tether, &["iso", "isospeed"]) {
            Some((key, c)) => Some((key, IsoTable::from_choices(&c)?)),
            None => None,
        };
        let aperture = match first_setting(&mut tether, &["aperture", "f-number"]) {
            Some((key, _)) => {
                let now = tether.current(key)?;
                tracing::info!(camera = %name, setting = key, aperture = %now, "aperture kept as the camera has it");
                gphoto_settings::parse_aperture(&now).ok().flatten()
            }
            None => None,
        };
        let want = match config.file_format {
            FrameFileFormat::Jpeg => Some(WantedFile::Jpeg),
            FrameFileFormat::Dng => Some(WantedFile::Raw),
            FrameFileFormat::Png => None,
            FrameFileFormat::Fits => {
                return Err(DeviceError::Camera(format!(
                    "{name}: a DSLR writes no FITS files; set the station camera's file_format to Jpeg or Dng"
                )));
            }
        };
        if let Some(want) = want {
            let (key, c) = first_setting(&mut tether, &["imageformat", "imagequality"]).ok_or_else(|| {
                DeviceError::Camera(format!(
                    "{name}: has no imageformat setting, so the station's file_format cannot be set; leave file_format out"
                ))
            })?;
            let choice = gphoto_settings::image_format_choice(&c, want)?;
            tether.set(key, &choice)?;
        }
        if let Some((key, c)) = first_setting(&mut tether, &["capturetarget"])
            && let Some(ram) = c.into_iter().find(|c| c.to_ascii_lowercase().contains("ram"))
            && let Err(e) = tether.set(key, &ram)
        {
            tracing::warn!(camera = %name, "cannot capture to the camera's RAM ({e}); frames go to its card and are deleted after download");
        }
        let bulb = if shutter.bulb().is_none() {
            None
        } else if tether.choices("eosremoterelease").is_some() {
            Some(BulbControl::EosRemoteRelease)
        } else if tether.has_toggle("bulb") {
            Some(BulbControl::Toggle)
        } else {
            tracing::warn!(camera = %name, "lists bulb but has neither eosremoterelease nor a bulb toggle: exposures end at its longest timed speed");
            None
        };
        // Without a way to work bulb, the table stops at the timed speeds.
        let longest_s = if bulb.is_some() { config.exposure.max_s } else { 0.0 };
        let table = shutter.exposure_table(longest_s);
        let gain = iso.as_ref().map_or(
            GainRange {
                min: Gain::UNITY,
                max: Gain::UNITY,
                step_db: 0.0,
            },
            |(_, t)| t.range(),
        );
        // A JPEG's codes are 8-bit, a RAW's 16-bit linear codes (metered as
        // a linear camera's); with the camera's own format, the first frame
        // tells.
        let bits = match want {
            Some(WantedFile::Raw) => 16,
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
            linear: matches!(want, Some(WantedFile::Raw)),
        };
        tracing::info!(camera = %name, shutter = shutter_key, speeds = shutter.timed().len(), bulb = ?bulb, "tethered camera open");
        Ok(Self {
            tether,
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

    /// The tether (for its owner's use between captures).
    pub fn tether(&self) -> &T {
        &self.tether
    }

    fn failed(&self, what: &str, e: impl std::fmt::Display) -> DeviceError {
        DeviceError::Camera(format!("{}: {what}: {e}", self.tether.name()))
    }

    /// Sets the shutter to `label`, stepping a notch at a time if the
    /// camera only moves that way.
    fn set_shutter(&mut self, label: &str) -> Result<(), DeviceError> {
        let key = self.shutter_key;
        self.tether.set(key, label)?;
        let mut now = self.tether.current(key)?;
        if now == label {
            return Ok(());
        }
        let target = self
            .shutter
            .choice(label)
            .and_then(|c| ExposureTime::from_seconds(c.seconds))
            .ok_or_else(|| self.failed("setting the shutter speed", format!("{label:?} is no timed speed")))?;
        let notches = self.shutter.notches(&now, target)?;
        tracing::info!(camera = %self.tether.name(), from = %now, to = label, notches, "the shutter steps a notch at a time");
        for _ in 0..notches.unsigned_abs() {
            let Some(i) = self.shutter.timed().iter().position(|c| c.label == now) else {
                break;
            };
            let next = if notches > 0 { i + 1 } else { i.wrapping_sub(1) };
            let Some(next) = self.shutter.timed().get(next).map(|c| c.label.clone()) else {
                break;
            };
            self.tether.set(key, &next)?;
            now = self.tether.current(key)?;
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
    /// for a camera without an ISO setting, which stays at unity gain).
    fn set_iso(&mut self, gain: Gain) -> Result<(Gain, Option<f64>), DeviceError> {
        let Some((key, table)) = &self.iso else {
            self.info.gain.applied(gain)?;
            return Ok((Gain::UNITY, None));
        };
        let (label, iso, applied) = table.choice_for(gain)?;
        let (key, label) = (*key, label.to_owned());
        self.tether.set(key, &label)?;
        Ok((applied, Some(iso)))
    }

    /// Holds the shutter open for `hold` in bulb; the new file.
    fn bulb_exposure(&mut self, choice: &str, hold: Duration) -> Result<CameraFile, DeviceError> {
        let control = self
            .bulb
            .ok_or_else(|| self.failed("bulb", "the camera offers no way to hold the shutter open"))?;
        self.tether.set(self.shutter_key, choice)?;
        let press = |tether: &mut T, on: bool| match control {
            BulbControl::EosRemoteRelease => {
                tether.set("eosremoterelease", if on { "Immediate" } else { "Release Full" })
            }
            BulbControl::Toggle => tether.set_toggle("bulb", on),
        };
        let opened = Instant::now();
        press(&mut self.tether, true)?;
        std::thread::sleep(hold.saturating_sub(opened.elapsed()));
        press(&mut self.tether, false)?;
        tracing::debug!(camera = %self.tether.name(), held_s = opened.elapsed().as_secs_f64(), "bulb closed");
        self.tether.await_new_file(FILE_TIMEOUT)
    }
}

impl<T: Tether> BlockingCamera for TetheredCamera<T> {
    fn info(&self) -> CameraInfo {
        self.info.clone()
    }

    fn capture(&mut self, settings: CaptureSettings) -> Result<Frame, DeviceError> {
        let plan = self.shutter.plan(settings.exposure, self.longest_s)?;
        let (gain, iso) = self.set_iso(settings.gain)?;
        let sequence = self.sequence;
        self.sequence += 1;
        let timestamp = chrono::Utc::now();
        let file = match &plan {
            ShutterPlan::Timed(choice) => {
                self.set_shutter(&choice.label)?;
                self.tether.capture()?
            }
            ShutterPlan::Bulb { choice, hold } => self.bulb_exposure(choice, hold.duration())?,
        };
        let bytes = self.tether.download(&file)?;
        let delivered = decode_delivered(&file.name, bytes)?;
        let off = exposure_mismatch_stops(&plan, delivered.exposure.time_s);
        if off > MISMATCH_STOPS {
            tracing::warn!(
                camera = %self.tether.name(),
                file = %file.name,
                set_s = plan.nominal().seconds(),
                exif_s = delivered.exposure.time_s,
                off_stops = off,
                "the file's exposure time is not the speed set; the frame keeps the file's"
            );
        }
        for m in settings_mismatches(self.aperture, iso, &delivered.exposure) {
            tracing::warn!(camera = %self.tether.name(), file = %file.name, "{m}");
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
    use std::collections::BTreeMap;
    use std::path::Path;

    /// The radiantlab EOS 5D Mark II bracket (640×640 crops, EXIF kept):
    /// file and EXIF exposure time (exposures.csv beside them). The
    /// scripted camera delivers the one nearest the exposure taken.
    const BRACKET: [(&str, f64); 18] = [
        ("IMG_6955.JPG", 13.0),
        ("IMG_6956.JPG", 6.0),
        ("IMG_6957.JPG", 3.2),
        ("IMG_6958.JPG", 1.6),
        ("IMG_6959.JPG", 0.8),
        ("IMG_6960.JPG", 0.4),
        ("IMG_6961.JPG", 0.2),
        ("IMG_6962.JPG", 0.1),
        ("IMG_6963.JPG", 0.05),
        ("IMG_6964.JPG", 0.025),
        ("IMG_6965.JPG", 1.0 / 80.0),
        ("IMG_6966.JPG", 1.0 / 160.0),
        ("IMG_6967.JPG", 1.0 / 320.0),
        ("IMG_6968.JPG", 1.0 / 640.0),
        ("IMG_6969.JPG", 1.0 / 1250.0),
        ("IMG_6970.JPG", 1.0 / 2500.0),
        ("IMG_6971.JPG", 1.0 / 5000.0),
        ("IMG_6972.JPG", 1.0 / 8000.0),
    ];

    fn jpeg(name: &str) -> Vec<u8> {
        std::fs::read(
            Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../validation/hdr/fixtures/radiantlab-eos")
                .join(name),
        )
        .unwrap()
    }

    /// A scripted camera: settings with choices, a bulb toggle, and the
    /// bracket's JPEG whose EXIF time is nearest the exposure taken.
    struct Scripted {
        settings: BTreeMap<String, (Vec<String>, String)>,
        toggles: BTreeMap<String, bool>,
        /// Moves one notch per set, towards the choice asked for.
        stepped: bool,
        /// Every set, as `key=choice`.
        log: Vec<String>,
        /// When the bulb opened, and how long it was held.
        opened: Option<Instant>,
        held: Option<Duration>,
        pending: Option<CameraFile>,
    }

    fn strings(s: &[&str]) -> Vec<String> {
        s.iter().map(|c| (*c).to_owned()).collect()
    }

    impl Scripted {
        /// A 5D Mark II in ⅓ stops up to `longest` (a label of the list),
        /// then bulb; Auto and ISO 100–6400; f/5.6.
        fn canon(longest: &str) -> Self {
            let speeds = [
                "1/8000", "1/6400", "1/5000", "1/4000", "1/3200", "1/2500", "1/2000", "1/1600", "1/1250", "1/1000",
                "1/800", "1/640", "1/500", "1/400", "1/320", "1/250", "1/200", "1/160", "1/125", "1/100", "1/80",
                "1/60", "1/50", "1/40", "1/30", "1/25", "1/20", "1/15", "1/13", "1/10", "1/8", "1/6", "1/5", "1/4",
                "0.3", "0.4", "0.5", "0.6", "0.8", "1", "1.3", "1.6", "2", "2.5", "3.2", "4", "5", "6", "8", "10",
                "13", "15", "20", "25", "30",
            ];
            let upto = speeds.iter().position(|s| *s == longest).unwrap();
            let mut shutter: Vec<String> = vec!["bulb".into()];
            shutter.extend(speeds[..=upto].iter().rev().map(|s| (*s).to_owned()));
            let mut settings = BTreeMap::new();
            settings.insert("shutterspeed".into(), (shutter, "1/5".into()));
            let iso = ["Auto", "100", "200", "400", "800", "1600", "3200", "6400"];
            settings.insert("iso".into(), (strings(&iso), "100".into()));
            settings.insert("aperture".into(), (strings(&["4", "5.6", "8"]), "5.6".into()));
            let formats = ["Large Fine JPEG", "Large Normal JPEG", "RAW + Large Fine JPEG", "RAW"];
            settings.insert("imageformat".into(), (strings(&formats), "RAW".into()));
            settings.insert(
                "capturetarget".into(),
                (strings(&["Internal RAM", "Memory card"]), "Memory card".into()),
            );
            Self {
                settings,
                toggles: BTreeMap::from([("bulb".to_owned(), false)]),
                stepped: false,
                log: Vec::new(),
                opened: None,
                held: None,
                pending: None,
            }
        }

        /// A camera whose speeds are exactly the bracket's 18, so every
        /// frame's file states the speed set.
        fn bracket_speeds() -> Self {
            let mut s = Self::canon("30");
            let labels = [
                "13", "6", "3.2", "1.6", "0.8", "0.4", "1/5", "1/10", "1/20", "1/40", "1/80", "1/160", "1/320",
                "1/640", "1/1250", "1/2500", "1/5000", "1/8000",
            ];
            s.settings
                .insert("shutterspeed".into(), (strings(&labels), "1/5".into()));
            s
        }

        fn exposure_s(&self) -> f64 {
            match gphoto_settings::parse_shutter_speed(&self.settings["shutterspeed"].1).unwrap() {
                gphoto_settings::ShutterValue::Timed { seconds, .. } => seconds,
                _ => self.held.unwrap().as_secs_f64(),
            }
        }

        /// The bracket's file nearest in stops to the exposure taken.
        fn file_for(&self, t: f64) -> CameraFile {
            let (name, _) = BRACKET
                .iter()
                .min_by(|a, b| (a.1 / t).log2().abs().total_cmp(&(b.1 / t).log2().abs()))
                .unwrap();
            CameraFile {
                folder: "/store_00020001/DCIM/100CANON".into(),
                name: (*name).into(),
            }
        }
    }

    impl Tether for Scripted {
        fn name(&self) -> &str {
            "Canon EOS 5D Mark II at usb:001,004"
        }
        fn choices(&mut self, key: &str) -> Option<Vec<String>> {
            self.settings.get(key).map(|(c, _)| c.clone())
        }
        fn current(&mut self, key: &str) -> Result<String, DeviceError> {
            Ok(self.settings[key].1.clone())
        }
        fn set(&mut self, key: &str, choice: &str) -> Result<(), DeviceError> {
            if key == "eosremoterelease" {
                // Canon's release button: Immediate opens, Release Full closes.
                self.set_toggle("bulb", choice == "Immediate")?;
                self.log.pop();
            }
            self.log.push(format!("{key}={choice}"));
            let stepped = self.stepped;
            let (choices, now) = self
                .settings
                .get_mut(key)
                .ok_or_else(|| DeviceError::Camera(format!("no setting {key}")))?;
            let to = choices
                .iter()
                .position(|c| c == choice)
                .ok_or_else(|| DeviceError::Camera(format!("{key}: no choice {choice:?}")))?;
            let from = choices.iter().position(|c| c == now).unwrap();
            let at = if stepped && key == "shutterspeed" && to.abs_diff(from) > 1 {
                if to > from { from + 1 } else { from - 1 }
            } else {
                to
            };
            *now = choices[at].clone();
            Ok(())
        }
        fn has_toggle(&mut self, key: &str) -> bool {
            self.toggles.contains_key(key)
        }
        fn set_toggle(&mut self, key: &str, on: bool) -> Result<(), DeviceError> {
            self.log.push(format!("{key}={on}"));
            self.toggles.insert(key.into(), on);
            if on {
                self.opened = Some(Instant::now());
            } else if let Some(t) = self.opened.take() {
                self.held = Some(t.elapsed());
                self.pending = Some(self.file_for(self.exposure_s()));
            }
            Ok(())
        }
        fn capture(&mut self) -> Result<CameraFile, DeviceError> {
            Ok(self.file_for(self.exposure_s()))
        }
        fn await_new_file(&mut self, _: Duration) -> Result<CameraFile, DeviceError> {
            self.pending
                .take()
                .ok_or_else(|| DeviceError::Timeout("no new file".into()))
        }
        fn download(&mut self, file: &CameraFile) -> Result<Vec<u8>, DeviceError> {
            Ok(jpeg(&file.name))
        }
    }

    fn config() -> CameraConfig {
        let station = campanile_config::load_station(
            &Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/gphoto2/station.ron"),
        )
        .unwrap()
        .value;
        let mut c = station.camera;
        c.resolution.width = 640;
        c.resolution.height = 640;
        c
    }

    fn shot(exposure_s: f64, gain_db: f64) -> CaptureSettings {
        CaptureSettings {
            exposure: ExposureTime::from_seconds(exposure_s).unwrap(),
            gain: Gain::from_db(gain_db).unwrap(),
        }
    }

    #[test]
    fn opening_sets_the_jpeg_format_and_ram_and_states_the_table() {
        let cam = TetheredCamera::new(Scripted::canon("30"), &config()).unwrap();
        assert_eq!(
            cam.tether().log,
            ["imageformat=Large Fine JPEG", "capturetarget=Internal RAM"]
        );
        let info = BlockingCamera::info(&cam);
        assert_eq!((info.width, info.height, info.bits), (640, 640, 8));
        // 55 timed speeds, then bulb up to the station's 120 s: 30·2^(k/3),
        // k = 1..6.
        let table = info.exposure_table.as_ref().unwrap();
        assert_eq!(table.times().len(), 61);
        assert_eq!(table.times()[54].seconds(), 30.0);
        assert_eq!(table.times()[60].seconds(), 120.0);
        assert_eq!(
            (info.exposure.min.seconds(), info.exposure.max.seconds()),
            (1.0 / 8000.0, 120.0)
        );
        // ISO 6400 over base 100: 20·log10(64) dB.
        assert!((info.gain.max.db() - 36.123_599_9).abs() < 1e-6);
        assert_eq!(cam.bulb, Some(BulbControl::Toggle));
        // No shutterspeed setting: a clear error.
        let mut none = Scripted::canon("30");
        none.settings.remove("shutterspeed");
        let err = TetheredCamera::new(none, &config()).unwrap_err().to_string();
        assert!(
            err.contains("has no shutterspeed setting") && err.contains("manual, M"),
            "{err}"
        );
    }

    #[test]
    fn a_frame_is_the_cameras_file_with_the_exif_exposure_and_the_iso_gain() {
        let mut cam = TetheredCamera::new(Scripted::canon("30"), &config()).unwrap();
        // 1/5 s at 12 dB: ISO 400 (12.04 dB), the 1/5 s notch.
        let f = cam.capture(shot(0.2, 12.0)).unwrap();
        assert_eq!(&cam.tether().log[2..], ["iso=400", "shutterspeed=1/5"]);
        assert_eq!(f.exposure_actual.seconds(), 0.2);
        assert_eq!(f.exposure_requested.seconds(), 0.2);
        assert!((f.gain.db() - 12.041_199_8).abs() < 1e-6, "{}", f.gain.db());
        let file = f.file.as_ref().unwrap();
        assert_eq!(file.format, crate::device::FrameFormat::Jpeg);
        assert_eq!(file.bytes, jpeg("IMG_6961.JPG"));
        assert_eq!((f.width, f.height, f.bits, f.data.len()), (640, 640, 8, 640 * 640 * 3));
        assert_eq!(f.sequence, 0);
        // 1/3 s snaps to the 0.3 notch; this camera then delivers the
        // bracket's 0.4 s frame: the frame keeps the file's 0.4 s.
        let f = cam.capture(shot(1.0 / 3.0, 0.0)).unwrap();
        assert_eq!(cam.tether().log.last().unwrap(), "shutterspeed=0.3");
        assert_eq!(f.exposure_actual.seconds(), 0.4);
        assert_eq!(f.sequence, 1);
        // Outside the table, or an ISO not offered: nothing is set.
        let before = cam.tether().log.len();
        assert!(matches!(
            cam.capture(shot(200.0, 0.0)),
            Err(DeviceError::OutOfRange { .. })
        ));
        let err = cam.capture(shot(0.2, 9.0)).unwrap_err().to_string();
        assert!(err.contains("does not offer"), "{err}");
        assert_eq!(cam.tether().log.len(), before);
        // A frame of another size than the station's: an error naming both.
        let mut small = config();
        small.resolution.width = 1920;
        let mut cam = TetheredCamera::new(Scripted::canon("30"), &small).unwrap();
        let err = cam.capture(shot(0.2, 0.0)).unwrap_err().to_string();
        assert!(err.contains("delivered 640×640") && err.contains("1920×640"), "{err}");
    }

    #[test]
    fn a_shutter_that_moves_a_notch_at_a_time_is_stepped_there() {
        let mut scripted = Scripted::canon("30");
        scripted.stepped = true;
        let mut cam = TetheredCamera::new(scripted, &config()).unwrap();
        // From 1/5 s to 1/20 s: the first set moves one notch (to 1/6),
        // then five more notches, one set each.
        let f = cam.capture(shot(0.05, 0.0)).unwrap();
        let sets: Vec<&str> = cam.tether().log[3..].iter().map(String::as_str).collect();
        assert_eq!(
            sets,
            [
                "shutterspeed=1/20",
                "shutterspeed=1/8",
                "shutterspeed=1/10",
                "shutterspeed=1/13",
                "shutterspeed=1/15",
                "shutterspeed=1/20"
            ]
        );
        assert_eq!(f.exposure_actual.seconds(), 0.05);
    }

    #[test]
    fn beyond_the_longest_timed_speed_the_bulb_is_held_for_the_planned_time() {
        // Timed speeds up to 1/5 s: 0.4 s is bulb, 1/5 s · 2 exactly.
        let mut cam = TetheredCamera::new(Scripted::canon("1/5"), &config()).unwrap();
        let f = cam.capture(shot(0.4, 0.0)).unwrap();
        assert_eq!(
            &cam.tether().log[2..],
            ["iso=100", "shutterspeed=bulb", "bulb=true", "bulb=false"]
        );
        let held = cam.tether().held.unwrap().as_secs_f64();
        // Held from the opening command to the closing one: at least the
        // planned 0.4 s, and not a scheduling slice more.
        assert!((0.4..0.5).contains(&held), "held {held} s");
        assert_eq!(f.exposure_actual.seconds(), 0.4);
        assert_eq!(f.file.as_ref().unwrap().bytes, jpeg("IMG_6960.JPG"));
        // Without a bulb toggle or eosremoterelease, the table ends at the
        // longest timed speed.
        let mut no_bulb = Scripted::canon("1/5");
        no_bulb.toggles.clear();
        let mut cam = TetheredCamera::new(no_bulb, &config()).unwrap();
        assert!(matches!(cam.capture(shot(0.4, 0.0)), Err(DeviceError::OutOfRange { max, .. }) if max == 0.2));
        // Canon's eosremoterelease is preferred when it exists.
        let mut canon = Scripted::canon("1/5");
        canon.settings.insert(
            "eosremoterelease".into(),
            (strings(&["None", "Immediate", "Release Full"]), "None".into()),
        );
        let mut cam = TetheredCamera::new(canon, &config()).unwrap();
        assert_eq!(cam.bulb, Some(BulbControl::EosRemoteRelease));
        let f = cam.capture(shot(0.4, 0.0)).unwrap();
        assert_eq!(
            &cam.tether().log[2..],
            [
                "iso=100",
                "shutterspeed=bulb",
                "eosremoterelease=Immediate",
                "eosremoterelease=Release Full"
            ]
        );
        assert!(cam.tether().held.unwrap().as_secs_f64() >= 0.4);
        assert_eq!(f.exposure_actual.seconds(), 0.4);
    }

    /// The camera conformance suite (`campanile devices test`) on the
    /// scripted camera through its thread. With the bracket's 18 speeds
    /// (no bulb toggle) every file states the speed set, and the suite
    /// passes: 1/800 s asked is the 1/640 s entry, 0.0375 s the 1/20 s one,
    /// twice the longest (26 s) is refused. With the 5D Mark II's ⅓-stop
    /// list the scripted camera delivers only the bracket's files, a third
    /// of a stop off at 1/800 s, and the suite says so.
    #[tokio::test]
    async fn the_camera_conformance_suite_checks_the_table() {
        let mut cam = crate::driver::camera_thread::ThreadedCamera::spawn("scripted EOS", || {
            let mut s = Scripted::bracket_speeds();
            s.toggles.clear();
            TetheredCamera::new(s, &config())
        })
        .unwrap();
        let report = crate::conformance::camera::run(&mut cam).await;
        assert!(report.passed(), "{:?}", report.failures());
        assert_eq!(report.checks.len(), 3);
        let mut cam = crate::driver::camera_thread::ThreadedCamera::spawn("scripted EOS", || {
            TetheredCamera::new(Scripted::canon("30"), &config())
        })
        .unwrap();
        let report = crate::conformance::camera::run(&mut cam).await;
        let failures = report.failures();
        assert_eq!(failures.len(), 2, "{failures:?}");
        let why = failures[0].failure.as_deref().unwrap_or_default();
        assert!(
            why.contains("the camera's table gives 0.00125 s, the camera reports 0.0015625 s applied (+0.32 stops)"),
            "{why}"
        );
    }
}
