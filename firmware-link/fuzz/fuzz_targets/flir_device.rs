//! FLIR PTU emulator command parsing: arbitrary bytes and clock steps.
#![no_main]
use campanile_firmware_link::firmware::{CountingOutput, Firmware};
use campanile_firmware_link::flir_ptu::device::{PtuConfig, PtuDevice};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let cfg = PtuConfig::default();
    let mut dev = PtuDevice::new(cfg);
    let mut out = CountingOutput::default();
    let mut now = 0u64;
    for chunk in data.chunks(11) {
        dev.receive(chunk, &mut out);
        now += u64::from(chunk[0]) * 13;
        dev.advance(now, &mut out);
        let (p, t) = dev.position();
        assert!(p >= cfg.pan_range.0 && p <= cfg.pan_range.1);
        assert!(t >= cfg.tilt_range.0 && t <= cfg.tilt_range.1);
    }
});
