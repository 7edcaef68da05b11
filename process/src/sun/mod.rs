//! The sun: where it is (thesis §5.3.1), when it rises, culminates and
//! sets, how bright it is (§5.3.1) and how the atmosphere dims and reddens
//! it (§5.5.1).
//!
//! Positions come from NREL's Solar Position Algorithm (Reda & Andreas,
//! 2004; ±0.0003° for years −2000 to 6000). One instant at a time
//! ([`Ephemeris`], [`sun_position`]) and the rise, transit and set times use
//! the `solar-positioning` crate, which this module wraps in Campanile's
//! conventions and verifies against NREL's published test case and against
//! pvlib (see `BENCHMARKS.md`). Tables of instants ([`sun_positions`],
//! `campanile sun --csv`) use this crate's own SPA, vectorized (`spa`),
//! which the tests hold to the crate's results within 1e-11°.

mod disc;
mod events;
mod extinction;
mod position;
mod spa;
mod spa_terms;
mod table;

pub use disc::{SunDisc, SunDiscError, SunFrame, measure_sun};
pub use events::{SolarDay, solar_day};
pub(crate) use extinction::line_fit;
pub use extinction::{Extinction, ExtinctionError, MIN_AIR_MASS_SPAN, air_mass, fit_extinction};
pub use position::{Ephemeris, Observer, SunError, SunPosition, delta_t_estimate, sun_position};
pub use table::{SunAnswer, SunRequest, SunTableError, sun_positions, sun_table};

/// Mean angular radius of the solar disc at 1 AU, in radians (959.63″).
pub const SUN_ANGULAR_RADIUS_AT_1_AU_RAD: f64 = 959.63 / 3600.0 * std::f64::consts::PI / 180.0;

/// Solid angle of the solar disc, in steradians, at an Earth–Sun distance
/// of `r_au` astronomical units: `2π (1 − cos ρ)` with ρ the angular radius.
pub fn sun_solid_angle_sr(r_au: f64) -> f64 {
    let rho = SUN_ANGULAR_RADIUS_AT_1_AU_RAD / r_au;
    2.0 * std::f64::consts::PI * (1.0 - rho.cos())
}
