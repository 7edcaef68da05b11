//! Proptest strategies for field types that proptest cannot derive.

use std::path::PathBuf;

use chrono::{NaiveDate, NaiveTime};
use proptest::prelude::*;

pub fn path() -> impl Strategy<Value = PathBuf> {
    "[a-zA-Z0-9_./ -]{1,24}".prop_map(PathBuf::from)
}

pub fn opt_path() -> impl Strategy<Value = Option<PathBuf>> {
    proptest::option::of(path())
}

pub fn time() -> impl Strategy<Value = NaiveTime> {
    (0u32..24, 0u32..60, 0u32..60, 0u32..1000)
        .prop_map(|(h, m, s, ms)| NaiveTime::from_hms_milli_opt(h, m, s, ms).expect("valid time"))
}

pub fn date() -> impl Strategy<Value = NaiveDate> {
    (1900i32..2200, 1u32..=12, 1u32..=28).prop_map(|(y, m, d)| NaiveDate::from_ymd_opt(y, m, d).expect("valid date"))
}

/// Short lists: nested default-size lists would make plans of millions of elements.
pub fn small_vec<T: Arbitrary>() -> impl Strategy<Value = Vec<T>> {
    proptest::collection::vec(any::<T>(), 0..4)
}

pub fn albedo() -> impl Strategy<Value = Option<(f64, f64, f64)>> {
    proptest::option::of((0.0..=1.0f64, 0.0..=1.0f64, 0.0..=1.0f64))
}

/// A head's place, metres, in the range a scene file uses.
pub fn position() -> impl Strategy<Value = Option<(f64, f64, f64)>> {
    proptest::option::of((-1e3..=1e3f64, -1e3..=1e3f64, -1e2..=1e2f64))
}
