//! FLIR PTU reply-line parsing.
#![no_main]
use campanile_firmware_link::flir_ptu::{Reply, is_reply_terminator};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    for line in data.split(|&b| is_reply_terminator(b)) {
        let r = Reply::parse(line);
        let _ = r.integer();
        let _ = r.milli();
    }
});
