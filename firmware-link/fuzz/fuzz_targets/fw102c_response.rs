//! FW102C answer parsing.
#![no_main]
use campanile_firmware_link::fw102c::{PROMPT, Response};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    for answer in data.split(|&b| b == PROMPT) {
        let r = Response::parse(answer);
        let _ = r.integer();
    }
});
