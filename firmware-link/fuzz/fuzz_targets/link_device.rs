//! campanile-link device side: arbitrary bytes and clock steps.
#![no_main]
use campanile_firmware_link::firmware::{CountingOutput, Firmware};
use campanile_firmware_link::link::device::{DeviceConfig, LinkDevice};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let cfg = DeviceConfig::default();
    let mut dev = LinkDevice::new(cfg);
    let mut out = CountingOutput::default();
    let mut now = 0u64;
    for chunk in data.chunks(13) {
        dev.receive(chunk, &mut out);
        now += u64::from(chunk[0]) * 7;
        dev.advance(now, &mut out);
        let s = dev.head_state();
        assert!(s.pan >= cfg.pan_range.0 && s.pan <= cfg.pan_range.1);
        assert!(s.tilt >= cfg.tilt_range.0 && s.tilt <= cfg.tilt_range.1);
        assert!(dev.filter_slot() < cfg.filter_slots);
    }
});
