//! Enttec widget emulator: arbitrary bytes.
#![no_main]
use campanile_firmware_link::enttec::device::DmxDevice;
use campanile_firmware_link::firmware::{CountingOutput, Firmware};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let mut dev = DmxDevice::new(12_345_678);
    let mut out = CountingOutput::default();
    dev.receive(data, &mut out);
    dev.advance(1, &mut out);
});
