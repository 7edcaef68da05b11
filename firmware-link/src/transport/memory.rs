//! An in-memory duplex byte stream for tests and simulations.

use tokio::io::DuplexStream;

/// Two connected ends; bytes written to one are read from the other. Each
/// direction buffers up to `capacity` bytes (writers wait beyond that, like
/// a UART with flow control).
pub fn duplex(capacity: usize) -> (DuplexStream, DuplexStream) {
    tokio::io::duplex(capacity.max(1))
}

#[cfg(test)]
mod tests {
    use super::*;
    use tokio::io::{AsyncReadExt, AsyncWriteExt};

    #[tokio::test]
    async fn carries_bytes_both_ways() {
        let (mut a, mut b) = duplex(8);
        a.write_all(b"ping").await.unwrap();
        let mut buf = [0u8; 4];
        b.read_exact(&mut buf).await.unwrap();
        assert_eq!(&buf, b"ping");
        b.write_all(b"pong").await.unwrap();
        a.read_exact(&mut buf).await.unwrap();
        assert_eq!(&buf, b"pong");
    }
}
