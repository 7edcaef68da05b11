//! Coded targets in the simulated worlds, and photographs of them from
//! free positions, with the true poses kept (thesis §3.3; issue 27).
//!
//! [`with_targets`] hangs AprilTags (tag36h11) on a scene: each a white
//! plate a cell wider than the tag's white frame on every side, its face
//! exactly where the survey ([`Target`]) puts it, painted with the tag's
//! cells ([`Texture::Pattern`]). The survey is the truth; a survey of tags
//! on a wall puts them a little proud of it (the example surveys: 2 mm,
//! a plate's thickness), so that plate and wall do not coincide.
//!
//! [`with_circle_targets`] hangs the thesis's own targets (§3.3): a dark
//! square plate ([`CIRCLE_PLATE`], the thesis's "flat square green
//! patches") with a white circle in the middle ([`Texture::Disc`]), the
//! circle's centre where the survey puts it. [`with_round_window`] hangs
//! a white disc in a square of wall colour: a round window, the false
//! target no survey lists.
//!
//! [`photograph`] renders a view through the world's path tracer (the
//! sun and sky outdoors, the lamps indoors), blurs it by the lens's
//! Gaussian spot, exposes it on the 8-bit [`CameraModel::typical`] sensor
//! (shot and read noise, response curve, quantization) at an automatic
//! exposure scaled by `exposure_scale` (low light: well below 1), and
//! keeps the pose the renderer actually used.

use campanile_config::targets::Target;
use campanile_process::camera::image::RadianceImage;
use campanile_process::camera::sensor::CameraModel;
use campanile_process::pose::Pinhole;
use campanile_process::registration::CameraPose;
use campanile_process::registration::apriltag::{TAG36H11_BORDER_CELLS, tag36h11_cells};
use campanile_process::render::{CameraRig, Material, Scene, Texture, Triangle};
use chrono::{DateTime, Utc};
use nalgebra::Vector3;

use super::truth::Appearance;
use super::{LoadedScene, World, WorldError};

/// Albedo of a tag's white cells and plate, and of its black cells.
pub const TAG_WHITE: [f64; 3] = [0.85, 0.85, 0.85];
/// See [`TAG_WHITE`].
pub const TAG_BLACK: [f64; 3] = [0.04, 0.04, 0.04];

/// Albedo of a circle target's plate: a dark green.
pub const CIRCLE_PLATE: [f64; 3] = [0.03, 0.07, 0.04];

fn vec3(v: (f64, f64, f64)) -> Vector3<f64> {
    Vector3::new(v.0, v.1, v.2)
}

fn geometry_error(message: String) -> WorldError {
    WorldError::Geometry {
        path: "targets".into(),
        message,
    }
}

/// A target's plate: a square of half-side `half` about its centre, as two
/// triangles counter-clockwise seen from the front (the normal faces out),
/// with the plate's right and up axes and its centre.
struct Plate {
    triangles: [Triangle; 2],
    right: Vector3<f64>,
    up: Vector3<f64>,
    centre: Vector3<f64>,
}

fn plate(t: &Target, half: f64, material: u32, surface: u32, what: &str) -> Result<Plate, WorldError> {
    let [right, up, _normal] = t.axes().map(Vector3::from);
    let centre = vec3(t.centre_m);
    let corner = |a: f64, b: f64| centre + right * (a * half) + up * (b * half);
    let (tl, tr, br, bl) = (
        corner(-1.0, 1.0),
        corner(1.0, 1.0),
        corner(1.0, -1.0),
        corner(-1.0, -1.0),
    );
    let pair = [
        Triangle::new([bl, br, tr], material, surface),
        Triangle::new([bl, tr, tl], material, surface),
    ];
    let [Some(a), Some(b)] = pair else {
        return Err(geometry_error(format!("{what} {}: a degenerate plate", t.id)));
    };
    Ok(Plate {
        triangles: [a, b],
        right,
        up,
        centre,
    })
}

/// `scene` with a survey's targets hung on it, of the survey's kind:
/// AprilTags ([`with_targets`]) or the thesis's circles
/// ([`with_circle_targets`]).
pub fn with_survey(
    scene: &LoadedScene,
    survey: &campanile_config::targets::Targets,
) -> Result<LoadedScene, WorldError> {
    match survey.kind {
        campanile_config::targets::TargetKind::Coded => with_targets(scene, &survey.targets),
        campanile_config::targets::TargetKind::Circle(radius_m) => {
            with_circle_targets(scene, &survey.targets, radius_m)
        }
    }
}

/// `scene` with `targets` hung on it (module doc). Targets are flat plates
/// standing free: they need not lie on a surface (a false target can
/// hang in the air in front of the wall it pretends to be on).
pub fn with_targets(scene: &LoadedScene, targets: &[Target]) -> Result<LoadedScene, WorldError> {
    let mut triangles: Vec<Triangle> = scene.scene.triangles().to_vec();
    let mut materials: Vec<Material> = scene.scene.materials().to_vec();
    let mut surfaces: Vec<String> = scene.scene.surfaces().to_vec();
    let mut appearances = scene.appearances.clone();
    let surface = surfaces.len() as u32;
    surfaces.push("targets".into());
    for t in targets {
        let (width, cells) =
            tag36h11_cells(t.id).ok_or_else(|| geometry_error(format!("target {}: not a tag36h11 id", t.id)))?;
        let cell = t.size_m / TAG36H11_BORDER_CELLS as f64;
        let half = 0.5 * (width as f64 + 2.0) * cell;
        let Plate {
            triangles: [a, b],
            right,
            up,
            centre,
        } = plate(t, half, materials.len() as u32, surface, "target")?;
        // The pattern's axes in the face's texture axes (s, t).
        let [s_axis, t_axis] = a.texture_axes;
        let texture = Texture::Pattern {
            centre_st: [centre.dot(&s_axis), centre.dot(&t_axis)],
            axes: [
                [right.dot(&s_axis), right.dot(&t_axis)],
                [up.dot(&s_axis), up.dot(&t_axis)],
            ],
            cell_m: cell,
            width,
            cells,
            black: TAG_BLACK,
            white: TAG_WHITE,
        };
        triangles.extend([a, b]);
        materials.push(Material {
            name: format!("target-{}", t.id),
            albedo: texture.clone(),
            specular: None,
            emission: [0.0; 3],
        });
        appearances.push(Appearance::diffuse(texture));
    }
    let scene_out = Scene::new(triangles, materials, surfaces).map_err(|e| geometry_error(e.to_string()))?;
    Ok(LoadedScene {
        description: scene.description.clone(),
        scene: scene_out,
        appearances,
    })
}

/// `scene` with circle targets of radius `radius_m` hung on it (module
/// doc): each target's plate of side `size_m`, centred on `centre_m`,
/// facing `normal`. Like [`with_targets`], plates stand free.
pub fn with_circle_targets(scene: &LoadedScene, targets: &[Target], radius_m: f64) -> Result<LoadedScene, WorldError> {
    hang_discs(scene, targets, radius_m, TAG_WHITE, CIRCLE_PLATE, "circle-targets")
}

/// `scene` with a round window of radius `radius_m` in a square of wall
/// (`wall` albedo, side `window.size_m`) where `window` says: a white
/// disc no survey lists and no dark plate surrounds, the thesis's hard
/// case of a false target (issue 27).
pub fn with_round_window(
    scene: &LoadedScene,
    window: &Target,
    radius_m: f64,
    wall: [f64; 3],
) -> Result<LoadedScene, WorldError> {
    hang_discs(
        scene,
        std::slice::from_ref(window),
        radius_m,
        TAG_WHITE,
        wall,
        "round-windows",
    )
}

/// `scene` with a disc of albedo `inside` on a square plate of albedo
/// `outside` at each of `targets`, in a new surface `surface_name`.
fn hang_discs(
    scene: &LoadedScene,
    targets: &[Target],
    radius_m: f64,
    inside: [f64; 3],
    outside: [f64; 3],
    surface_name: &str,
) -> Result<LoadedScene, WorldError> {
    let mut triangles: Vec<Triangle> = scene.scene.triangles().to_vec();
    let mut materials: Vec<Material> = scene.scene.materials().to_vec();
    let mut surfaces: Vec<String> = scene.scene.surfaces().to_vec();
    let mut appearances = scene.appearances.clone();
    let surface = surfaces.len() as u32;
    surfaces.push(surface_name.into());
    for t in targets {
        if !(t.size_m > 2.0 * radius_m && radius_m > 0.0) {
            return Err(geometry_error(format!(
                "circle target {}: a plate of {} m cannot hold a circle of radius {radius_m} m",
                t.id, t.size_m
            )));
        }
        let Plate {
            triangles: [a, b],
            centre,
            ..
        } = plate(t, 0.5 * t.size_m, materials.len() as u32, surface, "circle target")?;
        let [s_axis, t_axis] = a.texture_axes;
        let texture = Texture::Disc {
            centre_st: [centre.dot(&s_axis), centre.dot(&t_axis)],
            radius_m,
            plate_m: t.size_m,
            inside,
            outside,
        };
        triangles.extend([a, b]);
        materials.push(Material {
            name: format!("{surface_name}-{}", t.id),
            albedo: texture.clone(),
            specular: None,
            emission: [0.0; 3],
        });
        appearances.push(Appearance::diffuse(texture));
    }
    let scene_out = Scene::new(triangles, materials, surfaces).map_err(|e| geometry_error(e.to_string()))?;
    Ok(LoadedScene {
        description: scene.description.clone(),
        scene: scene_out,
        appearances,
    })
}

/// How a target photograph is taken.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhotoSettings {
    /// The lens (its focal length, principal point and distortion).
    pub pinhole: Pinhole,
    /// Image width, pixels.
    pub width: usize,
    /// Image height, pixels.
    pub height: usize,
    /// The time (the sun and sky outdoors).
    pub time: DateTime<Utc>,
    /// Lamp levels indoors (0–1, in the station's order).
    pub light_levels: [f64; 4],
    /// Gaussian blur of the lens, pixels (standard deviation); 0 for none.
    pub blur_px: f64,
    /// The exposure relative to one that puts the brightest 1% of pixels
    /// at 80% of full well: 1 for a well-exposed photo, 0.02 for low light.
    pub exposure_scale: f64,
    /// Seed of the render and of the sensor noise.
    pub seed: u64,
}

/// A simulated photograph and its truth.
#[derive(Debug, Clone, PartialEq)]
pub struct TargetPhoto {
    /// The 8-bit codes, RGB interleaved, `width · height · 3`.
    pub rgb: Vec<u8>,
    /// Width, pixels.
    pub width: usize,
    /// Height, pixels.
    pub height: usize,
    /// The pose the renderer used.
    pub pose: CameraPose,
    /// The exposure time, seconds.
    pub exposure_s: f64,
}

impl TargetPhoto {
    /// The photo in gray: the mean of the three channels' codes.
    pub fn gray(&self) -> Vec<u8> {
        self.rgb
            .chunks_exact(3)
            .map(|p| ((u16::from(p[0]) + u16::from(p[1]) + u16::from(p[2]) + 1) / 3) as u8)
            .collect()
    }
}

/// The camera at `centre` looking along `look` with the image's up toward
/// `up` (made orthogonal to `look`): the pose a photographer holds.
pub fn pose_looking(centre: [f64; 3], look: [f64; 3], up: [f64; 3]) -> Option<CameraPose> {
    let forward = Vector3::from(look).try_normalize(1e-12)?;
    let right = forward.cross(&Vector3::from(up)).try_normalize(1e-12)?;
    let down = forward.cross(&right);
    Some(CameraPose::from_axes(right, down, forward, Vector3::from(centre)))
}

/// A separable Gaussian blur of standard deviation `sigma` pixels, the
/// kernel cut at 3σ and renormalized at the borders.
fn blurred(image: &RadianceImage, sigma: f64) -> RadianceImage {
    if sigma <= 0.0 {
        return image.clone();
    }
    let r = (3.0 * sigma).ceil() as isize;
    let kernel: Vec<f64> = (-r..=r).map(|i| (-0.5 * (i as f64 / sigma).powi(2)).exp()).collect();
    let (w, h) = (image.width as isize, image.height as isize);
    let pass = |src: &[f32], horizontal: bool| -> Vec<f32> {
        let mut out = vec![0f32; src.len()];
        for y in 0..h {
            for x in 0..w {
                let mut acc = [0.0f64; 3];
                let mut wsum = 0.0;
                for (k, kv) in kernel.iter().enumerate() {
                    let d = k as isize - r;
                    let (xx, yy) = if horizontal { (x + d, y) } else { (x, y + d) };
                    if xx < 0 || yy < 0 || xx >= w || yy >= h {
                        continue;
                    }
                    let i = ((yy * w + xx) * 3) as usize;
                    (0..3).for_each(|c| acc[c] += kv * f64::from(src[i + c]));
                    wsum += kv;
                }
                let o = ((y * w + x) * 3) as usize;
                (0..3).for_each(|c| out[o + c] = (acc[c] / wsum) as f32);
            }
        }
        out
    };
    let data = pass(&pass(&image.data, true), false);
    RadianceImage {
        width: image.width,
        height: image.height,
        data,
    }
}

/// Photographs `world` from `pose` (module doc).
pub fn photograph(world: &World, pose: &CameraPose, settings: &PhotoSettings) -> Result<TargetPhoto, WorldError> {
    let m = pose.rotation.matrix();
    let forward = m.row(2).transpose();
    let down = m.row(1).transpose();
    let mut rig = CameraRig::look_at(pose.centre, forward, -down, 1.0, settings.width, settings.height)
        .ok_or_else(|| geometry_error("a degenerate camera pose".into()))?;
    rig.pinhole = settings.pinhole;
    // The pose the rig actually has: its axes through the mount.
    let oriented = rig.mount.at(rig.head);
    let axis = |d: [f64; 3]| Vector3::from(oriented.to_world(d));
    let truth = CameraPose::from_axes(
        axis([1.0, 0.0, 0.0]),
        axis([0.0, 1.0, 0.0]),
        axis([0.0, 0.0, 1.0]),
        pose.centre,
    );
    let radiance = world.render(settings.time, &rig, &settings.light_levels, settings.seed)?;
    let sensor_radiance = blurred(&radiance, settings.blur_px);
    let model = CameraModel::typical(8);
    // Automatic exposure: the 99th percentile of the green channel at 80% of full well.
    let mut green: Vec<f32> = sensor_radiance.data.chunks_exact(3).map(|p| p[1]).collect();
    green.sort_by(f32::total_cmp);
    let p99 = f64::from(green[(green.len() * 99 / 100).min(green.len() - 1)]).max(1e-12);
    let exposure_s = 0.8 / (p99 * model.sensor.gain[1]) * settings.exposure_scale;
    let codes = model.photograph(&sensor_radiance, exposure_s, settings.seed ^ 0x9e37_79b9);
    Ok(TargetPhoto {
        rgb: codes.data.iter().map(|c| (*c).min(255) as u8).collect(),
        width: settings.width,
        height: settings.height,
        pose: truth,
        exposure_s,
    })
}
