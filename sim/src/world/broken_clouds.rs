//! A broken-cloud day (issue 29's ground truth for the sky-condition
//! index): cloud patches on a flat layer that drift with the wind, so the
//! cloud changes from scan to scan and across the dome. Where a patch
//! covers a direction, the sky there is the thesis's §5.6.3 blend,
//! `(1 − o) clear + o overcast`, with `o` the patch's opacity in that
//! direction (1 inside, a smooth fall to 0 over its soft edge) and the
//! overcast sky the CIE standard overcast (type 1); the solar disc is
//! dimmed by `1 − o` at the sun. The uniform blend of
//! [`campanile_process::sky::Daylight::with_clouds`] is the special case
//! of one patch over the whole sky.
//!
//! The layer is at unit height; a direction `d` meets it at `(dx/dz,
//! dy/dz)`. Patches are discs of radius 0.3–1.2 layer heights, laid out
//! along the wind in stretches of one hour of drift, each stretch with its
//! own cover (a Poisson field of discs: cover `1 − exp(−λπr²)`), drawn from
//! the seed: clear spells, scattered and broken cloud, near-overcast.
//!
//! The truth per scan ([`CloudTruth`]) is what the index estimates: the
//! cloud fraction of each of the sky series' regions (mean opacity over
//! an even grid), whether the sun is covered, and the cloud fraction of
//! the sun's neighbourhood.

use campanile_process::render::sky::{Sky, SolarDisc};
use campanile_process::sky::{CieSky, CieSkyType, Daylight, SkyModel, angle_between};
use campanile_process::sky_series::{REGION_COUNT, region_grid, sun_neighbourhood_grid};
use chrono::{DateTime, Utc};
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};

/// A region, or the sun's neighbourhood, is cloudy in the truth when
/// clouds cover at least this fraction of it (a quarter: at the example's
/// cloud brightness, red twice the clear sky's, a quarter's cover departs
/// from clear by about the index's threshold).
pub const TRUTH_CLOUDY_FRACTION: f64 = 0.25;
/// The sun counts as covered when the opacity at its centre is at least this.
pub const SUN_COVERED_OPACITY: f64 = 0.5;
/// Width of a patch's soft edge, layer heights.
pub const EDGE_WIDTH: f64 = 0.15;
/// Cover levels a one-hour stretch of the layer is drawn from.
pub const COVER_LEVELS: [f64; 5] = [0.0, 0.15, 0.4, 0.7, 0.95];
/// Half-width of the layer across the wind, layer heights (tan 80° ≈ 5.7).
const HALF_WIDTH: f64 = 8.0;

/// One cloud patch: a disc on the layer, in the layer's own frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CloudPatch {
    /// Centre along the wind and across it, layer heights.
    pub centre: [f64; 2],
    /// Radius, layer heights.
    pub radius: f64,
}

/// A drifting layer of broken cloud (module doc).
#[derive(Debug, Clone, PartialEq)]
pub struct BrokenClouds {
    /// When the layer's frame coincides with the ground's.
    pub start: DateTime<Utc>,
    /// Wind speed, layer heights per hour.
    pub speed_per_hour: f64,
    /// Direction the wind blows toward, radians from north through east.
    pub toward_rad: f64,
    /// The overcast sky's zenith radiance per channel with the sun at the
    /// zenith, W·m⁻²·sr⁻¹; scaled as `√cos Zs` like the clear sky's.
    pub overcast_zenith: [f64; 3],
    /// The cover drawn for each hour's stretch, in order from `start`.
    pub hourly_cover: Vec<f64>,
    /// The patches, sorted by their centre along the wind (what
    /// [`BrokenClouds::opacity`] searches).
    pub patches: Vec<CloudPatch>,
    /// The largest patch radius, layer heights.
    pub max_radius: f64,
}

impl BrokenClouds {
    /// A seeded layer for `hours` hours from `start`, with grey-white
    /// clouds (red about twice the clear sky's zenith, blue a little below).
    pub fn seeded(seed: u64, start: DateTime<Utc>, hours: usize) -> BrokenClouds {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let speed_per_hour = 4.0;
        let toward_rad = rng.random_range(0.0..std::f64::consts::TAU);
        // Stretches cover the sky's view (±HALF_WIDTH along the wind) before and after.
        let stretch = speed_per_hour;
        let before = (HALF_WIDTH / stretch).ceil() as usize;
        let count = hours + 2 * before + 1;
        let hourly_cover: Vec<f64> = (0..count)
            .map(|_| COVER_LEVELS[rng.random_range(0..COVER_LEVELS.len())])
            .collect();
        let mut patches = Vec::new();
        for (k, &cover) in hourly_cover.iter().enumerate() {
            if cover <= 0.0 {
                continue;
            }
            // Radii uniform in 0.3–1.2: mean π r² = π (0.3² + 0.3·1.2 + 1.2²)/3.
            let mean_area = std::f64::consts::PI * (0.09 + 0.36 + 1.44) / 3.0;
            let area = stretch * 2.0 * HALF_WIDTH;
            let n = (-(1.0 - cover).ln() * area / mean_area).round() as usize;
            // The layer's frame: x along the wind; stretch k starts at (k − before) hours of drift upwind.
            let x0 = -(k as f64 - before as f64 + 1.0) * stretch;
            for _ in 0..n {
                patches.push(CloudPatch {
                    centre: [
                        x0 + rng.random_range(0.0..stretch),
                        rng.random_range(-HALF_WIDTH..HALF_WIDTH),
                    ],
                    radius: rng.random_range(0.3..1.2),
                });
            }
        }
        patches.sort_by(|a, b| a.centre[0].total_cmp(&b.centre[0]));
        BrokenClouds {
            start,
            speed_per_hour,
            toward_rad,
            overcast_zenith: [6.0, 6.5, 7.0],
            hourly_cover,
            max_radius: patches.iter().map(|p| p.radius).fold(0.0, f64::max),
            patches,
        }
    }

    /// The cloud's opacity (0–1) in unit direction `d` at `time`; 0 at and below the horizon.
    pub fn opacity(&self, d: [f64; 3], time: DateTime<Utc>) -> f64 {
        if d[2] <= 1e-3 {
            return 0.0;
        }
        let (px, py) = (d[0] / d[2], d[1] / d[2]);
        // Ground frame to the layer's: along and across the wind, minus the drift.
        let (s, c) = self.toward_rad.sin_cos();
        let hours = (time - self.start).num_milliseconds() as f64 / 3.6e6;
        let along = px * s + py * c - self.speed_per_hour * hours;
        let across = -px * c + py * s;
        let mut o: f64 = 0.0;
        let window = self.max_radius + EDGE_WIDTH;
        let from = self.patches.partition_point(|p| p.centre[0] < along - window);
        for p in self.patches[from..]
            .iter()
            .take_while(|p| p.centre[0] <= along + window)
        {
            let (dx, dy) = (along - p.centre[0], across - p.centre[1]);
            let reach = p.radius + EDGE_WIDTH;
            if dx.abs() > reach || dy.abs() > reach {
                continue;
            }
            let r = (dx * dx + dy * dy).sqrt();
            let t = ((p.radius + EDGE_WIDTH - r) / EDGE_WIDTH).clamp(0.0, 1.0);
            o = o.max(t * t * (3.0 - 2.0 * t));
            if o >= 1.0 {
                break;
            }
        }
        o
    }

    /// The overcast sky per channel for the sun at unit vector `sun`.
    pub fn overcast(&self, sun: [f64; 3]) -> [SkyModel; 3] {
        let kind = CieSkyType::new(1).unwrap_or_else(|| unreachable!("CIE type 1 exists"));
        let zs = sun[2].clamp(-1.0, 1.0).acos().min(std::f64::consts::FRAC_PI_2);
        let scale = sun[2].max(0.0).sqrt();
        self.overcast_zenith
            .map(|lz| CieSky::new(kind, lz * scale, zs).as_seven_parameter())
    }

    /// The sky at `time` over the clear `daylight`.
    pub fn sky(&self, daylight: Daylight, time: DateTime<Utc>) -> BrokenCloudSky<'_> {
        let sun_opacity = self.opacity(daylight.sun_direction, time);
        BrokenCloudSky {
            overcast: self.overcast(daylight.sun_direction),
            clear: daylight,
            clouds: self,
            time,
            sun_opacity,
        }
    }

    /// The truth at `time` with the sun at unit vector `sun` (module doc).
    pub fn truth(&self, time: DateTime<Utc>, sun: [f64; 3]) -> CloudTruth {
        let mean = |dirs: &[[f64; 3]]| {
            (!dirs.is_empty()).then(|| dirs.iter().map(|&d| self.opacity(d, time)).sum::<f64>() / dirs.len() as f64)
        };
        let region_fraction: Vec<Option<f64>> = (0..REGION_COUNT).map(|r| mean(&region_grid(r, sun, 12))).collect();
        let near_sun_fraction = mean(&sun_neighbourhood_grid(sun, 12)).unwrap_or(0.0);
        let weights: Vec<f64> = (0..REGION_COUNT)
            .map(|r| campanile_process::sky_series::region_solid_angle(r) * region_grid(r, sun, 12).len() as f64)
            .collect();
        let total: f64 = weights.iter().sum();
        let cover = region_fraction
            .iter()
            .zip(&weights)
            .map(|(f, w)| f.unwrap_or(0.0) * w)
            .sum::<f64>()
            / total.max(f64::MIN_POSITIVE);
        CloudTruth {
            region_fraction,
            cover,
            sun_opacity: self.opacity(sun, time),
            near_sun_fraction,
        }
    }
}

/// The truth of one moment (module doc).
#[derive(Debug, Clone, PartialEq)]
pub struct CloudTruth {
    /// Cloud fraction (mean opacity) of each region (`None`: the region lies in the sun's neighbourhood).
    pub region_fraction: Vec<Option<f64>>,
    /// The solid-angle-weighted cloud fraction of the regions.
    pub cover: f64,
    /// Opacity at the sun's centre.
    pub sun_opacity: f64,
    /// Cloud fraction of the sun's neighbourhood (3°–15°).
    pub near_sun_fraction: f64,
}

impl CloudTruth {
    /// Whether region `r` is cloudy in the truth ([`TRUTH_CLOUDY_FRACTION`]).
    pub fn region_cloudy(&self, r: usize) -> Option<bool> {
        self.region_fraction
            .get(r)
            .copied()
            .flatten()
            .map(|f| f >= TRUTH_CLOUDY_FRACTION)
    }

    /// Whether clouds are in the sun's neighbourhood in the truth.
    pub fn clouds_near_sun(&self) -> bool {
        self.near_sun_fraction >= TRUTH_CLOUDY_FRACTION
    }

    /// Whether the sun is covered ([`SUN_COVERED_OPACITY`]).
    pub fn sun_covered(&self) -> bool {
        self.sun_opacity >= SUN_COVERED_OPACITY
    }
}

/// Counts of a yes/no detection against the truth.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Tally {
    /// Detected and true.
    pub hits: usize,
    /// True but not detected.
    pub misses: usize,
    /// Detected but not true.
    pub false_alarms: usize,
    /// Neither.
    pub correct_rejections: usize,
}

impl Tally {
    fn add(&mut self, predicted: bool, truth: bool) {
        match (predicted, truth) {
            (true, true) => self.hits += 1,
            (false, true) => self.misses += 1,
            (true, false) => self.false_alarms += 1,
            (false, false) => self.correct_rejections += 1,
        }
    }

    /// Hits over the true cases (1 when there were none).
    pub fn hit_rate(&self) -> f64 {
        let t = self.hits + self.misses;
        if t == 0 { 1.0 } else { self.hits as f64 / t as f64 }
    }

    /// False alarms over the false cases (0 when there were none).
    pub fn false_alarm_rate(&self) -> f64 {
        let f = self.false_alarms + self.correct_rejections;
        if f == 0 {
            0.0
        } else {
            self.false_alarms as f64 / f as f64
        }
    }

    /// Agreements over all cases.
    pub fn accuracy(&self) -> f64 {
        let n = self.hits + self.misses + self.false_alarms + self.correct_rejections;
        if n == 0 {
            1.0
        } else {
            (self.hits + self.correct_rejections) as f64 / n as f64
        }
    }
}

/// A sky series' conditions scored against the layer's truth.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Detection {
    /// Scans in the series.
    pub scans: usize,
    /// Scans with a cloud cover (the others could not be computed).
    pub scored: usize,
    /// Regions: cloudy predicted vs true ([`TRUTH_CLOUDY_FRACTION`]).
    pub regions: Tally,
    /// The sun's neighbourhood: `clouds_near_sun_region` vs the truth.
    pub near_sun: Tally,
    /// Mean |predicted − true| cloud cover over the scored scans.
    pub cover_mean_abs_error: f64,
    /// Scored scans whose condition word is the truth's (the true cover in oktas).
    pub condition_agreements: usize,
    /// Per scored scan: (occurrence, predicted cover, true cover, predicted word, true word).
    pub rows: Vec<(String, f64, f64, String, String)>,
    /// Per measured region of every scored scan: (true cloud fraction, the index's departure from clear).
    pub departures: Vec<(f64, f64)>,
}

impl BrokenClouds {
    /// Scores `series`' conditions against this layer's truth at each scan's time and sun.
    pub fn score(&self, series: &campanile_process::sky_series::SkySeries) -> Detection {
        use campanile_process::sky_series::Condition;
        let mut out = Detection {
            scans: series.scans.len(),
            ..Detection::default()
        };
        let mut abs_error = 0.0;
        for (scan, cond) in series.scans.iter().zip(&series.conditions) {
            let (Some(cover), Some(word)) = (cond.cloud_cover, cond.condition) else {
                continue;
            };
            let sun =
                campanile_process::sky::direction(scan.sun_zenith_deg.to_radians(), scan.sun_azimuth_deg.to_radians());
            let truth = self.truth(scan.time_utc, sun);
            out.scored += 1;
            for r in 0..REGION_COUNT {
                if let (Some(p), Some(t)) = (cond.cloudy_regions.get(r).copied().flatten(), truth.region_cloudy(r)) {
                    out.regions.add(p, t);
                }
                if let (Some(d), Some(f)) = (
                    cond.departures.get(r).copied().flatten(),
                    truth.region_fraction.get(r).copied().flatten(),
                ) {
                    out.departures.push((f, d));
                }
            }
            if let Some(p) = cond.clouds_near_sun_region {
                out.near_sun.add(p, truth.clouds_near_sun());
            }
            abs_error += (cover - truth.cover).abs();
            let true_word = Condition::of_cover(truth.cover);
            out.condition_agreements += usize::from(true_word == word);
            out.rows.push((
                scan.occurrence.clone(),
                cover,
                truth.cover,
                word.as_str().to_owned(),
                true_word.as_str().to_owned(),
            ));
        }
        out.cover_mean_abs_error = abs_error / out.scored.max(1) as f64;
        out
    }
}

/// The clear daylight of one moment under a broken-cloud layer.
#[derive(Debug, Clone)]
pub struct BrokenCloudSky<'a> {
    /// The clear sun and sky.
    pub clear: Daylight,
    /// The overcast sky per channel.
    pub overcast: [SkyModel; 3],
    /// The layer.
    pub clouds: &'a BrokenClouds,
    /// The moment.
    pub time: DateTime<Utc>,
    /// The opacity at the sun's centre.
    pub sun_opacity: f64,
}

impl Sky for BrokenCloudSky<'_> {
    fn radiance(&self, d: &Vector3<f64>) -> [f64; 3] {
        let v = [d.x, d.y, d.z];
        let clear = self.clear.sky_radiance(v);
        if v[2] <= 0.0 {
            return clear;
        }
        let o = self.clouds.opacity(v, self.time);
        if o <= 0.0 {
            return clear;
        }
        let xi = v[2].min(1.0).acos();
        let g = angle_between(v, self.clear.sun_direction);
        [0, 1, 2].map(|c| (1.0 - o) * clear[c] + o * self.overcast[c].radiance(xi, g))
    }

    fn sun(&self) -> Option<SolarDisc> {
        let disc = self.clear.sun()?;
        let k = 1.0 - self.sun_opacity;
        (k > 0.0).then(|| SolarDisc {
            radiance: disc.radiance.map(|l| l * k),
            ..disc
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use campanile_process::sky::{Atmosphere, direction};

    fn start() -> DateTime<Utc> {
        "2026-08-28T06:00:00Z".parse().unwrap()
    }

    fn later_by(minutes: i32) -> DateTime<Utc> {
        start() + chrono::TimeDelta::minutes(i64::from(minutes) * 3)
    }

    #[test]
    fn the_layer_is_seeded_drifts_and_blends_the_overcast_sky() {
        let a = BrokenClouds::seeded(7, start(), 12);
        assert_eq!(a, BrokenClouds::seeded(7, start(), 12));
        assert_ne!(a.patches, BrokenClouds::seeded(8, start(), 12).patches);
        // Inside a patch (in the layer frame at the start) the opacity is 1;
        // an hour later the wind has moved it 4 layer heights on.
        let p = a.patches[a.patches.len() / 2];
        let (s, c) = a.toward_rad.sin_cos();
        let ground = |along: f64, across: f64| {
            let (x, y) = (along * s - across * c, along * c + across * s);
            let n = (x * x + y * y + 1.0).sqrt();
            [x / n, y / n, 1.0 / n]
        };
        assert!((a.opacity(ground(p.centre[0], p.centre[1]), start()) - 1.0).abs() < 1e-12);
        let later = start() + chrono::TimeDelta::hours(1);
        let moved = ground(p.centre[0] + a.speed_per_hour, p.centre[1]);
        assert!((a.opacity(moved, later) - 1.0).abs() < 1e-12);
        assert_eq!(a.opacity([0.0, 0.0, -1.0], start()), 0.0);
        // The search along the wind finds what a look at every patch finds.
        let every = BrokenClouds {
            max_radius: 1e9,
            ..a.clone()
        };
        for k in 0..200 {
            let d = direction(f64::from(k) * 0.0041, f64::from(k) * 0.37);
            assert_eq!(a.opacity(d, later_by(k)), every.opacity(d, later_by(k)));
        }
        // The sky: clear where the opacity is 0, the overcast sky where it is 1.
        let sun = direction(40f64.to_radians(), 2.0);
        let day = Daylight::clear(sun, &Atmosphere::clear());
        let sky = a.sky(day, later);
        let inside = Vector3::from(moved);
        let overcast = a.overcast(sun);
        let xi = moved[2].acos();
        let g = angle_between(moved, sun);
        let l = sky.radiance(&inside);
        for ch in 0..3 {
            assert!((l[ch] / overcast[ch].radiance(xi, g) - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn the_truth_counts_cover_by_region() {
        let clouds = BrokenClouds {
            start: start(),
            speed_per_hour: 0.0,
            toward_rad: 0.0,
            overcast_zenith: [6.0; 3],
            hourly_cover: vec![1.0],
            // One huge patch over the whole layer: everything cloudy.
            patches: vec![CloudPatch {
                centre: [0.0, 0.0],
                radius: 100.0,
            }],
            max_radius: 100.0,
        };
        let sun = direction(30f64.to_radians(), 1.0);
        let t = clouds.truth(start(), sun);
        assert!((t.cover - 1.0).abs() < 1e-12);
        assert!(t.sun_covered() && t.clouds_near_sun());
        assert!((0..REGION_COUNT).all(|r| t.region_cloudy(r) == Some(true)));
        let none = BrokenClouds {
            patches: vec![],
            ..clouds
        };
        let t = none.truth(start(), sun);
        assert_eq!(t.cover, 0.0);
        assert!(!t.sun_covered() && !t.clouds_near_sun());
        // A seeded day's stretches give every kind of hour.
        let day = BrokenClouds::seeded(3, start(), 12);
        assert!(day.hourly_cover.iter().all(|c| COVER_LEVELS.contains(c)));
    }
}
