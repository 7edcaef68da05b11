//! Pelco-D head emulator: arbitrary bytes and clock steps.
#![no_main]
use campanile_firmware_link::firmware::{CountingOutput, Firmware};
use campanile_firmware_link::pelco_d::device::{PelcoConfig, PelcoDevice};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let cfg = PelcoConfig::default();
    let mut dev = PelcoDevice::new(cfg);
    let mut out = CountingOutput::default();
    let mut now = 0u64;
    for chunk in data.chunks(9) {
        dev.receive(chunk, &mut out);
        now += u64::from(chunk[0]) * 11;
        dev.advance(now, &mut out);
        let (p, t) = dev.position();
        assert!(p >= cfg.pan_range.0 && p <= cfg.pan_range.1);
        assert!(t >= cfg.tilt_range.0 && t <= cfg.tilt_range.1);
    }
});
