//! Shot keys: the scheduler's stable, opaque names for shots, checked and
//! mapped to frame file names.
//!
//! A key (e.g. `morning@2026-08-28/s2/t5/f1`) must be non-empty, at most
//! [`MAX_KEY_BYTES`] long and free of control characters (so it fits on one
//! journal line). Its file name keeps ASCII letters, digits, `-`, `_` and
//! `.` and turns every other character into `_`, then appends the key's
//! CRC-32C in hex, so keys that differ only in replaced characters still
//! get different names: `morning@2026-08-28/s2/t5/f1` becomes
//! `morning_2026-08-28_s2_t5_f1-xxxxxxxx.png`. The mapping is fixed: the
//! same key gives the same name in every run.

use super::checksum::crc32c;
use super::error::StoreError;
use crate::device::FrameFormat;

/// Longest key accepted, in bytes.
pub const MAX_KEY_BYTES: usize = 200;

/// Longest readable part of a frame file name, in characters (the hash
/// keeps truncated names distinct).
const MAX_STEM_CHARS: usize = 96;

/// Check that `key` can be journaled and named as a file.
pub fn check_key(key: &str) -> Result<(), StoreError> {
    let invalid = |reason| {
        Err(StoreError::InvalidKey {
            key: key.to_string(),
            reason,
        })
    };
    if key.is_empty() {
        return invalid("it is empty");
    }
    if key.len() > MAX_KEY_BYTES {
        return invalid("it is longer than 200 bytes");
    }
    if key.contains(['\n', '\r']) {
        return invalid("it contains a line break (a key must be a single line)");
    }
    if key.chars().any(char::is_control) {
        return invalid("it contains a control character");
    }
    if key.trim() != key {
        return invalid("it starts or ends with white space");
    }
    Ok(())
}

/// The PNG frame file name for `key` (call [`check_key`] first).
pub fn frame_file_name(key: &str) -> String {
    frame_file_name_as(key, FrameFormat::Png)
}

/// The frame file name for `key` in `format` (`….jpg`, `….dng`).
pub fn frame_file_name_as(key: &str, format: FrameFormat) -> String {
    let mut stem: String = key
        .chars()
        .take(MAX_STEM_CHARS)
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.') {
                c
            } else {
                '_'
            }
        })
        .collect();
    // A leading dot would hide the file and look like one of our temp files.
    if stem.starts_with('.') {
        stem.replace_range(0..1, "_");
    }
    format!("{stem}-{:08x}.{}", crc32c(key.as_bytes()), format.extension())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_are_checked() {
        assert!(check_key("morning@2026-08-28/s2/t5/f1").is_ok());
        for bad in ["", "a\nb", "a\rb", "tab\there", " lead", &"x".repeat(201)] {
            let e = check_key(bad).unwrap_err();
            assert!(matches!(e, StoreError::InvalidKey { .. }), "{bad:?}: {e}");
        }
        let msg = check_key("a\nb").unwrap_err().to_string();
        assert!(msg.contains("line break"), "{msg}");
    }

    #[test]
    fn file_names_are_safe_stable_and_distinct() {
        let a = frame_file_name("morning@2026-08-28/s2/t5/f1");
        assert!(a.starts_with("morning_2026-08-28_s2_t5_f1-"), "{a}");
        assert!(a.ends_with(".png"));
        assert_eq!(a, frame_file_name("morning@2026-08-28/s2/t5/f1"));
        // Keys that differ only in replaced characters get different names.
        assert_ne!(frame_file_name("a/b"), frame_file_name("a@b"));
        assert_ne!(frame_file_name("a/b"), frame_file_name("a#b"));
        let hidden = frame_file_name("../x");
        assert_eq!(hidden, format!("_._x-{:08x}.png", crc32c(b"../x")));
        assert!(!hidden.contains('/'));
        let long = frame_file_name(&"é".repeat(100));
        assert!(long.len() < 120, "{long}");
        assert!(long.chars().all(|c| c.is_ascii_alphanumeric() || "-_.".contains(c)));
    }
}
