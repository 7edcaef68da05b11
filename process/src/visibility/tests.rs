//! Analytic cases: panels in front of a wall, seen from one pinhole.

use geo::Area;
use nalgebra::Vector3;

use super::*;
use crate::render::shapes::quad;

/// A square panel facing −y (toward a camera at the origin looking +y),
/// `x0..x1 × z0..z1` at depth `y`.
fn panel(x0: f64, x1: f64, z0: f64, z1: f64, y: f64, surface: u32) -> Vec<crate::render::Triangle> {
    quad(
        [
            Vector3::new(x0, y, z0),
            Vector3::new(x1, y, z0),
            Vector3::new(x1, y, z1),
            Vector3::new(x0, y, z1),
        ],
        0,
        surface,
    )
}

fn view() -> PinholeView {
    PinholeView::look_at(
        "front",
        Vector3::zeros(),
        Vector3::y(),
        Vector3::z(),
        100f64.to_radians(),
        64,
        64,
    )
    .unwrap()
}

fn visible_area(f: &Fragmentation, model: &Model, surface: u32) -> (f64, f64) {
    let (mut seen, mut hidden) = (0.0, 0.0);
    for g in &f.fragments {
        if model.triangles[g.triangle].surface == surface {
            if g.visible[0] {
                seen += g.shape.unsigned_area()
            } else {
                hidden += g.shape.unsigned_area()
            }
        }
    }
    (seen, hidden)
}

#[test]
fn a_panel_hides_its_perspective_shadow_on_the_wall() {
    let mut tris = panel(-5.0, 5.0, -5.0, 5.0, 10.0, 0);
    tris.extend(panel(-1.0, 1.0, -1.0, 1.0, 5.0, 1));
    let model = Model::new(tris).unwrap();
    let v = [view()];
    for (name, f) in [
        ("hybrid", hybrid(&model, &v, 0.0).unwrap()),
        ("weiler-atherton", weiler_atherton(&model, &v, 0.0).unwrap()),
    ] {
        // Tolerances: 1e-7 relative, the Boolean operations' integer snapping.
        // The panel (2 m at 5 m) covers a 4 m square of the wall at 10 m.
        let (wall_seen, wall_hidden) = visible_area(&f, &model, 0);
        assert!((wall_seen - 84.0).abs() < 84e-7, "{name}: {wall_seen}");
        assert!((wall_hidden - 16.0).abs() < 84e-7, "{name}: {wall_hidden}");
        assert!((visible_area(&f, &model, 1).0 - 4.0).abs() < 4e-7, "{name}");
        let check = check::total(&misclassified(&model, &f.fragments, &v));
        assert_eq!((check.wrong, check.unlocated), (0, 0), "{name}: {check:?}");
    }
}

#[test]
fn shallow_clipping_leaves_a_wholly_hidden_panel_intact_where_weiler_atherton_cuts_it() {
    // A (front) overlaps B (middle) and the image of C (back); B hides C wholly.
    let mut tris = panel(0.0, 2.0, -0.5, 0.5, 5.0, 0); // A
    tris.extend(panel(-3.0, 3.0, -3.0, 3.0, 8.0, 1)); // B
    tris.extend(panel(-1.0, 1.0, -1.0, 1.0, 9.0, 2)); // C
    let model = Model::new(tris).unwrap();
    let v = [view()];
    let h = hybrid(&model, &v, 0.0).unwrap();
    let wa = weiler_atherton(&model, &v, 0.0).unwrap();
    let count = |f: &Fragmentation, s: u32| {
        f.fragments
            .iter()
            .filter(|g| model.triangles[g.triangle].surface == s)
            .count()
    };
    assert_eq!(count(&h, 2), 2, "C's two triangles stay whole in the hybrid");
    assert!(count(&wa, 2) > 2, "Weiler–Atherton cuts C: {} pieces", count(&wa, 2));
    // Both agree on what is seen: C nothing, A all of it, B all but A's image.
    for f in [&h, &wa] {
        assert!(visible_area(f, &model, 2).0.abs() < 1e-7);
        assert!((visible_area(f, &model, 0).0 - 2.0).abs() < 2e-7);
        // A's image covers x in [0, 0.4], z in [-0.1, 0.1] (tan units); on B at 8 m: 3.2 × 1.6 m,
        // of which x ≤ 3 m lies on B: 3 × 1.6 = 4.8 m².
        assert!((visible_area(f, &model, 1).0 - (36.0 - 4.8)).abs() < 36e-7);
        let check = check::total(&misclassified(&model, &f.fragments, &v));
        assert_eq!(check.wrong, 0, "{check:?}");
    }
    assert!(
        h.fragments.len() < wa.fragments.len(),
        "{} against {}",
        h.fragments.len(),
        wa.fragments.len()
    );
}

#[test]
fn below_the_size_threshold_a_fragment_keeps_its_larger_part_label() {
    let mut tris = panel(-5.0, 5.0, -5.0, 5.0, 10.0, 0);
    tris.extend(panel(-1.0, 1.0, -1.0, 1.0, 5.0, 1));
    let model = Model::new(tris).unwrap();
    let v = [view()];
    let f = hybrid(&model, &v, 1e3).unwrap();
    assert_eq!(f.fragments.len(), 4, "nothing is cut");
    assert_eq!(f.small_mixed, 2);
    // Each wall triangle is mostly visible (42 of 50 m²): labelled visible.
    assert!(f.fragments.iter().all(|g| g.visible[0]));
    let check = check::total(&misclassified(&model, &f.fragments, &v));
    assert!(check.wrong > 0 && check.wrong == check.wrong_in_mixed, "{check:?}");
    assert!(matches!(hybrid(&model, &v, f64::NAN), Err(VisibilityError::BadThreshold(t)) if t.is_nan()));
}

#[test]
fn a_panel_cut_by_the_image_border_and_the_near_plane() {
    // The wall extends behind the camera and beyond the image on one side.
    let tris = quad(
        [
            Vector3::new(-3.0, -5.0, -2.0),
            Vector3::new(-3.0, 20.0, -2.0),
            Vector3::new(-3.0, 20.0, 2.0),
            Vector3::new(-3.0, -5.0, 2.0),
        ],
        0,
        0,
    );
    let model = Model::new(tris).unwrap();
    let v = [view()];
    for f in [
        hybrid(&model, &v, 0.0).unwrap(),
        weiler_atherton(&model, &v, 0.0).unwrap(),
    ] {
        let total: f64 = f.fragments.iter().map(|g| g.shape.unsigned_area()).sum();
        assert!((total - 100.0).abs() < 1e-5, "area is kept: {total}");
        // Seen: the part in the 100° square frustum: y ≥ 3/tan 50° and |z| ≤ y tan 50°.
        let y0 = 3.0 / 50f64.to_radians().tan();
        let seen: f64 = f
            .fragments
            .iter()
            .filter(|g| g.visible[0])
            .map(|g| g.shape.unsigned_area())
            .sum();
        assert!(
            (seen - 4.0 * (20.0 - y0)).abs() < 1e-6,
            "{seen} against {}",
            4.0 * (20.0 - y0)
        );
        assert_eq!(check::total(&misclassified(&model, &f.fragments, &v)).wrong, 0);
    }
}
