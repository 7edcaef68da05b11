//! A blocking camera API behind the async [`Camera`] trait: the camera
//! lives on a thread of its own, and each capture is a request to it.
//!
//! V4L2 and nokhwa block while a frame is exposed and read out (up to the
//! longest exposure, seconds), and nokhwa's camera cannot move between
//! threads. So the camera is opened on its own thread, and the async side
//! sends it settings and awaits the frame; the controller's runtime thread
//! never blocks on the camera.

use crate::device::{Camera, CameraInfo, CaptureSettings, DeviceError, Frame};
use std::sync::mpsc;
use tokio::sync::oneshot;

/// A camera driven by blocking calls, owned by one thread.
pub trait BlockingCamera {
    /// Resolution, depth and ranges.
    fn info(&self) -> CameraInfo;

    /// Take one frame (blocks until it is read out).
    fn capture(&mut self, settings: CaptureSettings) -> Result<Frame, DeviceError>;
}

type Reply = oneshot::Sender<Result<Frame, DeviceError>>;

/// A [`BlockingCamera`] on its own thread, as a [`Camera`]. Dropping it
/// ends the thread once the capture in progress, if any, is done.
#[derive(Debug)]
pub struct ThreadedCamera {
    info: CameraInfo,
    requests: mpsc::Sender<(CaptureSettings, Reply)>,
    name: String,
}

impl ThreadedCamera {
    /// Start a thread named `name`, open the camera there with `open`, and
    /// return once it is open (or with `open`'s error).
    pub fn spawn<B, F>(name: &str, open: F) -> Result<Self, DeviceError>
    where
        B: BlockingCamera,
        F: FnOnce() -> Result<B, DeviceError> + Send + 'static,
    {
        let (requests, inbox) = mpsc::channel::<(CaptureSettings, Reply)>();
        let (opened, open_result) = mpsc::channel::<Result<CameraInfo, DeviceError>>();
        std::thread::Builder::new()
            .name(name.to_owned())
            .spawn(move || {
                let mut camera = match open() {
                    Ok(c) => c,
                    Err(e) => {
                        let _ = opened.send(Err(e));
                        return;
                    }
                };
                if opened.send(Ok(camera.info())).is_err() {
                    return;
                }
                while let Ok((settings, reply)) = inbox.recv() {
                    let _ = reply.send(camera.capture(settings));
                }
            })
            .map_err(|e| DeviceError::Camera(format!("{name}: cannot start the camera thread: {e}")))?;
        let info = open_result
            .recv()
            .map_err(|_| DeviceError::Camera(format!("{name}: the camera thread ended while opening the camera")))??;
        Ok(Self {
            info,
            requests,
            name: name.to_owned(),
        })
    }
}

impl Camera for ThreadedCamera {
    fn info(&self) -> CameraInfo {
        self.info.clone()
    }

    async fn capture(&mut self, settings: CaptureSettings) -> Result<Frame, DeviceError> {
        let gone = || DeviceError::Camera(format!("{}: the camera thread has ended", self.name));
        let (reply, frame) = oneshot::channel();
        self.requests.send((settings, reply)).map_err(|_| gone())?;
        frame.await.map_err(|_| gone())?
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::device::{ExposureRange, ExposureTime, Gain, GainRange};
    use std::rc::Rc;

    /// Not `Send` (like nokhwa's camera): it must stay on its thread.
    struct Counting {
        frames: Rc<std::cell::Cell<u64>>,
        fail_on: u64,
    }

    fn info() -> CameraInfo {
        CameraInfo {
            model: "counting".into(),
            width: 2,
            height: 1,
            bits: 8,
            exposure: ExposureRange {
                min: ExposureTime::from_micros(100).unwrap(),
                max: ExposureTime::from_seconds(1.0).unwrap(),
                step: ExposureTime::from_micros(100).unwrap(),
            },
            gain: GainRange {
                min: Gain::UNITY,
                max: Gain::UNITY,
                step_db: 0.0,
            },
            exposure_table: None,
            linear: false,
        }
    }

    impl BlockingCamera for Counting {
        fn info(&self) -> CameraInfo {
            info()
        }

        fn capture(&mut self, settings: CaptureSettings) -> Result<Frame, DeviceError> {
            let n = self.frames.get();
            self.frames.set(n + 1);
            if n == self.fail_on {
                return Err(DeviceError::Timeout(format!("frame {n}")));
            }
            std::thread::sleep(settings.exposure.duration());
            Ok(Frame {
                width: 2,
                height: 1,
                bits: 8,
                data: vec![n as u16; 6],
                exposure_requested: settings.exposure,
                exposure_actual: settings.exposure,
                gain: settings.gain,
                sequence: n,
                timestamp: chrono::DateTime::default(),
                temperature_c: None,
                file: None,
            })
        }
    }

    fn settings() -> CaptureSettings {
        CaptureSettings {
            exposure: ExposureTime::from_seconds(0.002).unwrap(),
            gain: Gain::UNITY,
        }
    }

    #[tokio::test]
    async fn frames_come_back_in_order_and_errors_pass_through() {
        let mut cam = ThreadedCamera::spawn("test camera", || {
            Ok(Counting {
                frames: Rc::new(std::cell::Cell::new(0)),
                fail_on: 2,
            })
        })
        .unwrap();
        assert_eq!(cam.info(), info());
        for n in 0..2u64 {
            let f = cam.capture(settings()).await.unwrap();
            assert_eq!((f.sequence, f.data[0]), (n, n as u16));
        }
        assert!(matches!(cam.capture(settings()).await, Err(DeviceError::Timeout(m)) if m == "frame 2"));
        assert_eq!(cam.capture(settings()).await.unwrap().sequence, 3);
    }

    #[tokio::test]
    async fn an_open_failure_is_returned_and_a_dead_thread_is_an_error() {
        let err = ThreadedCamera::spawn("absent camera", || -> Result<Counting, DeviceError> {
            Err(DeviceError::Camera("/dev/video9: no such device".into()))
        })
        .unwrap_err();
        assert_eq!(err.to_string(), "camera failure: /dev/video9: no such device");
        // A camera whose capture panics: the caller gets an error, not a panic.
        struct Panics;
        impl BlockingCamera for Panics {
            fn info(&self) -> CameraInfo {
                info()
            }
            fn capture(&mut self, _: CaptureSettings) -> Result<Frame, DeviceError> {
                panic!("driver bug")
            }
        }
        let mut cam = ThreadedCamera::spawn("panicky camera", || Ok(Panics)).unwrap();
        let err = cam.capture(settings()).await.unwrap_err();
        assert_eq!(
            err.to_string(),
            "camera failure: panicky camera: the camera thread has ended"
        );
        let err = cam.capture(settings()).await.unwrap_err();
        assert!(matches!(err, DeviceError::Camera(_)));
    }
}
