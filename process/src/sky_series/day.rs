//! A day's products, recomputed from its per-scan products alone (never
//! from raw frames, which the station may have deleted): the scans in time
//! order, and the extinction β per channel against air mass (the Langley
//! method: `ln E = ln E₀ − β m`, §5.5.1) over the scans whose sun triplet
//! agreed.

use std::collections::BTreeMap;

use super::condition::{SkyCondition, day_conditions};
use super::scan::ScanProducts;
use crate::sun::{Extinction, fit_extinction};

/// The extinction fit of one day, per channel.
#[derive(Debug, Clone, PartialEq)]
pub struct DayExtinction {
    /// The day (the date part of the occurrence ids, `YYYY-MM-DD`).
    pub date: String,
    /// `(air mass, irradiance per channel)` of the scans fitted, W·m⁻².
    pub points: Vec<(f64, [f64; 3])>,
    /// Scans left out (clouds near the sun or no sun measured).
    pub left_out: usize,
    /// The fit per channel, or why there is none.
    pub fit: [Result<Extinction, String>; 3],
}

/// The scans of a session grouped by day, and each day's extinction.
#[derive(Debug, Clone, PartialEq)]
pub struct SkySeries {
    /// Every scan, in time order (then by id).
    pub scans: Vec<ScanProducts>,
    /// One entry per day, in date order.
    pub days: Vec<DayExtinction>,
    /// The sky condition of each scan, in the order of [`SkySeries::scans`].
    pub conditions: Vec<SkyCondition>,
}

/// The day of an occurrence: the date after its `@` (`sky@2026-08-28#3`),
/// else the UTC date of its time.
pub fn day_of(scan: &ScanProducts) -> String {
    scan.occurrence
        .split_once('@')
        .map(|(_, rest)| rest.split('#').next().unwrap_or(rest).to_owned())
        .filter(|d| !d.is_empty())
        .unwrap_or_else(|| scan.time_utc.date_naive().to_string())
}

impl SkySeries {
    /// The series of `scans` (any order).
    pub fn new(mut scans: Vec<ScanProducts>) -> SkySeries {
        scans.sort_by(|a, b| a.time_utc.cmp(&b.time_utc).then(a.occurrence.cmp(&b.occurrence)));
        let mut by_day: BTreeMap<String, Vec<&ScanProducts>> = BTreeMap::new();
        for s in &scans {
            by_day.entry(day_of(s)).or_default().push(s);
        }
        let days: Vec<DayExtinction> = by_day
            .iter()
            .map(|(date, day)| {
                let date = date.clone();
                let used: Vec<&ScanProducts> = day
                    .iter()
                    .copied()
                    .filter(|s| s.sun.is_some() && !s.quality.clouds_near_sun)
                    .collect();
                let points: Vec<(f64, [f64; 3])> = used
                    .iter()
                    .filter_map(|s| s.sun.as_ref().map(|m| (m.air_mass, m.irradiance_w_m2)))
                    .collect();
                let zeniths: Vec<(f64, [f64; 3])> = used
                    .iter()
                    .filter_map(|s| s.sun.as_ref().map(|m| (m.zenith_deg.to_radians(), m.irradiance_w_m2)))
                    .collect();
                let fit = [0, 1, 2].map(|c| {
                    fit_extinction(&zeniths.iter().map(|&(z, e)| (z, e[c])).collect::<Vec<_>>())
                        .map_err(|e| e.to_string())
                });
                DayExtinction {
                    date,
                    left_out: day.len() - used.len(),
                    points,
                    fit,
                }
            })
            .collect();
        // Each day's conditions, then in the scans' order.
        let mut by_occurrence: BTreeMap<&str, SkyCondition> = BTreeMap::new();
        for (ext, (_, day)) in days.iter().zip(&by_day) {
            for (s, c) in day.iter().zip(day_conditions(day, ext)) {
                by_occurrence.insert(s.occurrence.as_str(), c);
            }
        }
        let conditions = scans
            .iter()
            .map(|s| by_occurrence.remove(s.occurrence.as_str()).unwrap_or_default())
            .collect();
        SkySeries {
            scans,
            days,
            conditions,
        }
    }
}
