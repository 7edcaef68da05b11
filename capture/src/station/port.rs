//! Opening a device's port by its configured name: the real serial port
//! ([`SerialOpener`]), or anything a test supplies (an in-memory duplex
//! with an emulator on the far end, a pseudo-terminal).

use campanile_config::link::SerialLink;
use campanile_firmware_link::transport::serial;
use std::future::Future;
use std::io;
use tokio::io::{AsyncRead, AsyncWrite};

/// Opens the byte stream of a configured serial link.
pub trait PortOpener: Send + Sync {
    /// The stream a driver talks over.
    type Port: AsyncRead + AsyncWrite + Unpin + Send + 'static;

    /// Open `link` (its port at its baud rate), anew each time it is
    /// called: a device that dropped is reconnected through a fresh open.
    fn open(&self, link: &SerialLink) -> impl Future<Output = io::Result<Self::Port>> + Send;
}

/// Real serial ports (8N1, no flow control) through `serialport`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SerialOpener;

impl PortOpener for SerialOpener {
    type Port = serial::SerialPort;

    async fn open(&self, link: &SerialLink) -> io::Result<Self::Port> {
        serial::open(&link.port, link.baud).map_err(|e| {
            io::Error::new(
                e.kind(),
                format!("opening serial port {} at {} baud: {e}", link.port, link.baud),
            )
        })
    }
}
