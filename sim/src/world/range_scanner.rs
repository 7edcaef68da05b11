//! The simulated terrestrial range scanner (thesis ch. 2's input): beams
//! cast from scanner poses over a scene, on an organised grid of azimuth ×
//! elevation steps, giving registered [`Scan`]s with their poses and grids
//! and the true surface of every point.
//!
//! # The beam
//!
//! The scanner's frame is x forward, y left, z up; a beam at azimuth `a`
//! (counter-clockwise from x, as in E57) and elevation `e` has the
//! direction (cos e cos a, cos e sin a, sin e), turned into the scene by
//! the pose's rotation. Column `c` of `columns` is at azimuth
//! `a₀ + (c + ½)·Δa`; row 0 is the highest elevation, the last row the
//! lowest (a range image reads top-down). Each beam:
//!
//! 1. meets the nearest surface ([`Scene::intersect`]) within
//!    [`ScannerSettings::max_range_m`], or returns nothing (sky);
//! 2. returns nothing at grazing incidence: beyond
//!    [`ScannerSettings::grazing_limit_deg`] from the surface's normal;
//! 3. drops out with probability [`ScannerSettings::dropout_probability`]
//!    (a seeded draw);
//! 4. at a **depth edge** is a **mixed pixel** with probability
//!    [`ScannerSettings::mixed_pixel_probability`]. Four more rays at the
//!    footprint's edge (± [`ScannerSettings::footprint`] of a step in
//!    azimuth and in elevation) look for a surface the footprint spills
//!    onto: one farther, by more than [`ScannerSettings::edge_jump_m`],
//!    than the central surface's plane along that ray. Such a beam is on
//!    the near side of a jump edge (a slanted plane or a concave corner
//!    is not one), and a mixed return lies at a uniformly drawn range
//!    between the central surface and the farthest such surface, as the
//!    comet tails behind real scanners' silhouettes do;
//! 5. gets Gaussian range noise of σ [`ScannerSettings::range_noise_m`]
//!    along the beam.
//!
//! The **intensity** is the surface's reflectance at the laser's
//! wavelength times the cosine of the incidence angle, plus Gaussian noise
//! of σ [`ScannerSettings::intensity_noise`], clamped to [0, 1]. The scenes
//! carry no near-infrared albedo: the red channel of [`Scene::albedo_at`]
//! stands in for it (red is the closest of the three to the 905 nm and
//! 1550 nm lasers of terrestrial scanners).
//!
//! # The truth
//!
//! [`RangeScans::truth`] labels every point with the surface its central
//! ray met, named by [`Scene::surfaces`]. A mixed pixel lies on no
//! surface and is labelled [`UNASSIGNED`]. A beam with no return has no
//! point (its grid cell is [`NO_RETURN`]) and so no label. Normals are not
//! given: scanners do not measure them.
//!
//! # Randomness
//!
//! Every draw comes from a ChaCha stream seeded by
//! [`crate::seed::derive`] with [`Purpose::RangeScan`] from
//! [`ScannerSettings::seed`], per scan and then per row, so rows run in
//! parallel and the same seed gives the same scans.

use std::path::{Path, PathBuf};

use campanile_process::render::{Ray, Scene};
use campanile_scan::cloud::{NO_RETURN, RangeGrid, Scan, ScannerPose};
use campanile_scan::segmentation::{Segmentation, UNASSIGNED};
use nalgebra::{Rotation3, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use super::WorldError;
use crate::seed::{Purpose, derive};

/// Why scans could not be simulated or written.
#[derive(Debug, thiserror::Error)]
pub enum RangeScanError {
    /// A setting is out of its range.
    #[error("range scanner setting {field} = {value}: expected {expected}")]
    Setting {
        /// The setting.
        field: &'static str,
        /// Its value.
        value: f64,
        /// Its range.
        expected: &'static str,
    },
    /// The example scene could not be loaded.
    #[error(transparent)]
    World(#[from] WorldError),
    /// A scan file could not be written.
    #[error(transparent)]
    Write(#[from] campanile_scan::write::WriteError),
    /// The output directory could not be made.
    #[error("{path}: {message}")]
    Io {
        /// The directory.
        path: PathBuf,
        /// The system's message.
        message: String,
    },
}

/// The scanner: its grid, its noise and its faults.
#[derive(Debug, Clone, PartialEq)]
pub struct ScannerSettings {
    /// Rows: elevation steps.
    pub rows: usize,
    /// Columns: azimuth steps.
    pub columns: usize,
    /// The azimuths swept, degrees, from the first column's edge to the
    /// last one's (0 to 360: a full turn).
    pub azimuth_deg: (f64, f64),
    /// The lowest and highest elevations, degrees (the last and first
    /// rows' centres).
    pub elevation_deg: (f64, f64),
    /// σ of the range noise, metres (3 mm: a phase or pulse scanner at
    /// room distances).
    pub range_noise_m: f64,
    /// σ of the intensity noise, in intensity units (0.01).
    pub intensity_noise: f64,
    /// The beam footprint's half-width as a fraction of the angular step
    /// (0.5: footprints touch their neighbours').
    pub footprint: f64,
    /// The depth jump across a footprint that makes a depth edge, metres
    /// (0.05).
    pub edge_jump_m: f64,
    /// The chance that a beam at a depth edge returns a mixed pixel (0.5).
    pub mixed_pixel_probability: f64,
    /// The chance that a beam that met a surface returns nothing (0.005).
    pub dropout_probability: f64,
    /// Incidence beyond which nothing returns, degrees from the normal (85).
    pub grazing_limit_deg: f64,
    /// The farthest return, metres (1000).
    pub max_range_m: f64,
    /// The seed of every draw.
    pub seed: u64,
}

impl ScannerSettings {
    /// A scanner of `rows` × `columns` beams over a full turn and
    /// elevations from −60° to 80°, with the default noise and faults.
    pub fn new(rows: usize, columns: usize) -> ScannerSettings {
        ScannerSettings {
            rows,
            columns,
            azimuth_deg: (0.0, 360.0),
            elevation_deg: (-60.0, 80.0),
            range_noise_m: 0.003,
            intensity_noise: 0.01,
            footprint: 0.5,
            edge_jump_m: 0.05,
            mixed_pixel_probability: 0.5,
            dropout_probability: 0.005,
            grazing_limit_deg: 85.0,
            max_range_m: 1000.0,
            seed: 1,
        }
    }

    /// Checks every setting's range.
    pub fn check(&self) -> Result<(), RangeScanError> {
        let bad = |field, value: f64, expected| Err(RangeScanError::Setting { field, value, expected });
        let (a0, a1) = self.azimuth_deg;
        let (e0, e1) = self.elevation_deg;
        if self.rows == 0 || self.rows > 1 << 16 {
            return bad("rows", self.rows as f64, "1 to 65536");
        }
        if self.columns == 0 || self.columns > 1 << 16 {
            return bad("columns", self.columns as f64, "1 to 65536");
        }
        if !(a1 > a0 && a1 - a0 <= 360.0) {
            return bad("azimuth_deg (end − start)", a1 - a0, "in (0, 360]");
        }
        if !(-90.0..=90.0).contains(&e0) || !(-90.0..=90.0).contains(&e1) || e1 < e0 {
            return bad("elevation_deg", e1 - e0, "−90 ≤ lowest ≤ highest ≤ 90");
        }
        for (field, value) in [
            ("range_noise_m", self.range_noise_m),
            ("intensity_noise", self.intensity_noise),
            ("footprint", self.footprint),
            ("edge_jump_m", self.edge_jump_m),
        ] {
            if !(value >= 0.0 && value.is_finite()) {
                return bad(field, value, "a finite number ≥ 0");
            }
        }
        for (field, value) in [
            ("mixed_pixel_probability", self.mixed_pixel_probability),
            ("dropout_probability", self.dropout_probability),
        ] {
            if !(0.0..=1.0).contains(&value) {
                return bad(field, value, "a probability in [0, 1]");
            }
        }
        if !(self.grazing_limit_deg > 0.0 && self.grazing_limit_deg <= 90.0) {
            return bad("grazing_limit_deg", self.grazing_limit_deg, "in (0, 90]");
        }
        if !(self.max_range_m > 0.0 && self.max_range_m.is_finite()) {
            return bad("max_range_m", self.max_range_m, "a finite number > 0");
        }
        Ok(())
    }

    fn azimuth_step(&self) -> f64 {
        (self.azimuth_deg.1 - self.azimuth_deg.0).to_radians() / self.columns as f64
    }

    fn elevation_step(&self) -> f64 {
        if self.rows > 1 {
            (self.elevation_deg.1 - self.elevation_deg.0).to_radians() / (self.rows - 1) as f64
        } else {
            0.0
        }
    }

    /// The azimuth and elevation of the beam at (`row`, `column`), radians.
    pub fn beam_angles(&self, row: usize, column: usize) -> (f64, f64) {
        let azimuth = self.azimuth_deg.0.to_radians() + (column as f64 + 0.5) * self.azimuth_step();
        let elevation = if self.rows > 1 {
            self.elevation_deg.1.to_radians() - row as f64 * self.elevation_step()
        } else {
            0.5 * (self.elevation_deg.0 + self.elevation_deg.1).to_radians()
        };
        (azimuth, elevation)
    }
}

/// The unit direction of a beam in the scanner's frame.
pub fn beam_direction(azimuth: f64, elevation: f64) -> Vector3<f64> {
    Vector3::new(
        elevation.cos() * azimuth.cos(),
        elevation.cos() * azimuth.sin(),
        elevation.sin(),
    )
}

/// A level scanner at `origin` whose x axis points `heading_deg` from
/// north through east (DESIGN.md's azimuth): the pose of a scanner on a
/// tripod.
pub fn level_pose(origin: Vector3<f64>, heading_deg: f64) -> ScannerPose {
    // Scene x is east, y north: north-through-east heading h is the angle
    // π/2 − h counter-clockwise from east.
    ScannerPose {
        origin,
        rotation: Rotation3::from_axis_angle(
            &Vector3::z_axis(),
            std::f64::consts::FRAC_PI_2 - heading_deg.to_radians(),
        ),
    }
}

/// What happened to one scan's beams.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct BeamCounts {
    /// Beams cast (rows × columns).
    pub beams: usize,
    /// Beams that met no surface within range.
    pub misses: usize,
    /// Beams lost at grazing incidence.
    pub grazing: usize,
    /// Beams that met a surface, not at grazing incidence: the ones that
    /// could drop out.
    pub eligible: usize,
    /// Of those, beams dropped by the seeded draw.
    pub dropouts: usize,
    /// Returned beams whose footprint straddled a depth edge.
    pub edges: usize,
    /// Of those, mixed pixels.
    pub mixed: usize,
    /// Points returned.
    pub returns: usize,
}

impl BeamCounts {
    fn add(&mut self, o: &BeamCounts) {
        self.beams += o.beams;
        self.misses += o.misses;
        self.grazing += o.grazing;
        self.eligible += o.eligible;
        self.dropouts += o.dropouts;
        self.edges += o.edges;
        self.mixed += o.mixed;
        self.returns += o.returns;
    }
}

/// Several registered scans of one scene, with their truth.
#[derive(Debug, Clone)]
pub struct RangeScans {
    /// One scan per pose, named for it, with its pose and grid.
    pub scans: Vec<Scan>,
    /// Every point's true surface (names: the scene's surfaces).
    pub truth: Segmentation,
    /// What happened to each scan's beams.
    pub counts: Vec<BeamCounts>,
}

/// One returned beam.
struct Return {
    position: Vector3<f64>,
    intensity: f32,
    label: u32,
}

/// A standard normal draw (Box–Muller).
fn gaussian(rng: &mut ChaCha8Rng) -> f64 {
    let u1: f64 = rng.random::<f64>().max(1e-300);
    let u2: f64 = rng.random();
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

fn beam(
    scene: &Scene,
    pose: &ScannerPose,
    settings: &ScannerSettings,
    (azimuth, elevation): (f64, f64),
    rng: &mut ChaCha8Rng,
    counts: &mut BeamCounts,
) -> Option<Return> {
    counts.beams += 1;
    let cast = |a: f64, e: f64| {
        let direction = pose.rotation * beam_direction(a, e);
        let ray = Ray {
            origin: pose.origin,
            direction,
        };
        scene.intersect(&ray, settings.max_range_m).map(|hit| (hit, direction))
    };
    let Some((hit, direction)) = cast(azimuth, elevation) else {
        counts.misses += 1;
        return None;
    };
    let triangle = &scene.triangles()[hit.triangle];
    let cos_incidence = triangle.normal.dot(&direction).abs();
    if cos_incidence < settings.grazing_limit_deg.to_radians().cos() {
        counts.grazing += 1;
        return None;
    }
    counts.eligible += 1;
    // Draw every variate for every eligible beam, so that one setting's
    // change does not shift the others' streams.
    let (drop, mix, blend) = (rng.random::<f64>(), rng.random::<f64>(), rng.random::<f64>());
    let (range_noise, intensity_noise) = (gaussian(rng), gaussian(rng));
    if drop < settings.dropout_probability {
        counts.dropouts += 1;
        return None;
    }
    counts.returns += 1;
    let (ha, he) = (
        settings.footprint * settings.azimuth_step(),
        settings.footprint * settings.elevation_step(),
    );
    // The footprint spills past the surface's edge when a sub-ray meets
    // something farther than the central surface's plane would be: the
    // far side of a jump edge. (A sub-ray on a slanted plane meets that
    // plane; one in a concave corner meets the other wall before it.)
    let plane_range = |d: &Vector3<f64>| {
        let along = triangle.normal.dot(d);
        (along.abs() > 1e-6).then(|| triangle.normal.dot(&(hit.point - pose.origin)) / along)
    };
    let mut far = hit.t;
    for (da, de) in [(ha, 0.0), (-ha, 0.0), (0.0, he), (0.0, -he)] {
        if let Some((h, d)) = cast(azimuth + da, elevation + de)
            && plane_range(&d).is_some_and(|t| h.t > t + settings.edge_jump_m)
        {
            far = far.max(h.t);
        }
    }
    let mut range = hit.t;
    let mut label = triangle.surface;
    if far > hit.t {
        counts.edges += 1;
        if mix < settings.mixed_pixel_probability {
            counts.mixed += 1;
            range = hit.t + blend * (far - hit.t);
            label = UNASSIGNED;
        }
    }
    range += settings.range_noise_m * range_noise;
    let reflectance = scene.albedo_at(hit.triangle, &hit.point)[0];
    let intensity = (reflectance * cos_incidence + settings.intensity_noise * intensity_noise).clamp(0.0, 1.0);
    Some(Return {
        position: pose.origin + direction * range,
        intensity: intensity as f32,
        label,
    })
}

/// Scans `scene` from each of `poses` (name, pose) with `settings`.
pub fn scan_scene(
    scene: &Scene,
    poses: &[(String, ScannerPose)],
    settings: &ScannerSettings,
) -> Result<RangeScans, RangeScanError> {
    settings.check()?;
    let mut scans = Vec::with_capacity(poses.len());
    let mut labels = Vec::with_capacity(poses.len());
    let mut all_counts = Vec::with_capacity(poses.len());
    for (index, (name, pose)) in poses.iter().enumerate() {
        let scan_seed = derive(settings.seed, Purpose::RangeScan, index as u64);
        let rows: Vec<(Vec<Option<Return>>, BeamCounts)> = (0..settings.rows)
            .into_par_iter()
            .map(|row| {
                let mut rng = ChaCha8Rng::seed_from_u64(derive(scan_seed, Purpose::RangeScan, row as u64));
                let mut counts = BeamCounts::default();
                let beams = (0..settings.columns)
                    .map(|col| {
                        beam(
                            scene,
                            pose,
                            settings,
                            settings.beam_angles(row, col),
                            &mut rng,
                            &mut counts,
                        )
                    })
                    .collect();
                (beams, counts)
            })
            .collect();
        let mut counts = BeamCounts::default();
        let mut positions = Vec::new();
        let mut intensity = Vec::new();
        let mut scan_labels = Vec::new();
        let mut cells = Vec::with_capacity(settings.rows * settings.columns);
        for (beams, row_counts) in rows {
            counts.add(&row_counts);
            for b in beams {
                match b {
                    Some(r) => {
                        cells.push(positions.len() as u32);
                        positions.push(r.position);
                        intensity.push(r.intensity);
                        scan_labels.push(r.label);
                    }
                    None => cells.push(NO_RETURN),
                }
            }
        }
        let mut scan = Scan::from_positions(name.clone(), positions);
        scan.pose = Some(*pose);
        scan.intensity = Some(intensity);
        scan.grid = Some(RangeGrid {
            rows: settings.rows,
            cols: settings.columns,
            cells,
        });
        debug_assert_eq!(scan.check(), Ok(()));
        scans.push(scan);
        labels.push(scan_labels);
        all_counts.push(counts);
    }
    Ok(RangeScans {
        scans,
        truth: Segmentation {
            labels,
            names: scene.surfaces().to_vec(),
        },
        counts: all_counts,
    })
}

/// Five scanner poses in the example room (5 × 4 × 3 m; `examples/room.obj`):
/// four near the corners and one high over the south wall, all at tripod
/// height or above and clear of the table and spheres, each facing the
/// room's centre.
pub fn room_poses() -> Vec<(String, ScannerPose)> {
    [
        ("room-sw", (0.8, 0.6, 1.5), 45.0),
        ("room-se", (4.2, 0.6, 1.5), 315.0),
        ("room-ne", (4.2, 3.4, 1.5), 225.0),
        ("room-nw", (0.8, 3.4, 1.5), 135.0),
        ("room-s-high", (2.5, 0.6, 2.4), 0.0),
    ]
    .into_iter()
    .map(|(name, (x, y, z), heading)| (name.to_string(), level_pose(Vector3::new(x, y, z), heading)))
    .collect()
}

/// Five scanner poses around the example bell tower (11 m square, 94 m
/// tall; `examples/campanile.obj`): one 30 m off each corner and one 40 m
/// south, at tripod height, each facing the tower.
pub fn building_poses() -> Vec<(String, ScannerPose)> {
    [
        ("tower-se", (30.0, -30.0, 1.5), 315.0),
        ("tower-sw", (-30.0, -30.0, 1.5), 45.0),
        ("tower-nw", (-30.0, 30.0, 1.5), 135.0),
        ("tower-ne", (30.0, 30.0, 1.5), 225.0),
        ("tower-s", (0.0, -40.0, 1.5), 0.0),
    ]
    .into_iter()
    .map(|(name, (x, y, z), heading)| (name.to_string(), level_pose(Vector3::new(x, y, z), heading)))
    .collect()
}

/// The example room's scene (`examples/room-scene.ron`).
pub fn room_scene() -> Result<Scene, RangeScanError> {
    Ok(super::room_igi::RoomIgi::example()?.loaded.scene)
}

/// The example building's scene (`examples/campanile-scene.ron`).
pub fn building_scene() -> Result<Scene, RangeScanError> {
    Ok(super::scene_file::load_scene(&super::scene_file::examples_dir().join("campanile-scene.ron"))?.scene)
}

/// How [`write_scans`] writes the scans.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ScanFileFormat {
    /// One binary PLY file per scan, `NAME.ply`.
    Ply,
    /// One E57 file with every scan, `SET.e57`.
    E57,
}

/// Writes `scans` into `dir` (made if missing) as `format`; `set` names
/// the E57 file. Returns the files written. The files hold what a scanner
/// gives (points, intensity, grid, pose), not the truth.
pub fn write_scans(
    dir: &Path,
    set: &str,
    scans: &RangeScans,
    format: ScanFileFormat,
) -> Result<Vec<PathBuf>, RangeScanError> {
    std::fs::create_dir_all(dir).map_err(|e| RangeScanError::Io {
        path: dir.to_path_buf(),
        message: e.to_string(),
    })?;
    match format {
        ScanFileFormat::Ply => scans
            .scans
            .iter()
            .map(|s| {
                let path = dir.join(format!("{}.ply", s.name));
                campanile_scan::write::ply::write(&path, s)?;
                Ok(path)
            })
            .collect(),
        ScanFileFormat::E57 => {
            let path = dir.join(format!("{set}.e57"));
            campanile_scan::write::e57::write(&path, &scans.scans)?;
            Ok(vec![path])
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use campanile_process::render::{Material, shapes};

    const FACES: [&str; 6] = ["west", "east", "south", "north", "floor", "ceiling"];
    const RED: [f64; 6] = [0.2, 0.3, 0.4, 0.5, 0.6, 0.7];
    const MIN: Vector3<f64> = Vector3::new(0.0, 0.0, 0.0);
    const MAX: Vector3<f64> = Vector3::new(4.0, 3.0, 2.5);

    /// A 4 × 3 × 2.5 m box room, each face its own surface and red albedo.
    fn box_room() -> Scene {
        let materials = FACES
            .iter()
            .zip(RED)
            .map(|(f, r)| Material::diffuse(f, [r, 0.5, 0.5]))
            .collect();
        let triangles = shapes::cuboid(MIN, MAX, true, [0, 1, 2, 3, 4, 5], [0, 1, 2, 3, 4, 5]);
        Scene::new(triangles, materials, FACES.iter().map(|f| f.to_string()).collect()).unwrap()
    }

    /// The analytic distance from `c` along unit `d` to the box's inside,
    /// and the face met (in `FACES` order).
    fn box_hit(c: &Vector3<f64>, d: &Vector3<f64>) -> (f64, usize) {
        (0..3)
            .filter(|&i| d[i].abs() > 1e-12)
            .map(|i| {
                if d[i] > 0.0 {
                    ((MAX[i] - c[i]) / d[i], 2 * i + 1)
                } else {
                    ((MIN[i] - c[i]) / d[i], 2 * i)
                }
            })
            .fold((f64::INFINITY, 0), |a, b| if b.0 < a.0 { b } else { a })
    }

    fn centre_scan(settings: &ScannerSettings) -> (Vector3<f64>, RangeScans) {
        let centre = Vector3::new(2.0, 1.5, 1.25);
        let poses = vec![("centre".to_string(), level_pose(centre, 90.0))];
        (centre, scan_scene(&box_room(), &poses, settings).unwrap())
    }

    #[test]
    fn a_scanner_at_a_box_rooms_centre_sees_the_analytic_ranges_faces_and_reflectances() {
        let mut settings = ScannerSettings::new(19, 36);
        settings.elevation_deg = (-80.0, 80.0);
        settings.mixed_pixel_probability = 0.0;
        settings.dropout_probability = 0.0;
        let (centre, scans) = centre_scan(&settings);
        let scan = &scans.scans[0];
        let grid = scan.grid.as_ref().unwrap();
        // Nothing grazes (the steepest incidence from the centre is 63°),
        // nothing is missed or dropped: a return in every cell.
        assert_eq!(scans.counts[0].returns, 19 * 36);
        assert_eq!(scan.len(), 19 * 36);
        // Heading 90° (east) is the identity rotation.
        assert!(scan.pose.unwrap().rotation.angle() < 1e-12);
        let intensity = scan.intensity.as_ref().unwrap();
        let (mut worst_range, mut worst_intensity) = (0.0f64, 0.0f64);
        for row in 0..grid.rows {
            for col in 0..grid.cols {
                let p = grid.point_at(row, col).unwrap();
                let (a, e) = settings.beam_angles(row, col);
                let d = beam_direction(a, e);
                let (t, face) = box_hit(&centre, &d);
                // Range: analytic within 5σ (σ = 3 mm); the point on the beam.
                let r = scan.positions[p] - centre;
                worst_range = worst_range.max((r.norm() - t).abs());
                assert!(r.normalize().dot(&d) > 1.0 - 1e-12);
                // Surface: the analytic face.
                assert_eq!(
                    scans.truth.names[scans.truth.labels[0][p] as usize], FACES[face],
                    "row {row} col {col}"
                );
                // Intensity: red albedo × cos(incidence), within 5σ (0.01).
                let n = [Vector3::x(), Vector3::y(), Vector3::z()][face / 2];
                let expected = RED[face] * n.dot(&d).abs();
                worst_intensity = worst_intensity.max((f64::from(intensity[p]) - expected).abs());
            }
        }
        assert!(worst_range < 5.0 * 0.003, "{worst_range}");
        assert!(worst_intensity < 5.0 * 0.01, "{worst_intensity}");
    }

    #[test]
    fn grazing_beams_return_nothing_and_the_same_seed_gives_the_same_scans() {
        // From 0.05 m above the floor, the floor is met at grazing angles.
        let mut settings = ScannerSettings::new(12, 24);
        settings.grazing_limit_deg = 60.0;
        settings.dropout_probability = 0.0;
        let poses = vec![("low".to_string(), level_pose(Vector3::new(2.0, 1.5, 0.05), 0.0))];
        let a = scan_scene(&box_room(), &poses, &settings).unwrap();
        let c = a.counts[0];
        assert!(c.grazing > 0);
        assert_eq!(c.beams, c.misses + c.grazing + c.returns + c.dropouts);
        assert_eq!(
            a.scans[0]
                .grid
                .as_ref()
                .unwrap()
                .cells
                .iter()
                .filter(|&&p| p == NO_RETURN)
                .count(),
            c.grazing
        );
        let b = scan_scene(&box_room(), &poses, &settings).unwrap();
        assert_eq!(a.scans, b.scans);
        assert_eq!(a.truth, b.truth);
        settings.seed = 2;
        let other = scan_scene(&box_room(), &poses, &settings).unwrap();
        assert_ne!(a.scans[0].positions, other.scans[0].positions);
    }

    /// |rate − p| within 4 binomial standard errors of `n` trials.
    fn assert_rate(what: &str, events: usize, n: usize, p: f64) {
        assert!(n > 100, "{what}: only {n} trials");
        let rate = events as f64 / n as f64;
        let bound = 4.0 * (p * (1.0 - p) / n as f64).sqrt();
        assert!(
            (rate - p).abs() < bound,
            "{what}: {events}/{n} = {rate}, expected {p} ± {bound}"
        );
    }

    #[test]
    fn the_example_rooms_dropouts_and_mixed_pixels_come_at_their_rates_off_their_surfaces() {
        let scene = room_scene().unwrap();
        let mut settings = ScannerSettings::new(90, 180);
        settings.dropout_probability = 0.1;
        settings.mixed_pixel_probability = 0.3;
        let scans = scan_scene(&scene, &room_poses(), &settings).unwrap();
        let total = scans.counts.iter().fold(BeamCounts::default(), |mut a, c| {
            a.add(c);
            a
        });
        assert_eq!(total.beams, 5 * 90 * 180);
        // Inside a closed room every beam meets a surface.
        assert_eq!(total.misses, 0);
        assert_rate("dropouts", total.dropouts, total.eligible, 0.1);
        assert_rate("mixed pixels", total.mixed, total.edges, 0.3);
        // Mixed pixels are unassigned; every other point is on its
        // surface: a floor point at z = 0 and a ceiling point at z = 3
        // (within 5σ = 15 mm).
        let floor = scans.truth.names.iter().position(|n| n == "floor").unwrap() as u32;
        let ceiling = scans.truth.names.iter().position(|n| n == "ceiling").unwrap() as u32;
        let mut unassigned = 0;
        for (scan, labels) in scans.scans.iter().zip(&scans.truth.labels) {
            for (p, &l) in scan.positions.iter().zip(labels) {
                match l {
                    UNASSIGNED => unassigned += 1,
                    l if l == floor => assert!(p.z.abs() < 0.015, "{p}"),
                    l if l == ceiling => assert!((p.z - 3.0).abs() < 0.015, "{p}"),
                    _ => {}
                }
            }
        }
        assert_eq!(unassigned, total.mixed);
        assert_eq!(scans.truth.sizes().iter().sum::<usize>() + unassigned, total.returns);
    }

    #[test]
    fn the_building_scan_sees_the_towers_south_face_where_it_stands() {
        let scene = building_scene().unwrap();
        let mut settings = ScannerSettings::new(30, 40);
        settings.azimuth_deg = (-20.0, 20.0);
        settings.elevation_deg = (0.0, 70.0);
        let poses: Vec<_> = building_poses().into_iter().filter(|(n, _)| n == "tower-s").collect();
        let scans = scan_scene(&scene, &poses, &settings).unwrap();
        let south = scans.truth.names.iter().position(|n| n == "south-face").unwrap() as u32;
        let on_face: Vec<_> = scans.scans[0]
            .positions
            .iter()
            .zip(&scans.truth.labels[0])
            .filter(|&(_, &l)| l == south)
            .map(|(p, _)| *p)
            .collect();
        assert!(on_face.len() > 100, "{}", on_face.len());
        // The shaft's south face is the plane y = −5.5 below 70 m and the
        // belfry's y = −4 above it.
        for p in &on_face {
            let y = if p.z < 70.0 { -5.5 } else { -4.0 };
            assert!((p.y - y).abs() < 0.015, "{p}");
        }
    }

    #[test]
    fn bad_settings_are_refused_naming_the_setting() {
        let mut settings = ScannerSettings::new(0, 10);
        assert!(matches!(
            settings.check(),
            Err(RangeScanError::Setting { field: "rows", .. })
        ));
        settings.rows = 10;
        settings.dropout_probability = 1.5;
        let e = scan_scene(&box_room(), &[], &settings).unwrap_err();
        assert!(e.to_string().contains("dropout_probability"), "{e}");
        settings.dropout_probability = 0.0;
        settings.range_noise_m = f64::NAN;
        assert!(matches!(
            settings.check(),
            Err(RangeScanError::Setting {
                field: "range_noise_m",
                ..
            })
        ));
    }

    #[test]
    fn written_scans_read_back_with_their_grids_and_poses() {
        let mut settings = ScannerSettings::new(6, 12);
        settings.elevation_deg = (-60.0, 60.0);
        let poses = vec![
            ("a".to_string(), level_pose(Vector3::new(1.0, 1.0, 1.0), 30.0)),
            ("b".to_string(), level_pose(Vector3::new(3.0, 2.0, 1.5), 200.0)),
        ];
        let scans = scan_scene(&box_room(), &poses, &settings).unwrap();
        let dir = tempfile::tempdir().unwrap();
        for format in [ScanFileFormat::Ply, ScanFileFormat::E57] {
            let files = write_scans(dir.path(), "box", &scans, format).unwrap();
            let back: Vec<Scan> = files
                .iter()
                .flat_map(|f| campanile_scan::read::read_scan(f).unwrap())
                .collect();
            assert_eq!(back.len(), 2);
            for (a, b) in scans.scans.iter().zip(&back) {
                assert_eq!(a.name, b.name);
                assert_eq!(a.grid, b.grid);
                assert_eq!(a.intensity, b.intensity);
                let (pa, pb) = (a.pose.unwrap(), b.pose.unwrap());
                assert!((pa.origin - pb.origin).norm() < 1e-12 && pa.rotation.angle_to(&pb.rotation) < 1e-9);
                for (p, q) in a.positions.iter().zip(&b.positions) {
                    assert!((p - q).norm() < 1e-12);
                }
            }
        }
    }
}
