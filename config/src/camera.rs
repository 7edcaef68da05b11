//! The camera: driver, intrinsics (thesis §3.2), lens falloff (§4.7.2) and
//! sensor limits.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use crate::shutter::ShutterSteps;
use crate::validate::{Validate, Validator};

/// Which driver talks to the camera.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
pub enum CameraDriver {
    /// The simulated camera of the `sim` crate.
    Sim,
    /// A V4L2 camera through the `v4l` crate (cargo feature `v4l`).
    V4l,
    /// A camera through `nokhwa` (cargo feature `nokhwa`).
    Nokhwa,
    /// An INDI `CCD` device on an INDI server (`device: Indi(server:
    /// "127.0.0.1:7624", device: "CCD Simulator")`); DSLRs reach INDI
    /// through `indi_gphoto_ccd`.
    Indi,
    /// A tethered DSLR or mirrorless body through libgphoto2 (cargo
    /// feature `gphoto2`): `device` absent for the first camera found,
    /// `Path("usb:001,004")` for a gphoto2 port, `Path("Canon EOS 5D Mark
    /// II")` for a model as `gphoto2 --auto-detect` lists it, or
    /// `Index(n)` for the n-th camera found.
    Gphoto2,
    /// A GenICam machine-vision camera (GigE Vision, USB3 Vision) through
    /// Aravis (cargo feature `aravis`; `device: Aravis(id: "Basler-21234567")`,
    /// the id `campanile devices` lists; Aravis's fake camera is `"Fake_1"`).
    Aravis,
}

/// How to find the camera device.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
pub enum DeviceRef {
    /// A device path such as "/dev/video0".
    Path(String),
    /// A device index as the driver enumerates them.
    Index(u32),
    /// A device on an INDI server, for the `Indi` driver.
    Indi {
        /// The server, `host:port` (INDI's port is 7624).
        server: String,
        /// The device's INDI name, e.g. "CCD Simulator".
        device: String,
        /// The sensor's gain as the driver states it (`CCD_GAIN`, in the
        /// driver's own units, not dB), held for the session; the driver's
        /// own when absent.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        gain: Option<f64>,
        /// A DSLR's ISO through `indi_gphoto_ccd` (`CCD_ISO`), e.g. "100".
        #[serde(default, skip_serializing_if = "Option::is_none")]
        iso: Option<String>,
    },
    /// A GenICam camera, for the `Aravis` driver.
    Aravis {
        /// Aravis's device id (`Vendor-Serial`, e.g. "Basler-21234567"),
        /// its physical id, or its address, as `campanile devices` lists
        /// them; `"Fake_1"` is Aravis's fake camera.
        id: String,
        /// The GenICam pixel format to capture in (one of
        /// [`GENICAM_PIXEL_FORMATS`]); when absent the driver takes the
        /// deepest raw format the camera offers.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pixel_format: Option<String>,
    },
}

/// The GenICam (PFNC) pixel formats the `Aravis` driver reads: unpacked
/// monochrome, unpacked Bayer mosaics (demosaiced by the driver) and
/// packed 8-bit RGB.
pub const GENICAM_PIXEL_FORMATS: [&str; 21] = [
    "Mono8",
    "Mono10",
    "Mono12",
    "Mono16",
    "BayerRG8",
    "BayerGR8",
    "BayerGB8",
    "BayerBG8",
    "BayerRG10",
    "BayerGR10",
    "BayerGB10",
    "BayerBG10",
    "BayerRG12",
    "BayerGR12",
    "BayerGB12",
    "BayerBG12",
    "BayerRG16",
    "BayerGR16",
    "BayerGB16",
    "BayerBG16",
    "RGB8",
];

/// Checks an INDI server address and device name under `v`.
pub(crate) fn validate_indi(v: &mut Validator, server: &str, device: &str) {
    let port_ok = server
        .rsplit_once(':')
        .is_some_and(|(host, port)| !host.is_empty() && port.parse::<u16>().is_ok_and(|p| p > 0));
    if !port_ok {
        v.invalid(
            "server",
            format!("{server:?}"),
            "an INDI server as host:port, e.g. \"127.0.0.1:7624\"",
        );
    }
    v.non_empty("device", device);
}

/// Image size in pixels.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
#[serde(deny_unknown_fields)]
pub struct Resolution {
    /// Width in pixels, in [1, 65536].
    pub width: u32,
    /// Height in pixels, in [1, 65536].
    pub height: u32,
}

/// How the lens maps a ray's angle θ off the optical axis to its ideal
/// normalized image radius ρ (image radius over the focal length, before
/// the radial terms): the central (pinhole) projection, or one of the two
/// fisheye projections all-sky cameras are built to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
pub enum Projection {
    /// ρ = tan θ: the rectilinear (pinhole) lens, field under 180°.
    #[default]
    Pinhole,
    /// ρ = θ (radians): the equidistant ("f-theta") fisheye.
    Equidistant,
    /// ρ = 2 sin(θ/2): the equisolid-angle (equal-area) fisheye.
    Equisolid,
}

impl Projection {
    /// Whether this is the central projection (the default).
    pub fn is_pinhole(&self) -> bool {
        *self == Projection::Pinhole
    }

    /// Whether this is one of the fisheye projections.
    pub fn is_fisheye(&self) -> bool {
        !self.is_pinhole()
    }

    /// The ideal normalized radius ρ of a ray `theta` radians off the axis
    /// (infinite for a pinhole at or past 90°).
    pub fn radius(self, theta: f64) -> f64 {
        match self {
            Projection::Pinhole if theta >= std::f64::consts::FRAC_PI_2 => f64::INFINITY,
            Projection::Pinhole => theta.tan(),
            Projection::Equidistant => theta,
            Projection::Equisolid => 2.0 * (0.5 * theta).sin(),
        }
    }

    /// The angle off the axis of ideal normalized radius `rho` ≥ 0 (the
    /// inverse of [`Projection::radius`]); `None` past the projection's
    /// largest radius (equisolid: ρ > 2).
    pub fn angle(self, rho: f64) -> Option<f64> {
        match self {
            Projection::Pinhole => Some(rho.atan()),
            Projection::Equidistant => (rho <= std::f64::consts::PI).then_some(rho),
            Projection::Equisolid => (rho <= 2.0).then(|| 2.0 * (0.5 * rho).asin()),
        }
    }

    /// The widest field of view, degrees, a lens of this projection can
    /// have across the image (a pinhole's is under 180°, a fisheye's under 360°).
    pub fn max_field_deg(self) -> f64 {
        if self.is_pinhole() { 180.0 } else { 360.0 }
    }
}

/// The focal length, either directly in pixels or through a field of view.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
pub enum Focal {
    /// Focal length in pixels, in (0, 1e6].
    Pixels(f64),
    /// Horizontal field of view in degrees, in (0, 180).
    HorizontalFovDeg(f64),
}

impl Focal {
    /// The focal length in pixels for an image `width` pixels wide, of a
    /// pinhole lens (a field of view is ideal: radial terms left out).
    pub fn pixels(self, width: u32) -> f64 {
        self.pixels_for(Projection::Pinhole, width)
    }

    /// The focal length in pixels for an image `width` pixels wide through
    /// `projection`: a horizontal field of view 2θ puts the image's side
    /// edges at ideal radius ρ(θ), so f = (width / 2) / ρ(θ).
    pub fn pixels_for(self, projection: Projection, width: u32) -> f64 {
        match self {
            Focal::Pixels(f) => f,
            Focal::HorizontalFovDeg(fov) => 0.5 * f64::from(width) / projection.radius(0.5 * fov.to_radians()),
        }
    }
}

/// Camera intrinsics: a projection (pinhole or fisheye) with radial
/// distortion, and vignetting falloff.
///
/// Distortion: a ray θ off the axis has the ideal normalized radius
/// `r = ρ(θ)` of the projection (`tan θ`, `θ` or `2 sin(θ/2)`); it is
/// imaged at `r (1 + k1 r² + k2 r⁴)` focal lengths from the principal
/// point. Falloff: with `ρ` the distance from the image
/// centre normalized to 1 at the corners (as `campanile hdr lens` fits it),
/// the recorded intensity is scaled by `1 + a ρ² + b ρ⁴` (thesis §4.7.2).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
#[serde(deny_unknown_fields)]
pub struct Intrinsics {
    /// The focal length (a field of view is through `projection`).
    pub focal: Focal,
    /// The lens's projection: `Pinhole` (the default), `Equidistant` or
    /// `Equisolid` (fisheyes, whose field may reach 90° off the axis and
    /// beyond).
    #[serde(default, skip_serializing_if = "Projection::is_pinhole")]
    pub projection: Projection,
    /// Principal point `(x, y)` in pixels; the image centre when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub principal_point_px: Option<(f64, f64)>,
    /// Radial distortion coefficients `(k1, k2)`, each in [-2, 2].
    #[serde(default)]
    pub distortion: (f64, f64),
    /// Falloff coefficients `(a, b)` of `1 + a ρ² + b ρ⁴` (ρ = 1 at the corners), each in [-2, 2].
    #[serde(default)]
    pub falloff: (f64, f64),
}

/// The smallest ideal radius in (0, `rho_max`] at which the distorted
/// radius `r (1 + k1 r² + k2 r⁴)` stops growing (its derivative
/// `1 + 3 k1 r² + 5 k2 r⁴` reaches zero), or `None` when it grows all the
/// way out: where the lens model would fold the image over.
pub fn fold_radius((k1, k2): (f64, f64), rho_max: f64) -> Option<f64> {
    // The derivative as a quadratic in s = r²: 1 + 3 k1 s + 5 k2 s².
    let (a, b) = (5.0 * k2, 3.0 * k1);
    let s_max = rho_max * rho_max;
    let roots: Vec<f64> = if a.abs() < 1e-300 {
        if b < 0.0 { vec![-1.0 / b] } else { vec![] }
    } else {
        let disc = b * b - 4.0 * a;
        if disc < 0.0 {
            vec![]
        } else {
            let q = disc.sqrt();
            vec![(-b - q) / (2.0 * a), (-b + q) / (2.0 * a)]
        }
    };
    roots
        .into_iter()
        .filter(|&s| s > 0.0 && s <= s_max)
        .min_by(f64::total_cmp)
        .map(f64::sqrt)
}

/// A closed interval of exposure times in seconds.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
#[serde(deny_unknown_fields)]
pub struct ExposureLimits {
    /// Shortest exposure in seconds, > 0.
    pub min_s: f64,
    /// Longest exposure in seconds, ≥ `min_s` and ≤ 3600.
    pub max_s: f64,
    /// How the shutter steps between the limits: `Continuous` (the
    /// default), or a DSLR's nominal series (`Thirds`, `Halves`, `Whole`),
    /// to which the camera snaps every exposure asked for.
    #[serde(default, skip_serializing_if = "ShutterSteps::is_continuous")]
    pub steps: ShutterSteps,
}

/// A closed interval of analogue gains in dB.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
#[serde(deny_unknown_fields)]
pub struct GainLimits {
    /// Lowest gain in dB, in [0, 60].
    pub min_db: f64,
    /// Highest gain in dB, in [`min_db`, 60].
    pub max_db: f64,
}

/// The file the camera delivers each frame as (the simulated camera; real
/// drivers deliver what their device gives).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
pub enum FrameFileFormat {
    /// Decoded codes, stored by the session as a lossless 16-bit PNG.
    #[default]
    Png,
    /// A JPEG at quality 95 with EXIF ExposureTime (8-bit codes).
    Jpeg,
    /// A DNG of the sensor's Bayer mosaic (linear, black and white levels).
    Dng,
    /// A FITS file of the sensor's linear codes (R, G, B planes and an
    /// `EXPTIME` card), as an INDI astro camera delivers.
    Fits,
}

impl FrameFileFormat {
    fn is_png(&self) -> bool {
        *self == FrameFileFormat::Png
    }
}

/// The camera as the station drives it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(proptest_derive::Arbitrary))]
#[serde(deny_unknown_fields)]
pub struct Camera {
    /// The driver.
    pub driver: CameraDriver,
    /// The device, for real drivers; ignored by `Sim`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub device: Option<DeviceRef>,
    /// Frame size.
    pub resolution: Resolution,
    /// Geometric and photometric intrinsics.
    pub intrinsics: Intrinsics,
    /// Bits per sample of the raw frames: 8, 10, 12, 14 or 16.
    pub bit_depth: u8,
    /// Exposure time limits.
    pub exposure: ExposureLimits,
    /// Gain limits.
    pub gain: GainLimits,
    /// A previously recovered response curve (CSV from `campanile hdr
    /// calibrate`), relative to this file; recovered anew when absent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[cfg_attr(test, proptest(strategy = "crate::arbitrary::opt_path()"))]
    pub response_curve: Option<PathBuf>,
    /// The file each frame arrives as (`Png` when absent): `Jpeg` or `Dng`
    /// makes the simulated camera deliver what a DSLR would, `Fits` what an
    /// astro camera would, kept byte for byte by the session and decoded by
    /// `campanile process`. The `Sim` driver takes it, and `Gphoto2` (`Jpeg`
    /// or `Dng`), which sets the camera's image format to its largest
    /// finest JPEG (`Jpeg`) or its RAW (`Dng`: whatever RAW the camera
    /// writes, DNG, CR2, NEF, …), or leaves it as the camera has it (`Png`).
    #[serde(default, skip_serializing_if = "FrameFileFormat::is_png")]
    pub file_format: FrameFileFormat,
}

impl Validate for Camera {
    fn validate(&self, v: &mut Validator) {
        match (&self.driver, &self.device) {
            (CameraDriver::Sim, _) => {}
            (CameraDriver::Indi, Some(DeviceRef::Indi { server, device, gain, iso })) => {
                v.at("device", |v| {
                    validate_indi(v, server, device);
                    if let Some(g) = gain {
                        v.range("gain", *g, 0.0, 1.0e6, "a gain in the INDI driver's units (CCD_GAIN), at least 0");
                    }
                    if iso.as_deref().is_some_and(|i| i.trim().is_empty()) {
                        v.invalid("iso", format!("{iso:?}"), "an ISO the camera offers, e.g. \"100\"");
                    }
                });
            }
            (CameraDriver::Indi, other) => v.invalid(
                "device",
                format!("{other:?}"),
                "an INDI device for the Indi driver, e.g. `device: Indi(server: \"127.0.0.1:7624\", device: \"CCD Simulator\")`",
            ),
            (CameraDriver::Aravis, Some(DeviceRef::Aravis { id, pixel_format })) => {
                v.at("device", |v| {
                    v.non_empty("id", id);
                    if let Some(f) = pixel_format
                        && !GENICAM_PIXEL_FORMATS.contains(&f.as_str())
                    {
                        v.invalid(
                            "pixel_format",
                            format!("{f:?}"),
                            &format!(
                                "a GenICam pixel format the Aravis driver reads: one of {}",
                                GENICAM_PIXEL_FORMATS.join(", ")
                            ),
                        );
                    }
                });
            }
            (CameraDriver::Aravis, other) => v.invalid(
                "device",
                format!("{other:?}"),
                "a GenICam camera for the Aravis driver, e.g. `device: Aravis(id: \"Fake_1\")` (the ids `campanile devices` lists)",
            ),
            (_, Some(DeviceRef::Indi { .. })) => v.invalid(
                "device",
                "Indi(...)".into(),
                "a Path or an Index for this driver (an INDI device needs `driver: Indi`)",
            ),
            (CameraDriver::Gphoto2, None) => {}
            (_, Some(DeviceRef::Aravis { .. })) => v.invalid(
                "device",
                "Aravis(...)".into(),
                "a Path or an Index for this driver (a GenICam camera needs `driver: Aravis`)",
            ),
            (_, None) => v.invalid(
                "device",
                "nothing".into(),
                "a device for a real camera driver, e.g. `device: Some(Path(\"/dev/video0\"))`",
            ),
            (_, Some(DeviceRef::Path(p))) => {
                v.at("device", |v| v.non_empty(0, p));
            }
            (_, Some(DeviceRef::Index(_))) => {}
        }
        v.at("resolution", |v| {
            v.range_u(
                "width",
                self.resolution.width.into(),
                1,
                65536,
                "an image width in pixels",
            );
            v.range_u(
                "height",
                self.resolution.height.into(),
                1,
                65536,
                "an image height in pixels",
            );
        });
        v.at("intrinsics", |v| {
            let i = &self.intrinsics;
            match i.focal {
                Focal::Pixels(f) => v.at("focal", |v| {
                    v.range_open_low(0, f, 0.0, 1e6, "a focal length in pixels")
                }),
                Focal::HorizontalFovDeg(fov) => v.at("focal", |v| {
                    let what = if i.projection.is_pinhole() {
                        "a horizontal field of view in degrees (a fisheye projection takes up to 360)"
                    } else {
                        "a horizontal field of view in degrees"
                    };
                    v.range_open(0, fov, 0.0, i.projection.max_field_deg(), what)
                }),
            }
            if let Some((x, y)) = i.principal_point_px {
                v.at("principal_point_px", |v| {
                    let (w, h) = (f64::from(self.resolution.width), f64::from(self.resolution.height));
                    v.range(0, x, 0.0, w, "a principal point x inside the image, in pixels");
                    v.range(1, y, 0.0, h, "a principal point y inside the image, in pixels");
                });
            }
            v.at("distortion", |v| {
                v.range(0, i.distortion.0, -2.0, 2.0, "a radial distortion coefficient k1");
                v.range(1, i.distortion.1, -2.0, 2.0, "a radial distortion coefficient k2");
            });
            if i.projection.is_fisheye() {
                let rho = i.projection.radius(std::f64::consts::FRAC_PI_2);
                if let Some(fold) = fold_radius(i.distortion, rho) {
                    v.invalid(
                        "distortion",
                        format!("{:?}", i.distortion),
                        &format!(
                            "radial terms whose image radius grows out to 90° off the axis for a fisheye \
                             (these fold the image over at {:.1}° off the axis)",
                            i.projection
                                .angle(fold)
                                .unwrap_or(std::f64::consts::FRAC_PI_2)
                                .to_degrees()
                        ),
                    );
                }
            }
            v.at("falloff", |v| {
                v.range(0, i.falloff.0, -2.0, 2.0, "a falloff coefficient a");
                v.range(1, i.falloff.1, -2.0, 2.0, "a falloff coefficient b");
            });
        });
        if ![8, 10, 12, 14, 16].contains(&self.bit_depth) {
            v.invalid(
                "bit_depth",
                self.bit_depth.to_string(),
                "one of 8, 10, 12, 14 or 16 bits",
            );
        }
        v.at("exposure", |v| {
            let e = self.exposure;
            v.range_open_low("min_s", e.min_s, 0.0, 3600.0, "an exposure time in seconds");
            v.range(
                "max_s",
                e.max_s,
                e.min_s.max(0.0),
                3600.0,
                "an exposure time in seconds (at least min_s)",
            );
            if e.steps.within(e.min_s, e.max_s).is_some_and(|s| s.is_empty()) {
                v.invalid(
                    "steps",
                    format!("{:?}", e.steps),
                    "a shutter series with a speed between min_s and max_s (the series run 1/8000 s to 30 s)",
                );
            }
        });
        v.at("gain", |v| {
            let g = self.gain;
            v.range("min_db", g.min_db, 0.0, 60.0, "a gain in dB");
            v.range(
                "max_db",
                g.max_db,
                g.min_db.max(0.0),
                60.0,
                "a gain in dB (at least min_db)",
            );
        });
        let takes = match self.driver {
            CameraDriver::Sim => true,
            CameraDriver::Gphoto2 => self.file_format != FrameFileFormat::Fits,
            _ => self.file_format == FrameFileFormat::Png,
        };
        if !takes {
            v.invalid(
                "file_format",
                format!("{:?}", self.file_format),
                "Png (the default) for this camera driver: the simulated camera takes Jpeg, Dng or Fits, Gphoto2 Jpeg or Dng",
            );
        }
        if let Some(p) = &self.response_curve {
            v.existing_file("response_curve", p, "a response curve CSV");
        }
    }
}
