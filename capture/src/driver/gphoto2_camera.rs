//! A tethered DSLR or mirrorless body through libgphoto2 (cargo feature
//! `gphoto2`, crate `gphoto2`, Debian `libgphoto2-dev`): the [`Tether`]
//! that [`TetheredCamera`] drives.
//!
//! **This backend has never met a camera.** Debian's libgphoto2 has no
//! virtual camera (`vusb`), so what is tested is the settings mapping
//! ([`gphoto_settings`](super::gphoto_settings)) and the camera logic
//! ([`tethered_camera`](super::tethered_camera)) in every build, against
//! real choice lists and real camera files, and here the choice of camera
//! and that opening with no camera attached is a clear [`DeviceError`].
//! The libgphoto2 calls below follow its documented use (`gphoto2
//! --capture-image-and-download`, the bulb recipes of gphoto.org/doc/remote)
//! and are untried.
//!
//! The camera is the first one libgphoto2 detects, or the one the station's
//! `device` names: a port (`Path("usb:001,004")`, any string with a gphoto2
//! port prefix), a model as `gphoto2 --auto-detect` lists it
//! (`Path("Canon EOS 5D Mark II")`), or the n-th camera found (`Index(n)`).

use super::camera_thread::ThreadedCamera;
use super::tethered_camera::{CameraFile, Tether, TetheredCamera};
use crate::device::DeviceError;
use campanile_config::camera::{Camera as CameraConfig, DeviceRef};
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

/// Open the station's gphoto2 camera on its own thread, as a
/// [`Camera`](crate::device::Camera).
pub fn open(config: &CameraConfig) -> Result<ThreadedCamera, DeviceError> {
    let config = config.clone();
    let name = format!("gphoto2 {}", device_label(config.device.as_ref()));
    ThreadedCamera::spawn(&name, move || {
        let tether = Gphoto2Tether::open(config.device.as_ref())?;
        TetheredCamera::new(tether, &config)
    })
}

fn device_label(device: Option<&DeviceRef>) -> String {
    match device {
        None => "(first camera found)".into(),
        Some(DeviceRef::Path(p)) => p.clone(),
        Some(DeviceRef::Index(i)) => format!("camera number {i}"),
        Some(DeviceRef::Indi { device, .. }) => device.clone(),
        Some(DeviceRef::Aravis { id, .. }) => id.clone(),
    }
}

/// The camera `device` names among those detected (the first when it
/// names none); a clear error listing what was found when none matches.
pub fn pick<'a>(
    found: &'a [CameraDescriptor],
    device: Option<&DeviceRef>,
) -> Result<&'a CameraDescriptor, DeviceError> {
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
        Some(DeviceRef::Aravis { .. }) => {
            return Err(DeviceError::Camera(
                "a GenICam camera names no gphoto2 camera: use driver Aravis, or a port or model".into(),
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

/// A camera open through libgphoto2.
pub struct Gphoto2Tether {
    camera: Camera,
    name: String,
}

impl std::fmt::Debug for Gphoto2Tether {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Gphoto2Tether")
            .field("name", &self.name)
            .finish_non_exhaustive()
    }
}

impl Gphoto2Tether {
    /// Finds and opens the camera `device` names (module doc); with no
    /// camera attached, a [`DeviceError::Camera`] saying what to check.
    pub fn open(device: Option<&DeviceRef>) -> Result<Self, DeviceError> {
        let gp = |what: &'static str| move |e: gphoto2::Error| DeviceError::Camera(format!("gphoto2: {what}: {e}"));
        let context = Context::new().map_err(gp("cannot start libgphoto2"))?;
        let found: Vec<CameraDescriptor> = context
            .list_cameras()
            .wait()
            .map_err(gp("cannot list cameras"))?
            .collect();
        let desc = pick(&found, device)?.clone();
        let name = format!("{} at {}", desc.model, desc.port);
        let camera = context
            .get_camera(&desc)
            .wait()
            .map_err(|e| DeviceError::Camera(format!("gphoto2: cannot open {name}: {e}")))?;
        Ok(Self { camera, name })
    }

    fn failed(&self, what: &str, e: impl std::fmt::Display) -> DeviceError {
        DeviceError::Camera(format!("{}: {what}: {e}", self.name))
    }

    fn radio(&self, key: &str) -> Result<RadioWidget, gphoto2::Error> {
        self.camera.config_key::<RadioWidget>(key).wait()
    }
}

impl Tether for Gphoto2Tether {
    fn name(&self) -> &str {
        &self.name
    }

    fn choices(&mut self, key: &str) -> Option<Vec<String>> {
        self.radio(key).ok().map(|w| w.choices_iter().collect())
    }

    fn current(&mut self, key: &str) -> Result<String, DeviceError> {
        self.radio(key)
            .map(|w| w.choice())
            .map_err(|e| self.failed(&format!("reading {key}"), e))
    }

    fn set(&mut self, key: &str, choice: &str) -> Result<(), DeviceError> {
        let w = self.radio(key).map_err(|e| self.failed(&format!("reading {key}"), e))?;
        w.set_choice(choice)
            .and_then(|()| self.camera.set_config(&w).wait())
            .map_err(|e| self.failed(&format!("setting {key} to {choice:?}"), e))
    }

    fn has_toggle(&mut self, key: &str) -> bool {
        self.camera.config_key::<ToggleWidget>(key).wait().is_ok()
    }

    fn set_toggle(&mut self, key: &str, on: bool) -> Result<(), DeviceError> {
        let w = self
            .camera
            .config_key::<ToggleWidget>(key)
            .wait()
            .map_err(|e| self.failed(&format!("reading {key}"), e))?;
        w.set_toggled(on);
        self.camera
            .set_config(&w)
            .wait()
            .map_err(|e| self.failed(&format!("setting {key} {}", if on { "on" } else { "off" }), e))
    }

    fn capture(&mut self) -> Result<CameraFile, DeviceError> {
        let path = self
            .camera
            .capture_image()
            .wait()
            .map_err(|e| self.failed("capturing", e))?;
        Ok(CameraFile {
            folder: path.folder().into_owned(),
            name: path.name().into_owned(),
        })
    }

    fn await_new_file(&mut self, timeout: Duration) -> Result<CameraFile, DeviceError> {
        let deadline = Instant::now() + timeout;
        while Instant::now() < deadline {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.camera.wait_event(left).wait() {
                Ok(CameraEvent::NewFile(path)) => {
                    return Ok(CameraFile {
                        folder: path.folder().into_owned(),
                        name: path.name().into_owned(),
                    });
                }
                Ok(CameraEvent::Timeout) => break,
                Ok(_) => {}
                Err(e) => return Err(self.failed("waiting for the file", e)),
            }
        }
        Err(DeviceError::Timeout(format!(
            "{}: no new file within {timeout:?} of the exposure's end",
            self.name
        )))
    }

    fn download(&mut self, file: &CameraFile) -> Result<Vec<u8>, DeviceError> {
        let path = format!("{}/{}", file.folder, file.name);
        let fs = self.camera.fs();
        let f = fs
            .download(&file.folder, &file.name)
            .wait()
            .map_err(|e| self.failed(&format!("downloading {path}"), e))?;
        let data = f
            .get_data(&self.camera)
            .wait()
            .map_err(|e| self.failed(&format!("reading {path}"), e))?;
        if let Err(e) = fs.delete_file(&file.folder, &file.name).wait() {
            tracing::info!(camera = %self.name, file = %path, "left on the camera: {e}");
        }
        Ok(data.into_vec())
    }
}
