//! Triangle meshes of simple solids, for built-in scenes and tests.

use nalgebra::Vector3;

use super::mesh::Triangle;

/// The two triangles of the quad `a b c d` (counter-clockwise from the front).
pub fn quad(corners: [Vector3<f64>; 4], material: u32, surface: u32) -> Vec<Triangle> {
    let [a, b, c, d] = corners;
    [[a, b, c], [a, c, d]]
        .into_iter()
        .filter_map(|v| Triangle::new(v, material, surface))
        .collect()
}

/// The six faces of the axis-aligned box from `min` to `max`, with
/// material and surface per face in the order −x, +x, −y, +y, −z, +z, normals
/// pointing inward when `inward` (a room) and outward otherwise (a block).
pub fn cuboid(
    min: Vector3<f64>,
    max: Vector3<f64>,
    inward: bool,
    material: [u32; 6],
    surface: [u32; 6],
) -> Vec<Triangle> {
    let p = |x: bool, y: bool, z: bool| {
        Vector3::new(
            if x { max.x } else { min.x },
            if y { max.y } else { min.y },
            if z { max.z } else { min.z },
        )
    };
    // Outward-facing corner orders.
    let faces = [
        [
            p(false, false, false),
            p(false, false, true),
            p(false, true, true),
            p(false, true, false),
        ],
        [
            p(true, false, false),
            p(true, true, false),
            p(true, true, true),
            p(true, false, true),
        ],
        [
            p(false, false, false),
            p(true, false, false),
            p(true, false, true),
            p(false, false, true),
        ],
        [
            p(false, true, false),
            p(false, true, true),
            p(true, true, true),
            p(true, true, false),
        ],
        [
            p(false, false, false),
            p(false, true, false),
            p(true, true, false),
            p(true, false, false),
        ],
        [
            p(false, false, true),
            p(true, false, true),
            p(true, true, true),
            p(false, true, true),
        ],
    ];
    faces
        .into_iter()
        .enumerate()
        .flat_map(|(i, mut f)| {
            if inward {
                f.reverse();
            }
            quad(f, material[i], surface[i])
        })
        .collect()
}

/// A latitude-longitude sphere of `rings` × `segments` quads, outward normals.
pub fn sphere(
    center: Vector3<f64>,
    radius: f64,
    rings: usize,
    segments: usize,
    material: u32,
    surface: u32,
) -> Vec<Triangle> {
    let rings = rings.max(2);
    let segments = segments.max(3);
    let at = |i: usize, j: usize| {
        let theta = std::f64::consts::PI * i as f64 / rings as f64;
        let phi = std::f64::consts::TAU * j as f64 / segments as f64;
        center + Vector3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()) * radius
    };
    let mut out = Vec::with_capacity(rings * segments * 2);
    for i in 0..rings {
        for j in 0..segments {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            out.extend(Triangle::new([a, b, c], material, surface));
            out.extend(Triangle::new([a, c, d], material, surface));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cuboid_normals_point_the_requested_way() {
        let min = Vector3::zeros();
        let max = Vector3::new(1.0, 2.0, 3.0);
        let centre = (min + max) / 2.0;
        for inward in [false, true] {
            let tris = cuboid(min, max, inward, [0; 6], [0; 6]);
            assert_eq!(tris.len(), 12);
            let area: f64 = tris.iter().map(|t| t.area()).sum();
            assert!((area - 2.0 * (2.0 + 3.0 + 6.0)).abs() < 1e-12);
            for t in &tris {
                let out = (t.vertices[0] - centre).dot(&t.normal) > 0.0;
                assert_eq!(out, !inward);
            }
        }
    }

    #[test]
    fn sphere_area_converges() {
        let tris = sphere(Vector3::zeros(), 2.0, 64, 128, 0, 0);
        let area: f64 = tris.iter().map(|t| t.area()).sum();
        let exact = 4.0 * std::f64::consts::PI * 4.0;
        assert!((area / exact - 1.0).abs() < 0.002, "area {area} vs {exact}");
        assert!(
            tris.iter()
                .all(|t| t.vertices[0].dot(&t.normal) > 0.0 || t.vertices[1].dot(&t.normal) > 0.0)
        );
    }
}
