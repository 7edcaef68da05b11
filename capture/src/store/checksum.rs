//! The frame checksum: CRC-32C (Castagnoli, `crc::CRC_32_ISCSI`) of a
//! file's bytes.

use crc::{CRC_32_ISCSI, Crc, Table};

/// Slice-by-16 tables: frames are megabytes, and `resume` and `verify`
/// checksum every one.
const CASTAGNOLI: Crc<u32, Table<16>> = Crc::<u32, Table<16>>::new(&CRC_32_ISCSI);

/// CRC-32C of `bytes`.
pub fn crc32c(bytes: &[u8]) -> u32 {
    CASTAGNOLI.checksum(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crc32c_check_value() {
        // The catalogue's check value: CRC-32C of "123456789".
        assert_eq!(crc32c(b"123456789"), 0xe306_9283);
    }
}
