//! Every configuration type survives serialize → parse unchanged, and the
//! span tree reads whatever the serializer writes. The comparison is on
//! `Debug` text, which prints floats exactly (shortest round-trip form),
//! and treats NaN as equal to itself.

use proptest::prelude::*;
use serde::Serialize;
use serde::de::DeserializeOwned;

use crate::camera::Camera;
use crate::filter_wheel::FilterWheel;
use crate::head::PanTiltHead;
use crate::lights::Lights;
use crate::plan::{Plan, Session, Step, Trigger};
use crate::scene::Scene;
use crate::site::Site;
use crate::source::ron_options;
use crate::span_tree;
use crate::station::Station;

fn round_trip<T: Serialize + DeserializeOwned + std::fmt::Debug>(x: &T) -> Result<(), TestCaseError> {
    for text in [
        ron::ser::to_string(x).map_err(|e| TestCaseError::fail(e.to_string()))?,
        ron::ser::to_string_pretty(x, ron::ser::PrettyConfig::default())
            .map_err(|e| TestCaseError::fail(e.to_string()))?,
    ] {
        let back: T = ron_options()
            .from_str(&text)
            .map_err(|e| TestCaseError::fail(format!("{e}\n{text}")))?;
        prop_assert_eq!(format!("{x:?}"), format!("{back:?}"), "text: {}", text);
        prop_assert!(span_tree::parse(&text).is_some(), "span tree failed on {}", text);
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, max_default_size_range: 4, ..ProptestConfig::default() })]

    #[test] fn site(x in any::<Site>()) { round_trip(&x)?; }
    #[test] fn camera(x in any::<Camera>()) { round_trip(&x)?; }
    #[test] fn head(x in any::<PanTiltHead>()) { round_trip(&x)?; }
    #[test] fn filter_wheel(x in any::<FilterWheel>()) { round_trip(&x)?; }
    #[test] fn lights(x in any::<Lights>()) { round_trip(&x)?; }
    #[test] fn station(x in any::<Station>()) { round_trip(&x)?; }
    #[test] fn trigger(x in any::<Trigger>()) { round_trip(&x)?; }
    #[test] fn step(x in any::<Step>()) { round_trip(&x)?; }
    #[test] fn session(x in any::<Session>()) { round_trip(&x)?; }
    #[test] fn plan(x in any::<Plan>()) { round_trip(&x)?; }
    #[test] fn scene(x in any::<Scene>()) { round_trip(&x)?; }

    /// Arbitrary edits of a valid file never make the loader panic, and
    /// every error it reports has a position inside the file.
    #[test]
    fn mangled_files_give_errors_not_panics(
        which in 0usize..6,
        edits in proptest::collection::vec((any::<prop::sample::Index>(), 0usize..4, "[ -~]{0,3}"), 1..4),
    ) {
        let names = ["sim-station.ron", "real-station.ron", "campanile-day.ron", "campanile-quick.ron", "room-lights.ron", "campanile-scene.ron", "room-scene.ron"];
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples").join(names[which]);
        let mut text = std::fs::read_to_string(&path).expect("example exists");
        for (at, del, ins) in edits {
            let mut i = at.index(text.len() + 1);
            while !text.is_char_boundary(i) { i -= 1; }
            let mut j = (i + del).min(text.len());
            while !text.is_char_boundary(j) { j += 1; }
            text.replace_range(i..j, &ins);
        }
        let lines = text.lines().count().max(1);
        if let Err(errors) = crate::load_text(&path, text) {
            for e in errors.0 {
                let (line, col) = e.position.expect("a position");
                prop_assert!(line >= 1 && line <= lines + 1 && col >= 1, "{e}");
            }
        }
    }
}

#[test]
fn span_tree_locates_fields_through_some_and_variants() {
    let text = "Plan(a: Some((x: 1, y: [2, Named(3), (z: \"w\")])), b: r#\"raw \" str\"#, c: 'q')";
    let tree = span_tree::parse(text).expect("valid RON");
    use crate::validate::{FieldPath, Segment::*};
    let at = |p: Vec<crate::validate::Segment>| &text[tree.offset_of(&FieldPath(p))..];
    assert!(at(vec![Field("a".into()), Field("y".into()), Index(1), Index(0)]).starts_with("3)"));
    assert!(at(vec![Field("a".into()), Field("y".into()), Index(2), Field("z".into())]).starts_with("\"w\""));
    assert!(at(vec![Field("c".into())]).starts_with("'q'"));
    // Reverse lookup: the offset of "w" is inside a.y[2].z.
    let off = text.find("\"w\"").expect("present");
    assert_eq!(tree.path_at(off).to_string(), "a.y[2].z");
    // A missing field points at the deepest existing part.
    assert!(at(vec![Field("a".into()), Field("nope".into())]).starts_with("(x: 1"));
}

#[test]
fn prefix_path_survives_truncation() {
    let text = "Station(site: (name: \"x\", latitude_deg: 3";
    assert_eq!(
        span_tree::path_before(text, text.len()).to_string(),
        "site.latitude_deg"
    );
    let text = "Plan(sessions: [(name: \"a\"), (steps: [Views(poses: [\"p\", ";
    assert_eq!(
        span_tree::path_before(text, text.len()).to_string(),
        "sessions[1].steps[0].poses[1]"
    );
}

#[test]
fn line_col_counts_characters_not_bytes() {
    let text = "// é\n  °x";
    let off = text.find('x').expect("present");
    assert_eq!(span_tree::line_col(text, off), (2, 4));
    assert_eq!(span_tree::offset_of_line_col(text, 2, 4), off);
}

#[test]
fn sun_elevation_trigger_round_trips_readably() {
    let t = Trigger::SolarElevation {
        elevation_deg: 25.0,
        motion: crate::plan::SunMotion::Rising,
    };
    assert_eq!(
        ron::ser::to_string(&t).expect("serializes"),
        "SolarElevation(elevation_deg:25.0,motion:Rising)"
    );
}
