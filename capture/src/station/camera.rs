//! Opening the station's camera with the driver its config names, as far
//! as this build has it (the V4L2, nokhwa and Aravis drivers are cargo
//! features).

use crate::device::{Camera, CameraInfo, CaptureSettings, DeviceError, Frame};
use crate::driver::camera_thread::ThreadedCamera;
use crate::driver::indi::{CcdSettings, IndiCamera};
use campanile_config::camera::DeviceRef;
use campanile_config::camera::{Camera as CameraConfig, CameraDriver};

/// The camera `config` describes, open on its own thread; a clear error if
/// this build lacks its driver or the camera cannot be set up.
pub fn open_camera(config: &CameraConfig) -> Result<ThreadedCamera, DeviceError> {
    match config.driver {
        CameraDriver::Sim => Err(DeviceError::Camera(
            "the `Sim` camera exists only in the simulator; a real station names `V4l`, `Nokhwa`, `Indi`, `Aravis` or `Gphoto2`"
                .into(),
        )),
        CameraDriver::V4l => open_v4l(config),
        CameraDriver::Nokhwa => open_nokhwa(config),
        CameraDriver::Aravis => open_aravis(config),
        CameraDriver::Indi => Err(DeviceError::Camera(
            "an INDI camera is opened over the network: open_station_camera".into(),
        )),
        CameraDriver::Gphoto2 => open_gphoto2(config),
    }
}

/// A real station's camera, whichever driver its config names.
pub enum StationCamera {
    /// A V4L2, nokhwa or GenICam (Aravis) camera on its own thread.
    Threaded(ThreadedCamera),
    /// An INDI CCD.
    Indi(Box<IndiCamera>),
}

impl Camera for StationCamera {
    fn info(&self) -> CameraInfo {
        match self {
            StationCamera::Threaded(c) => c.info(),
            StationCamera::Indi(c) => c.info(),
        }
    }

    async fn capture(&mut self, settings: CaptureSettings) -> Result<Frame, DeviceError> {
        match self {
            StationCamera::Threaded(c) => c.capture(settings).await,
            StationCamera::Indi(c) => c.capture(settings).await,
        }
    }

    async fn reconnect(&mut self) -> Result<(), DeviceError> {
        match self {
            StationCamera::Threaded(c) => c.reconnect().await,
            StationCamera::Indi(c) => c.reconnect().await,
        }
    }
}

/// The camera `config` describes: an INDI CCD over the network (its frame
/// the configured resolution), or a V4L2, nokhwa or GenICam camera on its
/// thread.
pub async fn open_station_camera(config: &CameraConfig) -> Result<StationCamera, DeviceError> {
    match (&config.driver, &config.device) {
        (
            CameraDriver::Indi,
            Some(DeviceRef::Indi {
                server,
                device,
                gain,
                iso,
            }),
        ) => {
            let resolution = (config.resolution.width, config.resolution.height);
            let sensor = CcdSettings {
                gain: *gain,
                iso: iso.clone(),
            };
            Ok(StationCamera::Indi(Box::new(
                IndiCamera::open_with(server, device, Some(resolution), &sensor).await?,
            )))
        }
        (CameraDriver::Indi, _) => Err(DeviceError::Camera(
            "the Indi driver needs `device: Indi(server: \"host:port\", device: \"NAME\")`".into(),
        )),
        _ => open_camera(config).map(StationCamera::Threaded),
    }
}

/// Whether this build holds `driver` (the V4L2, nokhwa and Aravis drivers
/// are cargo features; the simulator's camera always is).
pub fn driver_built(driver: CameraDriver) -> bool {
    match driver {
        CameraDriver::V4l => cfg!(feature = "v4l"),
        CameraDriver::Nokhwa => cfg!(feature = "nokhwa"),
        CameraDriver::Gphoto2 => cfg!(feature = "gphoto2"),
        CameraDriver::Aravis => cfg!(feature = "aravis"),
        CameraDriver::Sim | CameraDriver::Indi => true,
    }
}

#[cfg(feature = "v4l")]
fn open_v4l(config: &CameraConfig) -> Result<ThreadedCamera, DeviceError> {
    crate::driver::v4l2::open(config, crate::driver::v4l2::V4l2Options::default())
}

#[cfg(not(feature = "v4l"))]
fn open_v4l(_: &CameraConfig) -> Result<ThreadedCamera, DeviceError> {
    Err(DeviceError::Camera(
        "this campanile was built without the V4L2 camera driver; rebuild with `--features v4l` (needs libclang)"
            .into(),
    ))
}

#[cfg(feature = "nokhwa")]
fn open_nokhwa(config: &CameraConfig) -> Result<ThreadedCamera, DeviceError> {
    crate::driver::nokhwa_camera::open(config)
}

#[cfg(not(feature = "nokhwa"))]
fn open_nokhwa(_: &CameraConfig) -> Result<ThreadedCamera, DeviceError> {
    Err(DeviceError::Camera(
        "this campanile was built without the nokhwa camera driver; rebuild with `--features nokhwa` (needs libclang)"
            .into(),
    ))
}

#[cfg(feature = "gphoto2")]
fn open_gphoto2(config: &CameraConfig) -> Result<ThreadedCamera, DeviceError> {
    crate::driver::gphoto2_camera::open(config)
}

#[cfg(not(feature = "gphoto2"))]
fn open_gphoto2(_: &CameraConfig) -> Result<ThreadedCamera, DeviceError> {
    Err(DeviceError::Camera(
        "this campanile was built without the gphoto2 camera driver; rebuild with `--features gphoto2` (needs libgphoto2-dev)"
            .into(),
    ))
}

#[cfg(feature = "aravis")]
fn open_aravis(config: &CameraConfig) -> Result<ThreadedCamera, DeviceError> {
    crate::driver::aravis_camera::open(config, crate::driver::aravis_camera::AravisOptions::default())
}

#[cfg(not(feature = "aravis"))]
fn open_aravis(_: &CameraConfig) -> Result<ThreadedCamera, DeviceError> {
    Err(DeviceError::Camera(
        "this campanile was built without the Aravis (GenICam) camera driver; rebuild with `--features aravis` (needs libaravis-dev)"
            .into(),
    ))
}

/// A GenICam camera Aravis finds: its id (what `Aravis(id: …)` takes) and
/// a description (vendor, model, protocol, address).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct GenicamCamera {
    /// Aravis's device id.
    pub id: String,
    /// Vendor, model, protocol and address.
    pub description: String,
}

/// The GenICam cameras Aravis finds (with `fake`, Aravis's fake camera
/// too), or `None` in a build without the `aravis` feature.
pub fn list_genicam_cameras(fake: bool) -> Option<Vec<GenicamCamera>> {
    #[cfg(feature = "aravis")]
    {
        use crate::driver::aravis_camera;
        if fake {
            aravis_camera::enable_fake_interface();
        }
        Some(
            aravis_camera::list()
                .into_iter()
                .map(|e| GenicamCamera {
                    description: format!(
                        "{} {} ({}{})",
                        e.vendor,
                        e.model,
                        e.protocol,
                        if e.address.is_empty() {
                            String::new()
                        } else {
                            format!(" at {}", e.address)
                        }
                    ),
                    id: e.id,
                })
                .collect(),
        )
    }
    #[cfg(not(feature = "aravis"))]
    {
        let _ = fake;
        None
    }
}

/// A video device found on the system.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CameraEntry {
    /// Its device node, e.g. `/dev/video0`.
    pub path: std::path::PathBuf,
    /// The name its driver gives it, if known.
    pub name: Option<String>,
}

/// The video devices under `dev` (nodes `videoN`, in order of N), named
/// from `sys` (`sys/videoN/name`, as /sys/class/video4linux has them).
/// Absent directories list nothing.
pub fn list_video_nodes(dev: &std::path::Path, sys: &std::path::Path) -> std::io::Result<Vec<CameraEntry>> {
    let entries = match std::fs::read_dir(dev) {
        Ok(e) => e,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(e),
    };
    let mut found = Vec::new();
    for entry in entries {
        let entry = entry?;
        let file = entry.file_name();
        let Some(n) = file
            .to_str()
            .and_then(|f| f.strip_prefix("video"))
            .and_then(|n| n.parse::<u32>().ok())
        else {
            continue;
        };
        let name = std::fs::read_to_string(sys.join(format!("video{n}")).join("name"))
            .ok()
            .map(|s| s.trim().to_owned())
            .filter(|s| !s.is_empty());
        found.push((
            n,
            CameraEntry {
                path: entry.path(),
                name,
            },
        ));
    }
    found.sort_by_key(|(n, _)| *n);
    Ok(found.into_iter().map(|(_, e)| e).collect())
}

/// The system's cameras: through V4L2 when this build has the `v4l`
/// feature, otherwise the /dev/video* nodes named from /sys.
pub fn list_cameras() -> std::io::Result<Vec<CameraEntry>> {
    #[cfg(feature = "v4l")]
    {
        let mut found: Vec<CameraEntry> = v4l::context::enum_devices()
            .into_iter()
            .map(|node| CameraEntry {
                path: node.path().to_path_buf(),
                name: node.name(),
            })
            .collect();
        found.sort_by(|a, b| a.path.cmp(&b.path));
        Ok(found)
    }
    #[cfg(not(feature = "v4l"))]
    {
        list_video_nodes(
            std::path::Path::new("/dev"),
            std::path::Path::new("/sys/class/video4linux"),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn video_nodes_are_listed_in_order_with_their_names() {
        let tmp = tempfile::tempdir().unwrap();
        let (dev, sys) = (tmp.path().join("dev"), tmp.path().join("sys"));
        std::fs::create_dir_all(&dev).unwrap();
        for f in ["video10", "video2", "videofoo", "ttyUSB0", "video0"] {
            std::fs::write(dev.join(f), "").unwrap();
        }
        std::fs::create_dir_all(sys.join("video2")).unwrap();
        std::fs::write(sys.join("video2/name"), "HD Webcam C920\n").unwrap();
        let got = list_video_nodes(&dev, &sys).unwrap();
        let paths: Vec<_> = got
            .iter()
            .map(|e| e.path.file_name().unwrap().to_str().unwrap())
            .collect();
        assert_eq!(paths, ["video0", "video2", "video10"]);
        assert_eq!(got[1].name.as_deref(), Some("HD Webcam C920"));
        assert_eq!(got[0].name, None);
        assert!(list_video_nodes(&tmp.path().join("absent"), &sys).unwrap().is_empty());
    }

    #[test]
    fn a_simulated_or_unbuilt_driver_is_a_clear_error() {
        let station = campanile_config::load_station(
            &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/real-station.ron"),
        )
        .unwrap()
        .value;
        let mut cfg = station.camera.clone();
        cfg.driver = CameraDriver::Sim;
        let e = open_camera(&cfg).unwrap_err().to_string();
        assert!(e.contains("exists only in the simulator"), "{e}");
        #[cfg(not(feature = "v4l"))]
        {
            let e = open_camera(&station.camera).unwrap_err().to_string();
            assert!(e.contains("rebuild with `--features v4l`"), "{e}");
        }
        #[cfg(not(feature = "gphoto2"))]
        {
            cfg.driver = CameraDriver::Gphoto2;
            let e = open_camera(&cfg).unwrap_err().to_string();
            assert!(e.contains("rebuild with `--features gphoto2`"), "{e}");
        }
        cfg.driver = CameraDriver::Aravis;
        cfg.device = Some(DeviceRef::Aravis {
            id: "Fake_1".into(),
            pixel_format: None,
        });
        assert_eq!(driver_built(CameraDriver::Aravis), cfg!(feature = "aravis"));
        #[cfg(not(feature = "aravis"))]
        {
            let e = open_camera(&cfg).unwrap_err().to_string();
            assert!(
                e.contains("rebuild with `--features aravis` (needs libaravis-dev)"),
                "{e}"
            );
            assert_eq!(list_genicam_cameras(true), None);
        }
    }
}
