//! gphoto2 camera settings in campanile's units: shutter-speed, aperture,
//! ISO and image-format choice strings as libgphoto2 lists them, the plan
//! for one exposure (a timed speed, or bulb held for a time), ISO as gain,
//! and the exposure a delivered JPEG or RAW file says was used.
//!
//! Pure: no libgphoto2 is needed, so this is built and tested in every
//! build; the `gphoto2` driver (cargo feature `gphoto2`) calls it.
//!
//! **Shutter speeds.** libgphoto2 shows each camera's speeds in that
//! vendor's notation (`camlibs/ptp2/config.c`), and [`parse_shutter_speed`]
//! reads them all:
//! - Canon EOS: `"30"`, `"3.2"`, `"0.3"`, `"1/4000"`, `"bulb"`
//!   (`canon_shutterspeed`); older PowerShots `"15\""`, `"1\"3"` (1.3 s);
//! - Nikon through the vendor property: `"1/4000"`, `"10/13"` (1/1.3 s),
//!   `"13/10"`, `"30"` (`_get_Nikon_ShutterSpeed`); through the PTP
//!   standard one, four decimals and a unit, `"0.0001s"` … `"30.0000s"`,
//!   `"Bulb"` (a D7000, libgphoto2 issue 518), with the locale's comma,
//!   `"0,0002s"` (a D3100, issue 564);
//! - Fuji: `"1/32000"`, `"0.4s"`, `"2.5s"`, `"30s"`, `"2m"`, `"15m"` (an
//!   X-T2, issue 506); Sony `"30\""`, `"0.3\""`.
//!
//! A decimal string is as precise as its last digit: `"0.0001s"` is any
//! time in 0.00005–0.00015 s, which holds the nominal 1/8000 s that the
//! file's EXIF then states. [`ShutterValue::Timed`] keeps that interval,
//! and the EXIF check ([`exposure_mismatch_stops`]) measures from it.
//!
//! **Bulb.** A request longer than the longest timed speed uses bulb if the
//! camera lists it: the table goes on above the longest timed speed `t₀` in
//! exact third stops, `t₀ · 2^(k/3)` (30 s → 37.8, 47.6, 60, 75.6 … s) up to
//! the station's longest exposure, and the shutter is held open for the
//! chosen entry, timed on the host clock from the command that opens it to
//! the one that closes it (USB latency adds tens of milliseconds).
//!
//! **Stepped shutters.** A camera that only steps its setting a notch at a
//! time is turned by [`ShutterTable::notches`] notches from where it is.
//!
//! **ISO as gain.** ISO `S` is the gain `20·log₁₀(S / S₀)` dB over the base
//! ISO `S₀`, the lowest numeric speed the camera lists (turn ISO expansion
//! off so that it is the sensor's base). A gain is met by the ISO nearest
//! in stops if one lies within ⅙ stop (half a ⅓-stop notch); otherwise the
//! ISO is not offered and the request is an error.
//!
//! **Exposure used.** The exposure time, f-number and ISO of a frame come
//! from its file (JPEG EXIF through
//! [`exposure_metadata`](campanile_process::hdr::exposure_metadata), RAW
//! through [`raw_file`]), not from what
//! was asked. A time more than [`MISMATCH_STOPS`] from the chosen speed is a
//! warning, not an error: the frame is good data with a known exposure,
//! and the journal records both the requested and the actual time.

use crate::device::{DeviceError, ExposureTable, ExposureTime, FrameFile, FrameFormat, Gain, GainRange};
use campanile_process::camera::image::CodeImage;
use campanile_process::hdr::{image_file, linear_codes, raw_file, tiff_structure};
use std::path::Path;

/// How far (in stops) the file's exposure time may lie from the chosen
/// speed before it is reported: ⅙ stop, half a ⅓-stop notch.
pub const MISMATCH_STOPS: f64 = 1.0 / 6.0;

/// One shutter-speed choice, read.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ShutterValue {
    /// A speed the camera times: `seconds` as written, and the interval
    /// `lo..=hi` the string stands for (to its last printed digit).
    Timed {
        /// The time as written.
        seconds: f64,
        /// Shortest time the string stands for.
        lo: f64,
        /// Longest time the string stands for.
        hi: f64,
    },
    /// Bulb: open until told to close.
    Bulb,
    /// A choice that is no fixed time (`auto`, Nikon's `Time`, a flash
    /// sync setting `x 200`).
    NotATime,
}

fn bad_choice(setting: &str, s: &str, expected: &str) -> DeviceError {
    DeviceError::Camera(format!(
        "gphoto2 {setting} choice {s:?} is not understood (expected {expected})"
    ))
}

const SHUTTER_FORMS: &str = "a speed such as 1/250, 10/13, 0.3, 2.5s, 0,0002s, 1\"3, 30\", 2m, or bulb";

/// A decimal number (`.` or `,` as separator) with the half-width of its
/// last printed digit.
fn decimal(s: &str) -> Option<(f64, f64)> {
    let s = s.replace(',', ".");
    if s.is_empty() || !s.chars().all(|c| c.is_ascii_digit() || c == '.') || s.matches('.').count() > 1 {
        return None;
    }
    let v: f64 = s.parse().ok()?;
    let digits = s.split_once('.').map_or(0, |(_, f)| f.len());
    Some((v, 0.5 * 10f64.powi(-(digits as i32))))
}

/// Reads one shutter-speed choice string (module doc lists the forms).
pub fn parse_shutter_speed(choice: &str) -> Result<ShutterValue, DeviceError> {
    let s = choice.trim();
    let lower = s.to_ascii_lowercase();
    if lower == "bulb" || lower == "b" {
        return Ok(ShutterValue::Bulb);
    }
    if lower == "auto" || lower == "time" || lower == "t" || lower.starts_with("x ") {
        return Ok(ShutterValue::NotATime);
    }
    let bad = || bad_choice("shutterspeed", choice, SHUTTER_FORMS);
    let timed = |seconds: f64, half: f64| {
        if seconds.is_finite() && seconds > 0.0 {
            Ok(ShutterValue::Timed {
                seconds,
                lo: (seconds - half).max(seconds * 0.5),
                hi: seconds + half,
            })
        } else {
            Err(bad())
        }
    };
    // A fraction: 1/4000, 1/4000s, 10/13 (Nikon's rational).
    let body = lower
        .strip_suffix(" s")
        .or_else(|| lower.strip_suffix('s'))
        .unwrap_or(&lower);
    if let Some((n, d)) = body.split_once('/') {
        let (n, d) = (
            decimal(n.trim()).ok_or_else(bad)?.0,
            decimal(d.trim()).ok_or_else(bad)?.0,
        );
        if d == 0.0 {
            return Err(bad());
        }
        return timed(n / d, 0.0);
    }
    // Canon PowerShot and Sony: 1"3 (1.3 s), 15" (15 s), 0.3".
    if let Some((whole, tenths)) = s.split_once('"') {
        let text = if tenths.is_empty() {
            whole.to_owned()
        } else {
            format!("{whole}.{tenths}")
        };
        let (v, half) = decimal(&text).ok_or_else(bad)?;
        return timed(v, half);
    }
    // Minutes: 2m (Fuji).
    if let Some(m) = lower.strip_suffix('m') {
        let (v, half) = decimal(m.trim()).ok_or_else(bad)?;
        return timed(60.0 * v, 60.0 * half);
    }
    // Seconds: 30, 0.3, 2.5s, 0.0001s, 0,0002s.
    let (v, half) = decimal(body.trim()).ok_or_else(bad)?;
    timed(v, half)
}

/// A timed shutter-speed choice.
#[derive(Debug, Clone, PartialEq)]
pub struct TimedChoice {
    /// The choice string, as the camera lists it (what is set).
    pub label: String,
    /// The time as written, seconds.
    pub seconds: f64,
    /// The interval the string stands for, seconds.
    pub lo: f64,
    /// The interval the string stands for, seconds.
    pub hi: f64,
}

/// How to take one exposure.
#[derive(Debug, Clone, PartialEq)]
pub enum ShutterPlan {
    /// Set `shutterspeed` to this choice; the camera times the exposure.
    Timed(TimedChoice),
    /// Set `shutterspeed` to the bulb choice `choice` and hold the shutter
    /// open for `hold` on the host clock.
    Bulb {
        /// The bulb choice string.
        choice: String,
        /// How long the shutter is held open.
        hold: ExposureTime,
    },
}

impl ShutterPlan {
    /// The time this plan exposes for, as far as the host knows it.
    pub fn nominal(&self) -> ExposureTime {
        match self {
            ShutterPlan::Timed(c) => ExposureTime::from_seconds(c.seconds).unwrap_or_default(),
            ShutterPlan::Bulb { hold, .. } => *hold,
        }
    }

    /// The interval of times this plan stands for, seconds.
    fn interval(&self) -> (f64, f64) {
        match self {
            ShutterPlan::Timed(c) => (c.lo, c.hi),
            ShutterPlan::Bulb { hold, .. } => (hold.seconds(), hold.seconds()),
        }
    }
}

/// A camera's shutter speeds, from its `shutterspeed` choices.
#[derive(Debug, Clone, PartialEq)]
pub struct ShutterTable {
    /// Timed speeds, shortest first, one per distinct time.
    timed: Vec<TimedChoice>,
    /// The bulb choice, if listed.
    bulb: Option<String>,
    /// Choices that are no fixed time or were not understood, with why.
    skipped: Vec<String>,
    /// The timed speeds as a table.
    timed_table: ExposureTable,
}

impl ShutterTable {
    /// The table of `choices` (in the camera's order). Choices that are no
    /// time (`auto`) or not understood are skipped and listed in
    /// [`ShutterTable::skipped`]; a list with no timed speed is an error.
    pub fn from_choices<S: AsRef<str>>(choices: &[S]) -> Result<Self, DeviceError> {
        let mut timed: Vec<TimedChoice> = Vec::new();
        let mut bulb = None;
        let mut skipped = Vec::new();
        for c in choices {
            let label = c.as_ref();
            match parse_shutter_speed(label) {
                Ok(ShutterValue::Timed { seconds, lo, hi }) => timed.push(TimedChoice {
                    label: label.to_owned(),
                    seconds,
                    lo,
                    hi,
                }),
                Ok(ShutterValue::Bulb) => {
                    bulb.get_or_insert_with(|| label.to_owned());
                }
                Ok(ShutterValue::NotATime) => skipped.push(format!("{label:?}: not a fixed time")),
                Err(e) => skipped.push(e.to_string()),
            }
        }
        timed.sort_by(|a, b| a.seconds.total_cmp(&b.seconds));
        timed.dedup_by(|b, a| a.seconds == b.seconds);
        let seconds: Vec<f64> = timed.iter().map(|c| c.seconds).collect();
        let Some(timed_table) = ExposureTable::new(&seconds) else {
            let listed: Vec<&str> = choices.iter().map(AsRef::as_ref).collect();
            return Err(DeviceError::Camera(format!(
                "the camera's shutterspeed lists no timed speed ({listed:?}); put it in manual (M) exposure mode"
            )));
        };
        Ok(Self {
            timed,
            bulb,
            skipped,
            timed_table,
        })
    }

    /// The timed speeds, shortest first.
    pub fn timed(&self) -> &[TimedChoice] {
        &self.timed
    }

    /// The bulb choice, if the camera lists one.
    pub fn bulb(&self) -> Option<&str> {
        self.bulb.as_deref()
    }

    /// Choices skipped, with why.
    pub fn skipped(&self) -> &[String] {
        &self.skipped
    }

    /// The timed choice labelled `label`.
    pub fn choice(&self, label: &str) -> Option<&TimedChoice> {
        self.timed.iter().find(|c| c.label == label)
    }

    fn longest_timed(&self) -> f64 {
        self.timed[self.timed.len() - 1].seconds
    }

    /// The bulb times above the longest timed speed, in exact third stops
    /// up to `longest_s` (none without bulb).
    fn bulb_times(&self, longest_s: f64) -> Vec<f64> {
        let t0 = self.longest_timed();
        if self.bulb.is_none() {
            return Vec::new();
        }
        (1..)
            .map(|k| t0 * 2f64.powf(f64::from(k) / 3.0))
            .take_while(|t| *t <= longest_s * (1.0 + 1e-9))
            .take(64)
            .collect()
    }

    /// Every exposure the camera can take, shortest first: the timed speeds,
    /// then (with bulb) the bulb times up to `longest_s`.
    pub fn exposure_table(&self, longest_s: f64) -> ExposureTable {
        let mut all: Vec<f64> = self.timed.iter().map(|c| c.seconds).collect();
        all.extend(self.bulb_times(longest_s));
        ExposureTable::new(&all).unwrap_or_else(|| self.timed_table.clone())
    }

    /// The plan for `requested`: the entry of [`exposure_table`] nearest in
    /// stops, a timed speed or bulb held for its time. A request outside
    /// the table (shorter than the shortest speed, longer than the longest
    /// timed speed without bulb or than `longest_s` with it) is
    /// [`DeviceError::OutOfRange`].
    ///
    /// [`exposure_table`]: ShutterTable::exposure_table
    pub fn plan(&self, requested: ExposureTime, longest_s: f64) -> Result<ShutterPlan, DeviceError> {
        let table = self.exposure_table(longest_s);
        table.range().applied(requested)?;
        let i = table.nearest_index(requested);
        if i < self.timed.len() {
            Ok(ShutterPlan::Timed(self.timed[i].clone()))
        } else {
            Ok(ShutterPlan::Bulb {
                choice: self.bulb.clone().unwrap_or_default(),
                hold: table.times()[i],
            })
        }
    }

    /// The notches (positive: longer) a camera that steps its shutter a
    /// notch at a time turns from its current choice `current` to the
    /// timed speed nearest `target`; an error if `current` is no timed
    /// choice of the table.
    pub fn notches(&self, current: &str, target: ExposureTime) -> Result<isize, DeviceError> {
        let from = self.choice(current).ok_or_else(|| {
            DeviceError::Camera(format!(
                "the camera's shutter is at {current:?}, which is no timed speed it lists: cannot count notches from it"
            ))
        })?;
        let from = ExposureTime::from_seconds(from.seconds).unwrap_or_default();
        Ok(self.timed_table.notches(from, target))
    }
}

/// How many stops the file's exposure time `exif_s` lies outside what
/// `plan` stands for (0 inside it). Over [`MISMATCH_STOPS`], the camera did
/// not take what was set.
pub fn exposure_mismatch_stops(plan: &ShutterPlan, exif_s: f64) -> f64 {
    let (lo, hi) = plan.interval();
    if exif_s < lo {
        (lo / exif_s).log2()
    } else if exif_s > hi {
        (exif_s / hi).log2()
    } else {
        0.0
    }
}

/// Reads an aperture choice: `"f/8"`, `"f8"`, `"F5.6"`, `"8"`, `"5.6"`;
/// `None` for a choice that sets no f-number (`"auto"`, `"implicit
/// auto"`: a lens without electronic aperture).
pub fn parse_aperture(choice: &str) -> Result<Option<f64>, DeviceError> {
    let s = choice.trim().to_ascii_lowercase();
    if s.contains("auto") {
        return Ok(None);
    }
    let n = s
        .strip_prefix("f/")
        .or_else(|| s.strip_prefix('f'))
        .unwrap_or(&s)
        .trim();
    match decimal(n) {
        Some((v, _)) if v > 0.0 => Ok(Some(v)),
        _ => Err(bad_choice("aperture", choice, "an f-number such as f/8, f8 or 5.6")),
    }
}

/// The aperture choice nearest f-number `n` in stops (`2·log₂` of the
/// f-number ratio), if one lies within [`MISMATCH_STOPS`]; else an error
/// naming the nearest offered.
pub fn aperture_choice<S: AsRef<str>>(choices: &[S], n: f64) -> Result<(String, f64), DeviceError> {
    let mut best: Option<(String, f64)> = None;
    for c in choices {
        if let Ok(Some(f)) = parse_aperture(c.as_ref()) {
            let d = (2.0 * (f / n).log2()).abs();
            if best.as_ref().is_none_or(|(_, b)| d < (2.0 * (b / n).log2()).abs()) {
                best = Some((c.as_ref().to_owned(), f));
            }
        }
    }
    match best {
        Some((label, f)) if (2.0 * (f / n).log2()).abs() <= MISMATCH_STOPS + 1e-9 => Ok((label, f)),
        Some((label, _)) => Err(DeviceError::Camera(format!(
            "aperture f/{n} is not offered: the nearest the lens lists is {label:?}"
        ))),
        None => Err(DeviceError::Camera(format!(
            "aperture f/{n} cannot be set: the camera lists no f-number (a manual lens?)"
        ))),
    }
}

/// One ISO choice, read.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum IsoValue {
    /// A speed: `"100"`, `"ISO 100"`.
    Speed(f64),
    /// Automatic ISO.
    Auto,
    /// An extended-high setting `stops` above the highest standard speed
    /// (`"H"`, `"H1"`, `"Hi 0.3"`, `"Hi 2"`).
    High(f64),
    /// An extended-low setting `stops` below the base speed (`"L"`,
    /// `"Lo 1"`): over-exposed and pulled in processing, so no gain.
    Low(f64),
}

/// Reads one ISO choice string.
pub fn parse_iso(choice: &str) -> Result<IsoValue, DeviceError> {
    let s = choice.trim().to_ascii_lowercase();
    let bad = || bad_choice("iso", choice, "a speed such as 100 or ISO 100, Auto, Hi 1 or Lo 1");
    if s.starts_with("auto") || s.ends_with("auto") || s == "auto iso" {
        return Ok(IsoValue::Auto);
    }
    let s = s.strip_prefix("iso").unwrap_or(&s).trim();
    let extended = |rest: &str| -> Result<f64, DeviceError> {
        let rest = rest.trim().trim_start_matches('-').trim();
        if rest.is_empty() {
            return Ok(1.0);
        }
        match decimal(rest) {
            Some((v, _)) if v > 0.0 => Ok(v),
            _ => Err(bad()),
        }
    };
    if let Some(rest) = s.strip_prefix("hi").or_else(|| s.strip_prefix('h')) {
        return extended(rest).map(IsoValue::High);
    }
    if let Some(rest) = s.strip_prefix("lo").or_else(|| s.strip_prefix('l')) {
        return extended(rest).map(IsoValue::Low);
    }
    match decimal(s) {
        Some((v, _)) if v > 0.0 => Ok(IsoValue::Speed(v)),
        _ => Err(bad()),
    }
}

/// A camera's ISO speeds as gains over its base ISO.
#[derive(Debug, Clone, PartialEq)]
pub struct IsoTable {
    /// `(label, ISO)`, lowest first.
    speeds: Vec<(String, f64)>,
    /// Choices skipped, with why.
    skipped: Vec<String>,
}

impl IsoTable {
    /// The table of `choices`: numeric speeds, and extended-high settings
    /// at the highest numeric speed times `2^stops`. `Auto`, extended-low
    /// and unknown choices are skipped (listed in [`IsoTable::skipped`]); a
    /// list with no numeric speed is an error.
    pub fn from_choices<S: AsRef<str>>(choices: &[S]) -> Result<Self, DeviceError> {
        let mut speeds = Vec::new();
        let mut high = Vec::new();
        let mut skipped = Vec::new();
        for c in choices {
            let label = c.as_ref();
            match parse_iso(label) {
                Ok(IsoValue::Speed(v)) => speeds.push((label.to_owned(), v)),
                Ok(IsoValue::High(stops)) => high.push((label.to_owned(), stops)),
                Ok(IsoValue::Auto) => skipped.push(format!("{label:?}: automatic ISO")),
                Ok(IsoValue::Low(_)) => skipped.push(format!("{label:?}: below the base ISO (pulled, no gain)")),
                Err(e) => skipped.push(e.to_string()),
            }
        }
        speeds.sort_by(|a, b| a.1.total_cmp(&b.1));
        speeds.dedup_by(|b, a| a.1 == b.1);
        let Some(top) = speeds.last().map(|s| s.1) else {
            let listed: Vec<&str> = choices.iter().map(AsRef::as_ref).collect();
            return Err(DeviceError::Camera(format!(
                "the camera's iso lists no numeric speed ({listed:?})"
            )));
        };
        for (label, stops) in high {
            speeds.push((label, top * 2f64.powf(stops)));
        }
        speeds.sort_by(|a, b| a.1.total_cmp(&b.1));
        speeds.dedup_by(|b, a| a.1 == b.1);
        Ok(Self { speeds, skipped })
    }

    /// The base ISO `S₀` (the lowest numeric speed listed).
    pub fn base(&self) -> f64 {
        self.speeds[0].1
    }

    /// `(label, ISO)`, lowest first.
    pub fn speeds(&self) -> &[(String, f64)] {
        &self.speeds
    }

    /// Choices skipped, with why.
    pub fn skipped(&self) -> &[String] {
        &self.skipped
    }

    /// The gain of ISO `iso`: `20·log₁₀(iso / S₀)` dB.
    pub fn gain(&self, iso: f64) -> Gain {
        Gain::from_db(20.0 * (iso / self.base()).log10()).unwrap_or(Gain::UNITY)
    }

    /// The gains the camera offers, from the base (0 dB) to its highest ISO.
    pub fn range(&self) -> GainRange {
        GainRange {
            min: Gain::UNITY,
            max: self.gain(self.speeds[self.speeds.len() - 1].1),
            step_db: 0.0,
        }
    }

    /// The ISO choice for `gain`: the speed nearest in stops, if within
    /// [`MISMATCH_STOPS`]. Outside the range: [`DeviceError::OutOfRange`];
    /// between two speeds further apart: an error naming them.
    pub fn choice_for(&self, gain: Gain) -> Result<(&str, f64, Gain), DeviceError> {
        self.range().applied(gain)?;
        let wanted = self.base() * gain.linear();
        let stops = |iso: f64| (iso / wanted).log2().abs();
        let (label, iso) = self
            .speeds
            .iter()
            .min_by(|a, b| stops(a.1).total_cmp(&stops(b.1)))
            .map(|(l, i)| (l.as_str(), *i))
            .unwrap_or((self.speeds[0].0.as_str(), self.speeds[0].1));
        if stops(iso) > MISMATCH_STOPS + 1e-9 {
            return Err(DeviceError::Camera(format!(
                "gain {:.2} dB is ISO {:.0} (base ISO {:.0}), which the camera does not offer: the nearest is {label:?} ({:.2} dB)",
                gain.db(),
                wanted,
                self.base(),
                self.gain(iso).db()
            )));
        }
        Ok((label, iso, self.gain(iso)))
    }
}

/// Which file to ask the camera for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum WantedFile {
    /// The largest, finest JPEG (8-bit codes through the camera's curve).
    #[default]
    Jpeg,
    /// The camera's RAW alone (no JPEG beside it).
    Raw,
}

/// How well an `imageformat` choice fits `want` (higher is better; `None`:
/// not at all). RAW+JPEG choices fit neither: a capture would deliver two
/// files.
fn image_format_score(label: &str, want: WantedFile) -> Option<u32> {
    let l = label.to_ascii_lowercase();
    let raw = ["raw", "nef", "cr2", "cr3", "dng", "arw", "raf", "orf", "pef", "rw2"]
        .iter()
        .any(|r| l.contains(r));
    let jpeg = ["jpeg", "jpg", "fine", "normal", "basic", "large", "medium", "small"]
        .iter()
        .any(|j| l.contains(j));
    if l.contains('+') || (raw && jpeg) {
        return None;
    }
    match want {
        WantedFile::Raw if raw => {
            // Full-size RAW first: mRAW, sRAW and compressed cRAW after.
            let reduced = l.starts_with('m') || l.starts_with('s') || l.starts_with('c');
            Some(if reduced { 1 } else { 2 })
        }
        WantedFile::Jpeg if jpeg => {
            let size = if l.contains("large") || !(l.contains("medium") || l.contains("small") || l.contains("tiny")) {
                30
            } else if l.contains("medium") {
                20
            } else {
                10
            };
            let quality = if l.contains("extra fine") || l.contains("superfine") {
                4
            } else if l.contains("fine") {
                3
            } else if l.contains("normal") {
                2
            } else {
                1
            };
            Some(size + quality)
        }
        _ => None,
    }
}

/// The `imageformat` choice that best gives `want`, or an error listing
/// what the camera offers.
pub fn image_format_choice<S: AsRef<str>>(choices: &[S], want: WantedFile) -> Result<String, DeviceError> {
    choices
        .iter()
        .filter_map(|c| image_format_score(c.as_ref(), want).map(|s| (s, c.as_ref())))
        .max_by_key(|(s, _)| *s)
        .map(|(_, c)| c.to_owned())
        .ok_or_else(|| {
            let listed: Vec<&str> = choices.iter().map(AsRef::as_ref).collect();
            DeviceError::Camera(format!(
                "the camera offers no single-file {} image format among {listed:?}",
                match want {
                    WantedFile::Jpeg => "JPEG",
                    WantedFile::Raw => "RAW",
                }
            ))
        })
}

/// What a delivered file says about its exposure.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FileExposure {
    /// Exposure time, seconds (EXIF ExposureTime).
    pub time_s: f64,
    /// F-number (EXIF FNumber), if stated.
    pub f_number: Option<f64>,
    /// ISO speed, if stated.
    pub iso: Option<f64>,
}

/// What a delivered file says that differs from the aperture `f_number`
/// and ISO `iso` the camera was set to, by more than [`MISMATCH_STOPS`]
/// (aperture stops: `2·log₂` of the f-number ratio; ISO stops: `log₂` of
/// the ratio), one message each. A bracket merged as varying time alone
/// needs both fixed. Fields the file or the setting leaves unknown are not
/// compared.
pub fn settings_mismatches(f_number: Option<f64>, iso: Option<f64>, file: &FileExposure) -> Vec<String> {
    let mut out = Vec::new();
    if let (Some(set), Some(got)) = (f_number, file.f_number) {
        let stops = 2.0 * (got / set).log2();
        if stops.abs() > MISMATCH_STOPS {
            out.push(format!(
                "the file says f/{got}, the aperture was f/{set} ({stops:+.2} stops)"
            ));
        }
    }
    if let (Some(set), Some(got)) = (iso, file.iso) {
        let stops = (got / set).log2();
        if stops.abs() > MISMATCH_STOPS {
            out.push(format!(
                "the file says ISO {got}, the camera was set to ISO {set} ({stops:+.2} stops)"
            ));
        }
    }
    out
}

/// A file a camera delivered, decoded.
#[derive(Debug, Clone, PartialEq)]
pub struct DeliveredFrame {
    /// The file, byte for byte, for the session store.
    pub file: FrameFile,
    /// Its codes for metering (a JPEG's 8-bit codes turned upright; a
    /// RAW's logarithmic codes of
    /// [`linear_codes`]), as the
    /// store decodes them.
    pub codes: CodeImage,
    /// Its exposure.
    pub exposure: FileExposure,
}

/// Decodes a file the camera delivered as `name`: a JPEG by its EXIF, a
/// RAW file (DNG by its content, a maker's RAW, CR2, NEF, ARW …, by its
/// name and first bytes) through the RAW reader. Anything else is refused,
/// and so is a file whose exposure time is not stated.
pub fn decode_delivered(name: &str, bytes: Vec<u8>) -> Result<DeliveredFrame, DeviceError> {
    let path = Path::new(name);
    let failed = |e: campanile_process::hdr::HdrError| DeviceError::Camera(format!("{name}: {e}"));
    let raw = if tiff_structure::parse(&bytes).is_some_and(|s| s.is_dng()) {
        Some(FrameFormat::Dng)
    } else {
        FrameFormat::from_file_name(name).filter(|f| f.is_raw() && *f != FrameFormat::Dng)
    };
    let (format, codes, time_s, f_number, iso) = if bytes.starts_with(&[0xFF, 0xD8, 0xFF]) {
        if let Some(problem) = FrameFormat::Jpeg.end_problem(&bytes) {
            return Err(DeviceError::Camera(format!("{name}: {problem}")));
        }
        let (codes, meta) = image_file::read_frame_bytes(path, &bytes).map_err(failed)?;
        (FrameFormat::Jpeg, codes, meta.exposure_time_s, meta.f_number, meta.iso)
    } else if let Some(format) = raw {
        if let Some(problem) = format.signature_problem(&bytes) {
            return Err(DeviceError::Camera(format!("{name}: {problem}")));
        }
        let frame = raw_file::read_raw_bytes(path, bytes.clone()).map_err(failed)?;
        let meta = frame.meta.clone();
        (
            format,
            linear_codes::linear_codes16(&frame),
            meta.exposure_time_s,
            meta.f_number,
            meta.iso,
        )
    } else {
        return Err(DeviceError::Camera(format!(
            "{name}: the camera delivered neither a JPEG nor a RAW file campanile reads ({}); set the station \
             camera's file_format to Jpeg or Dng",
            FrameFormat::ALL
                .iter()
                .filter(|f| f.is_raw())
                .map(|f| f.name())
                .collect::<Vec<_>>()
                .join(", ")
        )));
    };
    let time_s = time_s.filter(|t| t.is_finite() && *t > 0.0).ok_or_else(|| {
        DeviceError::Camera(format!(
            "{name}: the file states no exposure time (EXIF ExposureTime), so the exposure used is unknown"
        ))
    })?;
    Ok(DeliveredFrame {
        file: FrameFile { format, bytes },
        codes,
        exposure: FileExposure { time_s, f_number, iso },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn e(s: f64) -> ExposureTime {
        ExposureTime::from_seconds(s).unwrap()
    }

    fn timed(s: &str) -> f64 {
        match parse_shutter_speed(s).unwrap() {
            ShutterValue::Timed { seconds, .. } => seconds,
            other => panic!("{s}: {other:?}"),
        }
    }

    /// A Canon EOS 5D Mark II in ⅓-stop steps, manual mode: the labels of
    /// libgphoto2's `canon_shutterspeed` table (camlibs/ptp2/config.c) for
    /// the speeds the body offers, 1/8000 s to 30 s and bulb, in the
    /// camera's order (longest first).
    const EOS_5D2: [&str; 56] = [
        "bulb", "30", "25", "20", "15", "13", "10", "8", "6", "5", "4", "3.2", "2.5", "2", "1.6", "1.3", "1", "0.8",
        "0.6", "0.5", "0.4", "0.3", "1/4", "1/5", "1/6", "1/8", "1/10", "1/13", "1/15", "1/20", "1/25", "1/30", "1/40",
        "1/50", "1/60", "1/80", "1/100", "1/125", "1/160", "1/200", "1/250", "1/320", "1/400", "1/500", "1/640",
        "1/800", "1/1000", "1/1250", "1/1600", "1/2000", "1/2500", "1/3200", "1/4000", "1/5000", "1/6400", "1/8000",
    ];

    /// A Nikon D7000's `shutterspeed` through the PTP standard property, as
    /// `gphoto2 --get-config` printed it in libgphoto2 issue 518.
    const D7000: [&str; 54] = [
        "0.0001s", "0.0002s", "0.0003s", "0.0004s", "0.0005s", "0.0006s", "0.0008s", "0.0010s", "0.0012s", "0.0015s",
        "0.0020s", "0.0025s", "0.0031s", "0.0040s", "0.0050s", "0.0062s", "0.0080s", "0.0100s", "0.0125s", "0.0166s",
        "0.0200s", "0.0250s", "0.0333s", "0.0400s", "0.0500s", "0.0666s", "0.0769s", "0.1000s", "0.1250s", "0.1666s",
        "0.2000s", "0.2500s", "0.3333s", "0.4000s", "0.5000s", "0.6250s", "0.7692s", "1.0000s", "1.3000s", "1.6000s",
        "2.0000s", "2.5000s", "3.0000s", "4.0000s", "5.0000s", "6.0000s", "8.0000s", "10.0000s", "13.0000s",
        "15.0000s", "20.0000s", "25.0000s", "30.0000s", "Bulb",
    ];

    /// A Fuji X-T2's `shutterspeed` (libgphoto2 issue 506): 1/32000 s to
    /// 15 minutes, no bulb.
    const XT2: [&str; 68] = [
        "1/32000", "1/25000", "1/20000", "1/16000", "1/13000", "1/10000", "1/8000", "1/6400", "1/5000", "1/4000",
        "1/3200", "1/2500", "1/2000", "1/1600", "1/1250", "1/1000", "1/800", "1/640", "1/500", "1/400", "1/320",
        "1/250", "1/200", "1/160", "1/125", "1/100", "1/80", "1/60", "1/50", "1/40", "1/30", "1/25", "1/20", "1/15",
        "1/13", "1/10", "1/8", "1/6", "1/5", "1/4", "1/3", "0.4s", "1/2", "0.6s", "0.8s", "1s", "1.3s", "1.6s", "2s",
        "2.5s", "3s", "4s", "5s", "6s", "8s", "10s", "13s", "15s", "20s", "25s", "30s", "40s", "50s", "60s", "2m",
        "4m", "8m", "15m",
    ];

    #[test]
    fn every_vendor_notation_is_read_as_seconds() {
        for (s, want) in [
            ("1/4000", 0.000_25),
            ("1/4000s", 0.000_25),
            ("10/13", 10.0 / 13.0),
            ("13/10", 1.3),
            ("0.3", 0.3),
            ("2.5", 2.5),
            ("30", 30.0),
            ("20.3", 20.3),
            ("1\"3", 1.3),
            ("0\"3", 0.3),
            ("15\"", 15.0),
            ("30\"", 30.0),
            ("0.0001s", 0.0001),
            ("0,0002s", 0.0002),
            ("30,0000s", 30.0),
            ("0.4s", 0.4),
            ("2m", 120.0),
            ("15m", 900.0),
        ] {
            assert!((timed(s) - want).abs() < 1e-12, "{s}: {} against {want}", timed(s));
        }
        for s in ["bulb", "Bulb", "BULB"] {
            assert_eq!(parse_shutter_speed(s).unwrap(), ShutterValue::Bulb, "{s}");
        }
        for s in ["auto", "Time", "x 200"] {
            assert_eq!(parse_shutter_speed(s).unwrap(), ShutterValue::NotATime, "{s}");
        }
        // The interval a string stands for: "0.0001s" is 0.00005–0.00015 s.
        let ShutterValue::Timed { lo, hi, .. } = parse_shutter_speed("0.0001s").unwrap() else {
            panic!()
        };
        assert!(
            (lo - 0.000_05).abs() < 1e-15 && (hi - 0.000_15).abs() < 1e-15,
            "{lo} {hi}"
        );
        let ShutterValue::Timed { lo, hi, .. } = parse_shutter_speed("1/250").unwrap() else {
            panic!()
        };
        assert_eq!((lo, hi), (0.004, 0.004));
    }

    #[test]
    fn bad_shutter_strings_are_clear_errors() {
        for s in [
            "", "fast", "1/0", "0", "-1/4", "1/x", "0.0.3", "1//4", "1\"x", "m", "NaN",
        ] {
            let err = parse_shutter_speed(s).unwrap_err().to_string();
            assert!(
                err.contains("shutterspeed choice") && err.contains("1/250"),
                "{s:?}: {err}"
            );
        }
        let err = ShutterTable::from_choices(&["auto", "bulb"]).unwrap_err().to_string();
        assert!(err.contains("no timed speed") && err.contains("manual (M)"), "{err}");
    }

    #[test]
    fn a_canon_list_snaps_the_bracket_of_a_real_5d_mark_ii() {
        let table = ShutterTable::from_choices(&EOS_5D2).unwrap();
        assert_eq!(table.timed().len(), 55);
        assert_eq!(table.bulb(), Some("bulb"));
        assert_eq!(table.timed()[0].label, "1/8000");
        assert_eq!(table.timed()[54].label, "30");
        // The 18 frames of the radiantlab bracket (exposures.csv beside
        // the JPEGs): each EXIF time lands on its own label, 0 stops off.
        let bracket = [
            (13.0, "13"),
            (6.0, "6"),
            (3.2, "3.2"),
            (1.6, "1.6"),
            (0.8, "0.8"),
            (0.4, "0.4"),
            (0.2, "1/5"),
            (0.1, "1/10"),
            (0.05, "1/20"),
            (0.025, "1/40"),
            (1.0 / 80.0, "1/80"),
            (1.0 / 160.0, "1/160"),
            (1.0 / 320.0, "1/320"),
            (1.0 / 640.0, "1/640"),
            (1.0 / 1250.0, "1/1250"),
            (1.0 / 2500.0, "1/2500"),
            (1.0 / 5000.0, "1/5000"),
            (1.0 / 8000.0, "1/8000"),
        ];
        for (t, label) in bracket {
            let plan = table.plan(e(t), 30.0).unwrap();
            assert_eq!(plan, ShutterPlan::Timed(table.choice(label).unwrap().clone()), "{t}");
            assert_eq!(exposure_mismatch_stops(&plan, t), 0.0, "{t}");
        }
        // 1/3 s: "0.3" stands for 0.25–0.35 s and holds 1/3 s.
        let third = table.plan(e(1.0 / 3.0), 30.0).unwrap();
        assert_eq!(third.nominal().seconds(), 0.3);
        assert_eq!(exposure_mismatch_stops(&third, 1.0 / 3.0), 0.0);
        // Four stops down from 1/60 s is 1/960 s: the 1/1000 s notch, 12
        // notches along a ⅓-stop dial.
        assert_eq!(table.plan(e(1.0 / 960.0), 30.0).unwrap().nominal().seconds(), 0.001);
        assert_eq!(table.notches("1/60", e(1.0 / 960.0)).unwrap(), -12);
        assert_eq!(table.notches("1/1000", e(1.0 / 60.0)).unwrap(), 12);
        assert_eq!(table.notches("30", e(30.0)).unwrap(), 0);
        let err = table.notches("bulb", e(1.0)).unwrap_err().to_string();
        assert!(err.contains("no timed speed"), "{err}");
        assert!(matches!(
            table.plan(e(1.0 / 10_000.0), 30.0),
            Err(DeviceError::OutOfRange { .. })
        ));
    }

    #[test]
    fn beyond_the_longest_timed_speed_bulb_is_held_in_third_stops() {
        let table = ShutterTable::from_choices(&EOS_5D2).unwrap();
        let all = table.exposure_table(120.0);
        let bulb: Vec<f64> = all.times()[55..].iter().map(|t| t.seconds()).collect();
        // 30 · 2^(k/3) for k = 1..6: 37.80, 47.62, 60, 75.59, 95.24, 120.
        let want = [37.797_631, 47.622_031, 60.0, 75.595_262, 95.244_063, 120.0];
        assert_eq!(bulb.len(), want.len());
        for (got, want) in bulb.iter().zip(want) {
            assert!((got - want).abs() < 1e-5, "{got} against {want}");
        }
        // 60 s: bulb held 60 s; 33 s is nearer 30 s (0.137 stop) than
        // 37.8 s (0.196 stop): timed.
        assert_eq!(
            table.plan(e(60.0), 120.0).unwrap(),
            ShutterPlan::Bulb {
                choice: "bulb".into(),
                hold: e(60.0)
            }
        );
        assert!(matches!(table.plan(e(33.0), 120.0).unwrap(), ShutterPlan::Timed(c) if c.label == "30"));
        assert!(matches!(
            table.plan(e(200.0), 120.0),
            Err(DeviceError::OutOfRange { max, .. }) if max == 120.0
        ));
        // Without bulb (the X-T2 lists none) the table ends at its longest
        // timed speed, 15 min.
        let fuji = ShutterTable::from_choices(&XT2).unwrap();
        assert_eq!(fuji.bulb(), None);
        assert_eq!(fuji.timed().len(), 68);
        assert_eq!(fuji.exposure_table(3600.0).times().last().unwrap().seconds(), 900.0);
        assert!(matches!(
            fuji.plan(e(1000.0), 3600.0),
            Err(DeviceError::OutOfRange { .. })
        ));
        assert!(matches!(fuji.plan(e(100.0), 3600.0).unwrap(), ShutterPlan::Timed(c) if c.label == "2m"));
    }

    #[test]
    fn a_nikon_list_with_four_decimals_keeps_its_rounding() {
        let table = ShutterTable::from_choices(&D7000).unwrap();
        assert_eq!(table.timed().len(), 53);
        assert_eq!(table.bulb(), Some("Bulb"));
        // 1/8000 s is listed as "0.0001s" (0.32 stop short) and 1/13 s as
        // "0.0769s": both are their camera's notch, and the EXIF time of a
        // frame taken there lies inside what the string stands for.
        let fastest = table.plan(e(1.0 / 8000.0), 30.0).unwrap();
        assert!(matches!(&fastest, ShutterPlan::Timed(c) if c.label == "0.0001s"));
        assert_eq!(exposure_mismatch_stops(&fastest, 1.0 / 8000.0), 0.0);
        let thirteenth = table.plan(e(1.0 / 13.0), 30.0).unwrap();
        assert!(matches!(&thirteenth, ShutterPlan::Timed(c) if c.label == "0.0769s"));
        assert_eq!(exposure_mismatch_stops(&thirteenth, 1.0 / 13.0), 0.0);
        // A frame that came back at 1/4000 s from the 1/8000 s setting is
        // off by log2(0.00025 / 0.00015) = 0.737 stop.
        let off = exposure_mismatch_stops(&fastest, 1.0 / 4000.0);
        assert!((off - 0.736_966).abs() < 1e-6 && off > MISMATCH_STOPS, "{off}");
        assert_eq!(table.notches("1.0000s", e(2.0)).unwrap(), 3);
    }

    #[test]
    fn skipped_choices_are_listed() {
        let table = ShutterTable::from_choices(&["auto", "1/100", "1/100", "garbage", "1/50"]).unwrap();
        assert_eq!(table.timed().len(), 2);
        assert_eq!(table.skipped().len(), 2);
        assert!(table.skipped()[0].contains("not a fixed time"), "{:?}", table.skipped());
        assert!(table.skipped()[1].contains("\"garbage\""), "{:?}", table.skipped());
    }

    #[test]
    fn apertures_are_read_and_matched_in_stops() {
        for (s, want) in [
            ("f/8", 8.0),
            ("f8", 8.0),
            ("F5.6", 5.6),
            ("5.6", 5.6),
            ("f/2.8", 2.8),
            ("22", 22.0),
        ] {
            assert_eq!(parse_aperture(s).unwrap(), Some(want), "{s}");
        }
        assert_eq!(parse_aperture("implicit auto").unwrap(), None);
        let err = parse_aperture("wide").unwrap_err().to_string();
        assert!(err.contains("aperture choice \"wide\""), "{err}");
        let lens = ["f/4", "f/4.5", "f/5", "f/5.6", "f/6.3", "f/7.1", "f/8"];
        // f/5.7 is 0.05 stop from f/5.6; f/6 is 0.14 stop from f/6.3.
        assert_eq!(aperture_choice(&lens, 5.7).unwrap(), ("f/5.6".into(), 5.6));
        assert_eq!(aperture_choice(&lens, 6.0).unwrap(), ("f/6.3".into(), 6.3));
        let err = aperture_choice(&lens, 16.0).unwrap_err().to_string();
        assert!(err.contains("f/16 is not offered") && err.contains("\"f/8\""), "{err}");
        let err = aperture_choice(&["implicit auto"], 8.0).unwrap_err().to_string();
        assert!(err.contains("lists no f-number"), "{err}");
    }

    #[test]
    fn iso_is_gain_over_the_base_and_unoffered_speeds_are_errors() {
        for (s, want) in [
            ("100", IsoValue::Speed(100.0)),
            ("ISO 200", IsoValue::Speed(200.0)),
            ("Auto", IsoValue::Auto),
            ("Auto ISO", IsoValue::Auto),
            ("H1", IsoValue::High(1.0)),
            ("Hi 0.3", IsoValue::High(0.3)),
            ("H", IsoValue::High(1.0)),
            ("Lo 1", IsoValue::Low(1.0)),
            ("L", IsoValue::Low(1.0)),
        ] {
            assert_eq!(parse_iso(s).unwrap(), want, "{s}");
        }
        for s in ["", "fast", "ISO", "-100", "Hx"] {
            let err = parse_iso(s).unwrap_err().to_string();
            assert!(err.contains("iso choice"), "{s:?}: {err}");
        }
        // libgphoto2's canon_isospeed labels for a 5D Mark II, 100–6400 in
        // thirds, with Auto; and a Nikon-style list with Lo 1 and Hi 1.
        let canon = [
            "Auto", "100", "125", "160", "200", "250", "320", "400", "500", "640", "800", "1000", "1250", "1600",
            "2000", "2500", "3200", "4000", "5000", "6400",
        ];
        let t = IsoTable::from_choices(&canon).unwrap();
        assert_eq!(t.base(), 100.0);
        assert_eq!(t.speeds().len(), 19);
        // ISO 6400 is 20·log10(64) = 36.124 dB.
        assert!(
            (t.range().max.db() - 36.123_599_9).abs() < 1e-6,
            "{}",
            t.range().max.db()
        );
        // 12 dB is ISO 398: the 400 notch, 12.041 dB.
        let (label, iso, g) = t.choice_for(Gain::from_db(12.0).unwrap()).unwrap();
        assert_eq!((label, iso), ("400", 400.0));
        assert!((g.db() - 12.041_199_8).abs() < 1e-6, "{}", g.db());
        assert!(matches!(
            t.choice_for(Gain::from_db(40.0).unwrap()),
            Err(DeviceError::OutOfRange { .. })
        ));
        let nikon = ["Lo 1", "200", "400", "800", "1600", "3200", "6400", "Hi 1"];
        let t = IsoTable::from_choices(&nikon).unwrap();
        assert_eq!(t.base(), 200.0);
        // Hi 1 is one stop over 6400: 12800, 20·log10(64) dB over 200.
        assert_eq!(t.speeds().last().unwrap(), &("Hi 1".to_string(), 12_800.0));
        assert_eq!(t.skipped().len(), 1);
        // Whole stops only: 9 dB is ISO 564, half a stop from 400 and 800.
        let err = t.choice_for(Gain::from_db(9.0).unwrap()).unwrap_err().to_string();
        assert!(err.contains("does not offer") && err.contains("ISO 564"), "{err}");
        let err = IsoTable::from_choices(&["Auto"]).unwrap_err().to_string();
        assert!(err.contains("no numeric speed"), "{err}");
    }

    #[test]
    fn image_formats_pick_the_largest_finest_single_file() {
        // libgphoto2's canon_eos_image_format labels and Nikon's.
        let canon = [
            "Large Fine JPEG",
            "Large Normal JPEG",
            "Medium Fine JPEG",
            "Small Fine JPEG",
            "RAW + Large Fine JPEG",
            "mRAW",
            "sRAW",
            "RAW",
        ];
        assert_eq!(
            image_format_choice(&canon, WantedFile::Jpeg).unwrap(),
            "Large Fine JPEG"
        );
        assert_eq!(image_format_choice(&canon, WantedFile::Raw).unwrap(), "RAW");
        let nikon = [
            "JPEG Basic",
            "JPEG Normal",
            "JPEG Fine",
            "NEF (Raw)",
            "NEF+Basic",
            "NEF+Fine",
        ];
        assert_eq!(image_format_choice(&nikon, WantedFile::Jpeg).unwrap(), "JPEG Fine");
        assert_eq!(image_format_choice(&nikon, WantedFile::Raw).unwrap(), "NEF (Raw)");
        let err = image_format_choice(&["RAW + Large Fine JPEG"], WantedFile::Raw)
            .unwrap_err()
            .to_string();
        assert!(err.contains("no single-file RAW"), "{err}");
    }

    fn fixture(rel: &str) -> Vec<u8> {
        std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(rel)).unwrap()
    }

    #[test]
    fn a_real_eos_jpeg_gives_its_exif_exposure_and_codes() {
        let table = ShutterTable::from_choices(&EOS_5D2).unwrap();
        let d = decode_delivered(
            "IMG_6961.JPG",
            fixture("validation/hdr/fixtures/radiantlab-eos/IMG_6961.JPG"),
        )
        .unwrap();
        assert_eq!(d.file.format, FrameFormat::Jpeg);
        assert_eq!((d.codes.width, d.codes.height, d.codes.bits), (640, 640, 8));
        // exposures.csv: 1/5 s, f/5.6, ISO 100.
        assert_eq!(d.exposure.time_s, 0.2);
        assert_eq!(d.exposure.f_number, Some(5.6));
        assert_eq!(d.exposure.iso, Some(100.0));
        let asked = table.plan(e(0.2), 30.0).unwrap();
        assert_eq!(exposure_mismatch_stops(&asked, d.exposure.time_s), 0.0);
        // Had 1/10 s been set, the file shows the camera took one stop more.
        let other = table.plan(e(0.1), 30.0).unwrap();
        assert!((exposure_mismatch_stops(&other, d.exposure.time_s) - 1.0).abs() < 1e-12);
        // The file's f/5.6 and ISO 100 against what the camera was set to.
        assert!(settings_mismatches(Some(5.6), Some(100.0), &d.exposure).is_empty());
        assert!(settings_mismatches(None, None, &d.exposure).is_empty());
        assert_eq!(
            settings_mismatches(Some(8.0), Some(400.0), &d.exposure),
            [
                "the file says f/5.6, the aperture was f/8 (-1.03 stops)",
                "the file says ISO 100, the camera was set to ISO 400 (-2.00 stops)"
            ]
        );
        // f/6.3 is a third stop (0.34) from f/5.6: reported; f/5.7 (0.05) is not.
        assert_eq!(settings_mismatches(Some(6.3), None, &d.exposure).len(), 1);
        assert!(settings_mismatches(Some(5.7), None, &d.exposure).is_empty());
        // The bytes are kept as delivered.
        assert_eq!(
            d.file.bytes,
            fixture("validation/hdr/fixtures/radiantlab-eos/IMG_6961.JPG")
        );
    }

    #[test]
    fn a_dng_gives_its_exposure_through_the_raw_reader() {
        let d = decode_delivered("f.dng", fixture("validation/raw/fixtures/sim_rggb_14bit.dng")).unwrap();
        assert_eq!(d.file.format, FrameFormat::Dng);
        // Written by process/examples/write_dng_fixture.rs: 1/4 s, f/4, ISO 100.
        assert_eq!(d.exposure.time_s, 0.25);
        assert_eq!(d.exposure.f_number, Some(4.0));
        assert_eq!(d.exposure.iso, Some(100.0));
        assert_eq!(d.codes.bits, 16);
        assert_eq!(d.codes.data.len(), d.codes.width * d.codes.height * 3);
        // A DNG is known by its content, whatever the camera names it.
        let named = decode_delivered("IMGP0001.PEF", fixture("validation/raw/fixtures/sim_rggb_14bit.dng")).unwrap();
        assert_eq!(named.file.format, FrameFormat::Dng);
        assert!(named.codes.data == d.codes.data && named.codes.width == d.codes.width);
    }

    #[test]
    fn undecodable_files_are_clear_errors() {
        let cut = {
            let mut b = fixture("validation/hdr/fixtures/radiantlab-eos/IMG_6961.JPG");
            b.truncate(b.len() / 2);
            b
        };
        let err = decode_delivered("IMG_1.JPG", cut).unwrap_err().to_string();
        assert!(err.contains("IMG_1.JPG") && err.contains("cut short"), "{err}");
        // A CR2 that is no TIFF, and one whose TIFF holds no raw image: the
        // RAW reader's error, named, never a panic.
        let err = decode_delivered("IMG_2.CR2", b"GIF89a".to_vec())
            .unwrap_err()
            .to_string();
        assert!(
            err.starts_with("camera failure: IMG_2.CR2: 6 bytes") && err.contains("CR2 file"),
            "{err}"
        );
        let err = decode_delivered("IMG_3.CR2", b"II*\0\x10\0\0\0CR\x02\0\0\0\0\0".to_vec())
            .unwrap_err()
            .to_string();
        assert!(err.starts_with("camera failure: IMG_3.CR2: "), "{err}");
        let err = decode_delivered("x.bin", vec![1, 2, 3]).unwrap_err().to_string();
        assert!(
            err.contains("neither a JPEG nor a RAW file campanile reads (DNG, CR2, CR3, NEF")
                && err.contains("file_format to Jpeg"),
            "{err}"
        );
        // A JPEG without EXIF: the exposure used is unknown.
        let mut plain = Vec::new();
        image::codecs::jpeg::JpegEncoder::new(&mut plain)
            .encode(&[128u8; 8 * 8 * 3], 8, 8, image::ExtendedColorType::Rgb8)
            .unwrap();
        let err = decode_delivered("plain.jpg", plain).unwrap_err().to_string();
        assert!(err.contains("states no exposure time"), "{err}");
    }
}
