//! campanile-link: our own protocol for a DIY controller (for example a
//! microcontroller driving steppers, a filter servo and light dimmers).
//!
//! # Wire format
//!
//! Each frame is COBS-encoded ([`crate::cobs`]) and followed by one `0x00`
//! delimiter. Decoded, a frame is
//!
//! ```text
//! version:u8  seq:u16 LE  kind:u8  payload:0..=24 bytes  crc:u32 LE
//! ```
//!
//! The payload length is implicit (the frame's length); it is bounded by
//! [`frame::MAX_PAYLOAD`], so a receiver needs only fixed buffers of
//! [`frame::MAX_WIRE`] bytes. `kind` says what the payload is
//! ([`message`]): requests from the host (`0x01..=0x3F`), replies from the
//! device (`0x80..=0xBF`, carrying the request's `seq`) and unsolicited
//! events (`0xC0..=0xFF`, with the device's own event counter as `seq`).
//!
//! # Why CRC-32C
//!
//! The check is CRC-32C (Castagnoli, the iSCSI polynomial `0x1EDC6F41`) over
//! header and payload. Frames are at most 32 bytes, so a CRC-16 would cost
//! two bytes less per frame (about 6%), but a 16-bit check lets one
//! corrupted frame in 65,536 through. On a noisy field cable at a few
//! percent byte error rate, a session of 10⁴ commands sees ~10⁴ damaged
//! frames, so a 16-bit check would accept about one bad command per session:
//! a wrong move. With 32 bits that becomes ~2·10⁻⁶ per session, and CRC-32C
//! keeps Hamming distance 6 for frames of this length. On a microcontroller
//! the bitwise form costs ~256 shift/xor steps per frame and no table.
//!
//! # Exactly-once effect
//!
//! The host sends one request at a time and retries it, byte for byte
//! identical, with the same `seq`, until a reply with that `seq` arrives.
//! The device keeps its last [`device::REPLAY_SLOTS`] replies, keyed by
//! `seq` and the request's CRC; a request that matches one is answered from
//! the cache and has no further effect. Absolute moves are idempotent
//! anyway; relative moves are applied to the *target* (not the current
//! position), exactly once. The host starts its sequence at a seeded random
//! value so that a restarted host does not collide with cached replies.

pub mod device;
pub mod frame;
pub mod message;

#[cfg(feature = "std")]
pub mod host;
#[cfg(feature = "std")]
pub mod soak;
