//! Surveyed targets (`targets.ron`): the world positions of the targets
//! that `campanile register` finds photographs' poses from (thesis §3.3).
//! Two kinds: coded targets (the default, `kind: Coded`), flat square
//! AprilTags whose id the image shows; and the thesis's own targets
//! (`kind: Circle(radius_m)`), flat dark square plates with a white circle
//! of that radius and no identity in the image, whose correspondences are
//! found by search (§3.3.2). Positions come from a survey or a range scan.
//!
//! ```ron
//! Targets(
//!     family: Tag36h11,
//!     targets: [
//!         // id: the tag's code; centre_m: world frame (x east, y north, z up);
//!         // normal: out of the tag's face; size_m: the black square's side.
//!         (id: 0, centre_m: (-3.0, -5.5, 2.0), normal: (0.0, -1.0, 0.0), size_m: 0.5),
//!         // On a horizontal face, `up` says where the tag's top points.
//!         (id: 7, centre_m: (0.0, -9.0, 0.0), normal: (0.0, 0.0, 1.0), up: Some((0.0, 1.0, 0.0)), size_m: 0.5),
//!     ],
//! )
//! ```
//!
//! Circle targets (the `id` is the survey's label, not seen in the image;
//! `centre_m` is the circle's centre; `size_m` is the plate's side, which
//! must exceed the circle's diameter; `up` is not used):
//!
//! ```ron
//! Targets(
//!     kind: Circle(0.1),
//!     targets: [
//!         (id: 1, centre_m: (-3.0, -5.502, 2.0), normal: (0.0, -1.0, 0.0), size_m: 0.4),
//!     ],
//! )
//! ```
//!
//! The tag's top edge faces `up`; without it, the world's up (z) projected
//! into the tag's plane, or north (y) on a horizontal face: the way a
//! tag is hung on a wall.

use serde::{Deserialize, Serialize};

use crate::validate::{Validate, Validator, fmt_f64};

/// The AprilTag families `register` decodes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum TagFamily {
    /// 36-bit codes, minimum Hamming distance 11, 587 ids (the AprilTag default).
    #[default]
    Tag36h11,
}

/// The kind of every target of a file.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub enum TargetKind {
    /// AprilTags of the file's `family`: identity from the image.
    #[default]
    Coded,
    /// The thesis's targets: a white circle of this radius, metres, on a
    /// dark square plate; no identity in the image.
    Circle(f64),
}

impl TargetKind {
    /// The circle's radius for `Circle`, `None` for coded targets.
    pub fn circle_radius_m(&self) -> Option<f64> {
        match self {
            TargetKind::Coded => None,
            TargetKind::Circle(r) => Some(*r),
        }
    }
}

/// One surveyed target.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Target {
    /// The tag's id in its family; for circle targets, the survey's label.
    pub id: u32,
    /// Centre of the tag (of the circle), world frame, metres.
    pub centre_m: (f64, f64, f64),
    /// Normal out of the tag's printed face (need not be unit length).
    pub normal: (f64, f64, f64),
    /// Where the tag's top edge faces, if not the default (module doc).
    #[serde(default)]
    pub up: Option<(f64, f64, f64)>,
    /// Side of the tag's black square; for circle targets, of the plate. Metres.
    pub size_m: f64,
}

/// The targets file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, rename = "Targets")]
pub struct Targets {
    /// The targets' kind (coded by default).
    #[serde(default)]
    pub kind: TargetKind,
    /// The tags' family (coded targets).
    #[serde(default)]
    pub family: TagFamily,
    /// The targets.
    pub targets: Vec<Target>,
}

fn norm(v: (f64, f64, f64)) -> f64 {
    (v.0 * v.0 + v.1 * v.1 + v.2 * v.2).sqrt()
}

fn fmt_v(v: (f64, f64, f64)) -> String {
    format!("({}, {}, {})", fmt_f64(v.0), fmt_f64(v.1), fmt_f64(v.2))
}

impl Validate for Targets {
    fn validate(&self, v: &mut Validator) {
        if self.targets.is_empty() {
            v.invalid("targets", "[]".into(), "at least one target");
        }
        let radius = self.kind.circle_radius_m();
        if let Some(r) = radius
            && !(r.is_finite() && r > 0.0)
        {
            v.invalid(
                "kind",
                format!("Circle({})", fmt_f64(r)),
                "a circle of positive radius, metres",
            );
        }
        v.at("targets", |v| {
            for (i, t) in self.targets.iter().enumerate() {
                v.at(i, |v| {
                    if radius.is_none() && t.id >= 587 {
                        v.invalid("id", t.id.to_string(), "a tag36h11 id, 0 to 586");
                    }
                    if self.targets[..i].iter().any(|o| o.id == t.id) {
                        v.invalid("id", t.id.to_string(), "an id not used by an earlier target");
                    }
                    let c = t.centre_m;
                    if ![c.0, c.1, c.2].iter().all(|x| x.is_finite()) {
                        v.invalid("centre_m", fmt_v(c), "finite coordinates, metres");
                    }
                    let n = norm(t.normal);
                    if !(n.is_finite() && n > 1e-9) {
                        v.invalid("normal", fmt_v(t.normal), "a non-zero direction out of the tag's face");
                    }
                    if let Some(up) = t.up {
                        let u = norm(up);
                        let dot = (up.0 * t.normal.0 + up.1 * t.normal.1 + up.2 * t.normal.2) / (u * n);
                        if !(u.is_finite() && u > 1e-9) || dot.abs() > 0.99 {
                            v.invalid(
                                "up",
                                format!("Some({})", fmt_v(up)),
                                "a non-zero direction not along the normal",
                            );
                        }
                    }
                    if !(t.size_m.is_finite() && t.size_m > 0.0) {
                        v.invalid("size_m", fmt_f64(t.size_m), "a positive side, metres");
                    } else if let Some(r) = radius
                        && r.is_finite()
                        && t.size_m <= 2.0 * r
                    {
                        v.invalid(
                            "size_m",
                            fmt_f64(t.size_m),
                            "a plate side larger than the circle's diameter, metres",
                        );
                    }
                });
            }
        });
    }
}

impl Target {
    /// The tag's frame: unit (right, up, normal) as seen facing its printed side.
    pub fn axes(&self) -> [[f64; 3]; 3] {
        let n = {
            let l = norm(self.normal);
            [self.normal.0 / l, self.normal.1 / l, self.normal.2 / l]
        };
        let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let project = |d: [f64; 3]| {
            let k = dot(d, n);
            [d[0] - k * n[0], d[1] - k * n[1], d[2] - k * n[2]]
        };
        let mut up = project(self.up.map_or([0.0, 0.0, 1.0], |u| [u.0, u.1, u.2]));
        if (dot(up, up)).sqrt() < 1e-6 {
            up = project([0.0, 1.0, 0.0]);
        }
        let l = dot(up, up).sqrt();
        let up = up.map(|x| x / l);
        // right × up = normal, so right = up × normal.
        let right = [
            up[1] * n[2] - up[2] * n[1],
            up[2] * n[0] - up[0] * n[2],
            up[0] * n[1] - up[1] * n[0],
        ];
        [right, up, n]
    }

    /// World positions of the black square's corners, in the order
    /// top-left, top-right, bottom-right, bottom-left as seen facing the tag.
    pub fn corners_m(&self) -> [[f64; 3]; 4] {
        let [r, u, _] = self.axes();
        let h = 0.5 * self.size_m;
        let c = [self.centre_m.0, self.centre_m.1, self.centre_m.2];
        [(-1.0, 1.0), (1.0, 1.0), (1.0, -1.0), (-1.0, -1.0)]
            .map(|(a, b)| [0, 1, 2].map(|i| c[i] + h * (a * r[i] + b * u[i])))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wall_tag() -> Target {
        Target {
            id: 3,
            centre_m: (1.0, -5.5, 2.0),
            normal: (0.0, -2.0, 0.0),
            up: None,
            size_m: 0.4,
        }
    }

    #[test]
    fn a_tag_on_a_south_wall_has_its_right_to_the_east() {
        let [r, u, n] = wall_tag().axes();
        assert_eq!(r, [1.0, 0.0, 0.0]);
        assert_eq!(u, [0.0, 0.0, 1.0]);
        assert_eq!(n, [0.0, -1.0, 0.0]);
        let c = wall_tag().corners_m();
        assert_eq!(c[0], [0.8, -5.5, 2.2]);
        assert_eq!(c[2], [1.2, -5.5, 1.8]);
    }

    #[test]
    fn a_tag_on_the_ground_faces_north_by_default() {
        let t = Target {
            normal: (0.0, 0.0, 1.0),
            ..wall_tag()
        };
        let [r, u, _] = t.axes();
        assert_eq!(u, [0.0, 1.0, 0.0]);
        assert_eq!(r, [1.0, 0.0, 0.0]);
    }

    #[test]
    fn bad_fields_are_named() {
        let t = Targets {
            kind: TargetKind::Coded,
            family: TagFamily::Tag36h11,
            targets: vec![
                wall_tag(),
                Target {
                    size_m: -1.0,
                    normal: (0.0, 0.0, 0.0),
                    ..wall_tag()
                },
            ],
        };
        let mut v = Validator::new(".");
        t.validate(&mut v);
        let issues: Vec<String> = v.into_issues().iter().map(|i| i.path.to_string()).collect();
        assert_eq!(issues, ["targets[1].id", "targets[1].normal", "targets[1].size_m"]);
    }

    #[test]
    fn circle_targets_take_any_label_and_need_a_plate_wider_than_the_circle() {
        let text = "Targets(kind: Circle(0.1), targets: [
            (id: 1000, centre_m: (0.0, 0.0, 1.0), normal: (0.0, -1.0, 0.0), size_m: 0.4),
            (id: 1001, centre_m: (1.0, 0.0, 1.0), normal: (0.0, -1.0, 0.0), size_m: 0.15),
        ])";
        let t: Targets = ron::from_str(text).expect("parses");
        assert_eq!(t.kind.circle_radius_m(), Some(0.1));
        let mut v = Validator::new(".");
        t.validate(&mut v);
        let issues: Vec<String> = v.into_issues().iter().map(|i| i.path.to_string()).collect();
        assert_eq!(issues, ["targets[1].size_m"]);
        // Without a kind: coded.
        let coded: Targets = ron::from_str(
            "Targets(targets: [(id: 1, centre_m: (0.0, 0.0, 1.0), normal: (0.0, -1.0, 0.0), size_m: 0.4)])",
        )
        .expect("parses");
        assert_eq!(coded.kind, TargetKind::Coded);
    }
}
