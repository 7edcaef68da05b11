//! Real serial ports, through `serialport` (built without libudev) wrapped
//! by `tokio-serial` for async I/O.
//!
//! A pseudo-terminal pair ([`pty_pair`]) gives a real tty in-process: run an
//! emulator on one end and open the other by path with [`open`], exactly as
//! a real device would be opened. A pty rejects modem-line calls (DTR, CTS),
//! so [`open`] makes none, and it reports `BrokenPipe` once the far end
//! closes.

use tokio_serial::{SerialPortBuilderExt, SerialStream};

pub use tokio_serial::SerialStream as SerialPort;

/// Open the serial port at `path` (8N1, no flow control) at `baud`.
pub fn open(path: &str, baud: u32) -> std::io::Result<SerialStream> {
    tokio_serial::new(path, baud)
        .data_bits(tokio_serial::DataBits::Eight)
        .parity(tokio_serial::Parity::None)
        .stop_bits(tokio_serial::StopBits::One)
        .flow_control(tokio_serial::FlowControl::None)
        .open_native_async()
        .map_err(std::io::Error::from)
}

/// A pseudo-terminal pair: (controlling end, device end). The device end's
/// path is available via [`device_path`].
pub fn pty_pair() -> std::io::Result<(SerialStream, SerialStream)> {
    SerialStream::pair().map_err(std::io::Error::from)
}

/// The filesystem path of a port (for a pty: `/dev/pts/N`).
pub fn device_path(port: &SerialStream) -> Option<String> {
    use tokio_serial::SerialPort as _;
    port.name()
}

/// Names of the serial ports the system lists (through /sys, no libudev).
pub fn list() -> std::io::Result<Vec<String>> {
    Ok(tokio_serial::available_ports()
        .map_err(std::io::Error::from)?
        .into_iter()
        .map(|p| p.port_name)
        .collect())
}
