//! FW102C emulator command parsing: arbitrary bytes.
#![no_main]
use campanile_firmware_link::firmware::{CountingOutput, Firmware};
use campanile_firmware_link::fw102c::device::WheelDevice;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let mut dev = WheelDevice::new(data.first().copied().unwrap_or(6));
    let mut out = CountingOutput::default();
    dev.receive(data, &mut out);
    assert!((1..=12).contains(&dev.position()));
});
