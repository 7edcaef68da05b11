//! Enttec DMX USB Pro message deframing.
#![no_main]
use campanile_firmware_link::enttec::{Deframer, encode};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let mut d = Deframer::default();
    for &b in data {
        if let Some(Ok(label)) = d.push(b) {
            let mut out = [0u8; 605];
            let n = encode(label, d.data(), &mut out).expect("a decoded message re-encodes");
            assert_eq!(n, d.data().len() + 5);
        }
    }
});
