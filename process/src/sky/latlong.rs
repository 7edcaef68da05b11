//! A fitted sky as an image: the upper hemisphere in latitude-longitude
//! form, azimuth 0° (north) at the left edge increasing to the right
//! (east at a quarter of the width), elevation 90° at the top row and 0° at
//! the bottom, pixel centres at half-integers.

use super::geometry::angle_between;
use super::seven_parameter::{SkyAngles, SkyModel};

/// The world direction at the centre of pixel `(x, y)` of a `width ×
/// height` map.
pub fn latlong_direction(x: usize, y: usize, width: usize, height: usize) -> [f64; 3] {
    let az = (x as f64 + 0.5) / width as f64 * std::f64::consts::TAU;
    let el = (1.0 - (y as f64 + 0.5) / height as f64) * std::f64::consts::FRAC_PI_2;
    [el.cos() * az.sin(), el.cos() * az.cos(), el.sin()]
}

/// Renders three channels' skies (sun toward unit vector `sun`) into an
/// interleaved RGB lat-long map of `width × width/4` pixels.
pub fn render_latlong(models: &[SkyModel; 3], sun: [f64; 3], width: usize) -> (usize, usize, Vec<f32>) {
    let width = width.max(4);
    let height = width / 4;
    let mut rgb = Vec::with_capacity(3 * width * height);
    for y in 0..height {
        for x in 0..width {
            let d = latlong_direction(x, y, width, height);
            let (xi, gamma) = (d[2].clamp(-1.0, 1.0).acos(), angle_between(d, sun));
            let at = SkyAngles::new(xi, gamma);
            rgb.extend(models.iter().map(|m| m.radiance_at(&at) as f32));
        }
    }
    (width, height, rgb)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_map_puts_the_zenith_on_top_east_at_a_quarter_and_the_aureole_at_the_sun() {
        let (w, h) = (360, 90);
        let top = latlong_direction(17, 0, w, h);
        assert!(top[2] > (89f64).to_radians().sin());
        let east = latlong_direction(89, h - 1, w, h);
        assert!(east[0] > 0.99 && east[2] < 0.01);
        let m = SkyModel {
            lz: 0.05,
            a: -1.0,
            b: -0.4,
            c: 12.0,
            d: -3.2,
            e: 0.5,
            h: 0.9,
        };
        // Sun due south (azimuth 180°) at 30° elevation: the brightest pixel is there.
        let sun = [0.0, -30f64.to_radians().cos(), 30f64.to_radians().sin()];
        let (w, h, rgb) = render_latlong(&[m, m, m], sun, 360);
        let brightest = (0..w * h)
            .max_by(|&a, &b| rgb[3 * a].total_cmp(&rgb[3 * b]))
            .expect("pixels");
        let (x, y) = (brightest % w, brightest / w);
        assert!(
            (x as f64 - 180.0).abs() <= 1.0 && ((h - 1 - y) as f64 - 30.0).abs() <= 1.0,
            "({x}, {y})"
        );
    }
}
