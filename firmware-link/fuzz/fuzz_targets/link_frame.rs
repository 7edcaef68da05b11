//! campanile-link host-side decoding: deframing, CRC, message payloads.
#![no_main]
use campanile_firmware_link::link::frame::Deframer;
use campanile_firmware_link::link::message::Message;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let mut d = Deframer::default();
    for &b in data {
        if let Some(Ok(frame)) = d.push(b) {
            if let Ok(m) = Message::decode(frame.kind, frame.payload()) {
                // Whatever decodes must re-encode to the same payload.
                let (k, p, n) = m.encode();
                assert_eq!(k, frame.kind);
                assert_eq!(&p[..n], frame.payload());
            }
        }
    }
    // Raw payload decoding for every kind byte.
    if let Some((&k, rest)) = data.split_first() {
        let _ = Message::decode(k, &rest[..rest.len().min(24)]);
    }
});
