//! Issue 28's end-to-end criterion for the room: the geometry its range
//! scans give (segmented, meshed, the table closed into a slab) fed to
//! inverse global illumination (thesis ch. 4) in place of the true
//! geometry, the same photographs and solver; each material's errors,
//! averaged over four solver seeds, within 1.5× of those on the true
//! geometry, where that bound can be told from the solver's own seed: the
//! true geometry's errors over four further seeds against the first four
//! give each material's floor (wood's striped lobe and the brushed board's
//! move 65× and 2.9× at these settings); a material whose floor exceeds
//! 1.5× is held to its floor. The three spheres are the simulator's 96-facet polyhedra,
//! which no scan at this density resolves (BENCHMARKS.md, "The room's
//! scans through `igi`"): they are checked with their true facets kept,
//! and the other materials with everything rebuilt.
//! `cargo run -p campanile-sim --example igi_from_scans -- 90 180 4` prints
//! the whole table.

use campanile_process::igi::{IgiInput, IgiOptions};
use campanile_scan::mesh::{MeshMethod, MeshOptions, mesh_groups};
use campanile_scan::segment::params::Overrides;
use campanile_scan::segment::segment;
use campanile_sim::world::igi_photograph::PhotoSettings;
use campanile_sim::world::range_scanner::{ScannerSettings, room_poses, scan_scene};
use campanile_sim::world::room_igi::{ROOM_BOUNCES, RoomIgi, igi_triangles_of};
use campanile_sim::world::scanned_scene::{majority_surfaces, mean_igi_errors, scanned_scene, worst_ratio};

/// Solver seeds each error is averaged over.
const SEEDS: u64 = 4;
/// The bound on the ratio of errors.
const BOUND: f64 = 1.5;

#[test]
fn the_rooms_scans_give_reflectance_within_one_and_a_half_times_the_true_geometrys() {
    let room = RoomIgi::example().unwrap();
    let scene = room.scene();
    let scans = scan_scene(scene, &room_poses(), &ScannerSettings::new(90, 180)).unwrap();
    let (found, _) = segment(&scans.scans, &Overrides::default(), &|_| {}).unwrap();
    let meshes = mesh_groups(&scans.scans, &found, &MeshOptions::default()).unwrap();
    let majority = majority_surfaces(&found, &scans.truth);
    let surfaces = scene.surfaces();
    let surface = |name: &str| scene.surface_index(name).unwrap();

    // The table's group: a planar top whose sides closed it into a slab
    // about its true 5 cm thick.
    let table = meshes
        .iter()
        .find(|m| majority[m.group as usize].is_some_and(|g| g.surface == surface("table")))
        .expect("a group for the table");
    assert!(
        matches!(table.method, MeshMethod::PlanarPolygon | MeshMethod::PlanePieces),
        "{:?}",
        table.method
    );
    let thickness = table.slabs.first().expect("the table closed into a slab").thickness_m;
    assert!(
        (thickness - 0.05).abs() <= 0.01,
        "table {thickness} m thick (true 0.05)"
    );

    let input = room.igi_input(
        room.solver_cameras(80, 60),
        &PhotoSettings {
            indirect_samples: 16,
            max_bounces: ROOM_BOUNCES,
            seed: 7,
        },
    );
    let options = IgiOptions {
        cells_per_edge: 6,
        gather_rays: 64,
        ..IgiOptions::default()
    };
    let truth = room.true_materials().unwrap();
    let on_truth = mean_igi_errors(&input, &options, 0, SEEDS, &truth).unwrap();
    let again = mean_igi_errors(&input, &options, SEEDS, SEEDS, &truth).unwrap();
    let floor = |m: usize| {
        worst_ratio(&on_truth[m], &again[m])
            .unwrap()
            .max(worst_ratio(&again[m], &on_truth[m]).unwrap())
    };
    let all: Vec<usize> = (0..surfaces.len()).collect();
    let spheres: Vec<usize> = ["sphere-plastic", "sphere-metal", "sphere-diffuse"]
        .map(surface)
        .to_vec();
    let names = room.material_names();
    for (keep, checked) in [
        (Vec::new(), vec!["paint", "wood", "brushed"]),
        (spheres, names.iter().map(String::as_str).collect()),
    ] {
        let rebuilt = scanned_scene(scene, &meshes, &majority, &all, &keep).unwrap();
        assert!(rebuilt.missing.is_empty(), "{:?}", rebuilt.missing);
        let on_scans = mean_igi_errors(
            &IgiInput {
                triangles: igi_triangles_of(&rebuilt.scene),
                ..input.clone()
            },
            &options,
            0,
            SEEDS,
            &truth,
        )
        .unwrap();
        for name in checked {
            let m = names.iter().position(|n| n == name).unwrap();
            let ratio = worst_ratio(&on_truth[m], &on_scans[m]).unwrap();
            let bound = BOUND.max(floor(m));
            eprintln!(
                "{name} (true spheres kept: {}): {:?} against {:?}, {ratio:.2}× (bound {bound:.2}×)",
                !keep.is_empty(),
                on_scans[m],
                on_truth[m]
            );
            assert!(
                ratio <= bound,
                "{name}: {ratio:.2}× the true geometry's errors (bound {bound:.2}×)"
            );
        }
    }
}
