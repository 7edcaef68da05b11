//! Pelco-D frame decoding and command recognition.
#![no_main]
use campanile_firmware_link::pelco_d::{Command, Deframer};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let mut d = Deframer::default();
    for &b in data {
        if let Some(Ok(f)) = d.push(b) {
            if let Some(c) = Command::from_frame(&f) {
                assert_eq!(Command::from_frame(&c.frame(f.address)), Some(c));
            }
        }
    }
});
