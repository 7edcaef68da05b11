//! The Perez all-weather sky (thesis eq. 5.8; Perez, Seals and Michalsky,
//! "All-weather model for sky luminance distribution", Solar Energy 50(3),
//! 1993): eq. (5.9) with h = 1, whose five coefficients a–e follow from the
//! sun's zenith angle Z, the sky clearness ε and the sky brightness Δ
//! through the paper's table of eight clearness bins.
//!
//! The fit uses these skies as starting shapes, and its parameter ranges
//! are set to hold every one of them ([`table_extremes`]).

use super::seven_parameter::SkyModel;

/// Upper edges of the clearness bins 1–7 (bin 8 is ε ≥ 6.2).
pub const CLEARNESS_BIN_EDGES: [f64; 7] = [1.065, 1.230, 1.500, 1.950, 2.800, 4.500, 6.200];

/// The brightness range of the table's data, Δ ∈ [0.01, 0.6] (the limits
/// RADIANCE's gendaylit also applies).
pub const BRIGHTNESS_RANGE: (f64, f64) = (0.01, 0.6);

/// Perez et al. (1993), Table 1: for each bin, for each coefficient a–e,
/// (x₁, x₂, x₃, x₄) with `x = x₁ + x₂ Z + Δ (x₃ + x₄ Z)`; in bin 1, c and d
/// have their own forms (see [`PerezSky::coefficients`]).
const TABLE: [[[f64; 4]; 5]; 8] = [
    [
        [1.3525, -0.2576, -0.2690, -1.4366],
        [-0.7670, 0.0007, 1.2734, -0.1233],
        [2.8000, 0.6004, 1.2375, 1.0000],
        [1.8734, 0.6297, 0.9738, 0.2809],
        [0.0356, -0.1246, -0.5718, 0.9938],
    ],
    [
        [-1.2219, -0.7730, 1.4148, 1.1016],
        [-0.2054, 0.0367, -3.9128, 0.9156],
        [6.9750, 0.1774, 6.4477, -0.1239],
        [-1.5798, -0.5081, -1.7812, 0.1080],
        [0.2624, 0.0672, -0.2190, -0.4285],
    ],
    [
        [-1.1000, -0.2515, 0.8952, 0.0156],
        [0.2782, -0.1812, -4.5000, 1.1766],
        [24.7219, -13.0812, -37.7000, 34.8438],
        [-5.0000, 1.5218, 3.9229, -2.6204],
        [-0.0156, 0.1597, 0.4199, -0.5562],
    ],
    [
        [-0.5484, -0.6654, -0.2672, 0.7117],
        [0.7234, -0.6219, -5.6812, 2.6297],
        [33.3389, -18.3000, -62.2500, 52.0781],
        [-3.5000, 0.0016, 1.1477, 0.1062],
        [0.4659, -0.3296, -0.0876, -0.0329],
    ],
    [
        [-0.6000, -0.3566, -2.5000, 2.3250],
        [0.2937, 0.0496, -5.6812, 1.8415],
        [21.0000, -4.7656, -21.5906, 7.2492],
        [-3.5000, -0.1554, 1.4062, 0.3988],
        [0.0032, 0.0766, -0.0656, -0.1294],
    ],
    [
        [-1.0156, -0.3670, 1.0078, 1.4051],
        [0.2875, -0.5328, -3.8500, 3.3750],
        [14.0000, -0.9999, -7.1406, 7.5469],
        [-3.4000, -0.1078, -1.0750, 1.5702],
        [-0.0672, 0.4016, 0.3017, -0.4844],
    ],
    [
        [-1.0000, 0.0211, 0.5025, -0.5119],
        [-0.3000, 0.1922, 0.7023, -1.6317],
        [19.0000, -5.0000, 1.2438, -1.9094],
        [-4.0000, 0.0250, 0.3844, 0.2656],
        [1.0468, -0.3788, -2.4517, 1.4656],
    ],
    [
        [-1.0500, 0.0289, 0.4260, 0.3590],
        [-0.3250, 0.1156, 0.7781, 0.0025],
        [31.0625, -14.5000, -46.1148, 55.3750],
        [-7.2312, 0.4050, 13.3500, 0.6234],
        [1.5000, -0.6426, 1.8564, 0.5636],
    ],
];

/// A Perez all-weather sky's conditions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PerezSky {
    /// Sky clearness ε (1 overcast … above 6.2 clear).
    pub clearness: f64,
    /// Sky brightness Δ.
    pub brightness: f64,
    /// The sun's zenith angle Z, radians.
    pub sun_zenith: f64,
}

impl PerezSky {
    /// The clearness bin, 1 to 8.
    pub fn bin(&self) -> usize {
        1 + CLEARNESS_BIN_EDGES.iter().filter(|&&e| self.clearness >= e).count()
    }

    /// The brightness the table is evaluated at: Δ clamped to
    /// [`BRIGHTNESS_RANGE`], and to at least 0.2 in bins 2–5, where the
    /// paper's fits are unreliable below it (as gendaylit does).
    pub fn effective_brightness(&self) -> f64 {
        let d = self.brightness.clamp(BRIGHTNESS_RANGE.0, BRIGHTNESS_RANGE.1);
        if (2..=5).contains(&self.bin()) { d.max(0.2) } else { d }
    }

    /// The coefficients [a, b, c, d, e] of eq. (5.8).
    pub fn coefficients(&self) -> [f64; 5] {
        let x = &TABLE[self.bin() - 1];
        let z = self.sun_zenith;
        let delta = self.effective_brightness();
        let mut k = [0.0; 5];
        for (i, row) in x.iter().enumerate() {
            k[i] = row[0] + row[1] * z + delta * (row[2] + row[3] * z);
        }
        if self.bin() == 1 {
            k[2] = (delta * (x[2][0] + x[2][1] * z)).powf(x[2][2]).exp() - x[2][3];
            k[3] = -(delta * (x[3][0] + x[3][1] * z)).exp() + x[3][2] + delta * x[3][3];
        }
        k
    }

    /// The sky as eq. (5.9) with h = 1 and scale `lz`.
    pub fn as_seven_parameter(&self, lz: f64) -> SkyModel {
        let [a, b, c, d, e] = self.coefficients();
        SkyModel {
            lz,
            a,
            b,
            c,
            d,
            e,
            h: 1.0,
        }
    }
}

/// The smallest and largest value of each coefficient a–e over the whole
/// table: every bin, Z from 0 to 90° and Δ over [`BRIGHTNESS_RANGE`]
/// (sampled every 1° and 0.01; the coefficients are linear in Δ and Z or,
/// in bin 1, monotone in each, so the extremes lie on the grid's edges).
pub fn table_extremes() -> [(f64, f64); 5] {
    let mut out = [(f64::INFINITY, f64::NEG_INFINITY); 5];
    for bin in 0..8 {
        let clearness = if bin == 0 { 1.0 } else { CLEARNESS_BIN_EDGES[bin - 1] };
        for z in 0..=90 {
            for d in 1..=60 {
                let sky = PerezSky {
                    clearness,
                    brightness: f64::from(d) / 100.0,
                    sun_zenith: f64::from(z).to_radians(),
                };
                for (slot, k) in out.iter_mut().zip(sky.coefficients()) {
                    slot.0 = slot.0.min(k);
                    slot.1 = slot.1.max(k);
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bins_follow_the_papers_edges() {
        let bin = |clearness| {
            PerezSky {
                clearness,
                brightness: 0.2,
                sun_zenith: 0.5,
            }
            .bin()
        };
        assert_eq!(bin(1.0), 1);
        assert_eq!(bin(1.064), 1);
        assert_eq!(bin(1.065), 2);
        assert_eq!(bin(2.0), 5);
        assert_eq!(bin(6.19), 7);
        assert_eq!(bin(6.2), 8);
        assert_eq!(bin(12.0), 8);
    }

    #[test]
    fn coefficients_match_the_published_table_at_its_corners() {
        // Bin 8 at Z = 0, Δ = 0.1: x1 + Δ x3 for each coefficient.
        let k = PerezSky {
            clearness: 8.0,
            brightness: 0.1,
            sun_zenith: 0.0,
        }
        .coefficients();
        let want = [
            -1.05 + 0.1 * 0.426,
            -0.325 + 0.1 * 0.7781,
            31.0625 + 0.1 * -46.1148,
            -7.2312 + 0.1 * 13.35,
            1.5 + 0.1 * 1.8564,
        ];
        for (k, w) in k.iter().zip(want) {
            assert!((k - w).abs() < 1e-12, "{k} vs {w}");
        }
        // Bin 1's own forms: c = exp((Δ (c1 + c2 Z))^c3) − c4.
        let z = 0.7_f64;
        let k = PerezSky {
            clearness: 1.02,
            brightness: 0.3,
            sun_zenith: z,
        }
        .coefficients();
        let c = (0.3 * (2.8 + 0.6004 * z)).powf(1.2375).exp() - 1.0;
        let d = -(0.3 * (1.8734 + 0.6297 * z)).exp() + 0.9738 + 0.3 * 0.2809;
        assert!((k[2] - c).abs() < 1e-12 && (k[3] - d).abs() < 1e-12, "{k:?}");
        // Δ below 0.2 is raised to 0.2 in bins 2–5 only.
        let low = |clearness| PerezSky {
            clearness,
            brightness: 0.05,
            sun_zenith: z,
        };
        assert_eq!(low(1.6).effective_brightness(), 0.2);
        assert_eq!(low(5.0).effective_brightness(), 0.05);
    }

    #[test]
    fn the_tables_extremes_are_known() {
        // Recorded so that a change to the table shows: a from −2.10 (bin 3
        // ... ) to 1.35, c down to −4.01 and d up to 2.00 (skies whose
        // aureole term grows away from the sun).
        let x = table_extremes();
        let want = [
            (-2.100, 1.350),
            (-3.115, 0.326),
            (-4.011, 32.807),
            (-7.098, 2.003),
            (-0.424, 2.614),
        ];
        for (got, want) in x.iter().zip(want) {
            assert!(
                (got.0 - want.0).abs() < 2e-3 && (got.1 - want.1).abs() < 2e-3,
                "{got:?} vs {want:?}"
            );
        }
    }
}
