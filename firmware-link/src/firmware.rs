//! The shape shared by every device-side state machine.
//!
//! A device side is pure: it is fed the bytes that arrived and the current
//! time, and it answers with bytes to send and effects (what the firmware
//! would do to the hardware: start a move, select a filter, set a dimmer).
//! It needs no allocator and no async runtime, so the same code can run on a
//! microcontroller, inside `sim`, or inside a fuzzer.

/// Where a device side puts what it produces.
pub trait Output<E> {
    /// Queue `bytes` for transmission to the host.
    fn send(&mut self, bytes: &[u8]);
    /// Report an effect on the (emulated) hardware.
    fn effect(&mut self, effect: E);
}

/// A device-side protocol state machine.
pub trait Firmware {
    /// What the firmware does to its hardware.
    type Effect;

    /// Feed bytes received from the host. Never panics, whatever the bytes.
    fn receive(&mut self, bytes: &[u8], out: &mut impl Output<Self::Effect>);

    /// Let time pass: `now_ms` is milliseconds since power-on (monotonic).
    /// Motion advances, and unsolicited events may be sent.
    fn advance(&mut self, now_ms: u64, out: &mut impl Output<Self::Effect>);
}

/// An [`Output`] that discards bytes and counts effects; useful for fuzzing
/// and for firmware that only needs to run.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
pub struct CountingOutput {
    /// Bytes passed to [`Output::send`].
    pub bytes_sent: usize,
    /// Effects passed to [`Output::effect`].
    pub effects: usize,
}

impl<E> Output<E> for CountingOutput {
    fn send(&mut self, bytes: &[u8]) {
        self.bytes_sent += bytes.len();
    }
    fn effect(&mut self, _effect: E) {
        self.effects += 1;
    }
}

/// An [`Output`] that collects into vectors (std only).
#[cfg(feature = "std")]
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CollectingOutput<E> {
    /// Every byte sent, in order.
    pub bytes: Vec<u8>,
    /// Every effect, in order.
    pub effects: Vec<E>,
}

#[cfg(feature = "std")]
impl<E> Default for CollectingOutput<E> {
    fn default() -> Self {
        Self {
            bytes: Vec::new(),
            effects: Vec::new(),
        }
    }
}

#[cfg(feature = "std")]
impl<E> Output<E> for CollectingOutput<E> {
    fn send(&mut self, bytes: &[u8]) {
        self.bytes.extend_from_slice(bytes);
    }
    fn effect(&mut self, effect: E) {
        self.effects.push(effect);
    }
}
