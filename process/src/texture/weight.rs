//! A photograph's weight at a texel (thesis §3.4): "the weight becomes
//! smaller when the triangle is viewed from a grazing angle or its projected
//! area is close to the boundaries of the photograph to obtain both good
//! resolution and smooth transitions". Three factors, multiplied:
//!
//! - **viewing angle**: `cos θ` between the face's normal and the direction
//!   to the camera; views more grazing than [`WeightSettings::min_cosine`]
//!   get no weight (their texels smear along the face);
//! - **resolution**: with `a` the texel's footprint in the photograph in
//!   square pixels, `a / (1 + a)`: about `a` where a pixel covers several
//!   texels (the photograph cannot resolve the texel), near 1 where the
//!   texel covers many pixels;
//! - **border**: rising linearly from 0 at the photograph's edge to 1 at
//!   [`WeightSettings::border_ramp`] of its shorter side, so that where one
//!   photograph's edge crosses a surface, its contribution fades out instead
//!   of ending in a step.

/// The knobs of the weight.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WeightSettings {
    /// Smallest `cos θ` that counts (0.1: 84°).
    pub min_cosine: f64,
    /// Width of the border ramp, as a fraction of the shorter image side.
    pub border_ramp: f64,
}

impl Default for WeightSettings {
    fn default() -> Self {
        WeightSettings {
            min_cosine: 0.1,
            border_ramp: 0.08,
        }
    }
}

/// The factors of one photograph's weight at one texel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViewWeight {
    /// Viewing-angle factor.
    pub angle: f64,
    /// Resolution factor.
    pub resolution: f64,
    /// Border factor.
    pub border: f64,
}

impl ViewWeight {
    /// The product of the factors.
    pub fn total(&self) -> f64 {
        self.angle * self.resolution * self.border
    }
}

/// The weight of a view with `cosine` = cos θ, a texel footprint of
/// `footprint_px2` square pixels, at image point `(u, v)` of a
/// `width × height` photograph.
pub fn view_weight(
    cosine: f64,
    footprint_px2: f64,
    (u, v): (f64, f64),
    (width, height): (usize, usize),
    settings: &WeightSettings,
) -> ViewWeight {
    let angle = if cosine.is_finite() && cosine >= settings.min_cosine {
        cosine
    } else {
        0.0
    };
    let resolution = if footprint_px2.is_finite() && footprint_px2 > 0.0 {
        footprint_px2 / (1.0 + footprint_px2)
    } else {
        0.0
    };
    let ramp = settings.border_ramp * width.min(height) as f64;
    let edge = u.min(v).min(width as f64 - u).min(height as f64 - v);
    let border = if ramp > 0.0 {
        (edge / ramp).clamp(0.0, 1.0)
    } else if edge >= 0.0 {
        1.0
    } else {
        0.0
    };
    ViewWeight {
        angle,
        resolution,
        border,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_factor_falls_where_the_thesis_says() {
        let s = WeightSettings::default();
        let size = (1000, 500);
        // Head-on, well resolved, in the middle: near 1 (a = 9 → 0.9).
        let w = view_weight(1.0, 9.0, (500.0, 250.0), size, &s);
        assert!((w.total() - 0.9).abs() < 1e-12);
        // Grazing at 80° (cos 0.174) counts at 0.174; at 85° (0.087) not at all.
        let w80 = view_weight(80f64.to_radians().cos(), 9.0, (500.0, 250.0), size, &s);
        assert!((w80.angle - 0.17365).abs() < 1e-4);
        assert_eq!(
            view_weight(85f64.to_radians().cos(), 9.0, (500.0, 250.0), size, &s).total(),
            0.0
        );
        // A pixel over 4 texels (a = 1/4): 0.2.
        assert!((view_weight(1.0, 0.25, (500.0, 250.0), size, &s).resolution - 0.2).abs() < 1e-12);
        // The ramp is 40 px (8% of 500): 10 px from the left edge is 1/4, outside is 0.
        assert!((view_weight(1.0, 9.0, (10.0, 250.0), size, &s).border - 0.25).abs() < 1e-12);
        assert_eq!(view_weight(1.0, 9.0, (-1.0, 250.0), size, &s).border, 0.0);
        assert_eq!(view_weight(1.0, 9.0, (500.0, 480.0), size, &s).border, 0.5);
    }
}
