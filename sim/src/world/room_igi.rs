//! The simulated room (thesis §4.7.2) as inverse global illumination sees
//! it: the room's geometry grouped by material (the groups that share
//! specular parameters), the station's lamps, cameras at the scene's poses,
//! and photographs by [`photograph`] (exact direct light, path-traced
//! interreflection).

use std::path::Path;

use campanile_process::brdf::WardMaterial;
use campanile_process::camera::image::RadianceImage;
use campanile_process::igi::{IgiInput, IgiLight, View, ViewCamera};
use campanile_process::render::{PointLight, Scene, SphereLight, Triangle};
use nalgebra::Vector3;

use super::igi_photograph::{PhotoSettings, photograph};
use super::scene_file::{LoadedScene, load_scene};
use super::{MIN_BULB_RADIUS_M, WorldError};

/// The room, its lamps and its true materials.
#[derive(Debug, Clone)]
pub struct RoomIgi {
    /// The scene with its true materials (surfaces are the OBJ groups'
    /// scene surfaces; materials the shared-specular groups).
    pub loaded: LoadedScene,
    /// The station's lamps (name, bulb at full level).
    pub lamps: Vec<(String, SphereLight)>,
}

/// The camera at a scene pose: azimuth from north through east, elevation
/// above the horizon, z up.
pub fn pose_camera(
    pose: &campanile_config::scene::CameraPose,
    vfov_deg: f64,
    width: usize,
    height: usize,
) -> ViewCamera {
    let (az, el) = (pose.azimuth_deg.to_radians(), pose.elevation_deg.to_radians());
    let (x, y, z) = pose.position_m;
    ViewCamera {
        position: Vector3::new(x, y, z),
        look: Vector3::new(az.sin() * el.cos(), az.cos() * el.cos(), el.sin()),
        up: Vector3::z(),
        vfov_rad: vfov_deg.to_radians(),
        width,
        height,
    }
}

impl RoomIgi {
    /// The room of scene file `scene` lit by the lamps of `station`.
    pub fn load(scene: &Path, station: &campanile_config::Station) -> Result<RoomIgi, WorldError> {
        let loaded = load_scene(scene)?;
        let lamps = station
            .lights
            .iter()
            .flat_map(|l| l.channels.iter())
            .map(|ch| {
                let (x, y, z) = ch.position_m;
                let (r, g, b) = ch.intensity.radiant_intensity_w_sr;
                (
                    ch.name.clone(),
                    SphereLight::with_intensity(Vector3::new(x, y, z), ch.radius_m.max(MIN_BULB_RADIUS_M), [r, g, b]),
                )
            })
            .collect();
        Ok(RoomIgi { loaded, lamps })
    }

    /// The example room: `examples/room-scene.ron` lit by the lamps of
    /// `examples/sim-station.ron`.
    pub fn example() -> Result<RoomIgi, WorldError> {
        let path = super::scene_file::examples_dir().join("sim-station.ron");
        let station = campanile_config::document::load_station(&path).map_err(|e| WorldError::Config {
            path: path.clone(),
            message: e.to_string(),
        })?;
        RoomIgi::load(
            &super::scene_file::examples_dir().join("room-scene.ron"),
            &station.value,
        )
    }

    /// The solver's views of the room used by the test, the budget example
    /// and the helper's runs: a wide view at each scene pose (60°,
    /// `width` × `height`), the highlight views (20°, `width / 2` square),
    /// the ceiling views (60° at [`CEILING_ELEVATION_DEG`]) and, last (so
    /// that the earlier views' photographs keep their seeds), the
    /// highlight views from free positions of [`RoomIgi::mirror_cameras`]
    /// (the metal sphere's). The first is the wide view `wide-sw`, the
    /// relighting check's camera. ([`RoomIgi::write_scene_file`] writes
    /// the free-position views too, last; the demo's capture has none.)
    pub fn solver_cameras(&self, width: usize, height: usize) -> Vec<(String, ViewCamera)> {
        let mut cams = self.cameras(60.0, width, height);
        cams.extend(self.highlight_cameras(20.0, width / 2));
        cams.extend(self.ceiling_cameras(CEILING_ELEVATION_DEG, 60.0, width, height));
        cams.extend(self.mirror_cameras(20.0, width / 2, MIRROR_CAMERA_DISTANCE_M));
        cams
    }

    /// The render scene with the true materials.
    pub fn scene(&self) -> &Scene {
        &self.loaded.scene
    }

    /// Names of the groups that share specular parameters (the scene's
    /// materials), which are the solver's surfaces.
    pub fn material_names(&self) -> Vec<String> {
        self.loaded.scene.materials().iter().map(|m| m.name.clone()).collect()
    }

    /// The true BRDF of each material, its texture's mean albedo as ρd.
    pub fn true_materials(&self) -> Result<Vec<WardMaterial>, WorldError> {
        self.loaded
            .appearances
            .iter()
            .map(|a| {
                Ok(WardMaterial {
                    rho_d: a.albedo.mean_albedo(),
                    lobe: a.lobe().map_err(|e| WorldError::Config {
                        path: "room truth".into(),
                        message: e.to_string(),
                    })?,
                })
            })
            .collect()
    }

    /// The triangles as the solver takes them: `surface` is the material
    /// index (the group sharing one BRDF).
    pub fn igi_triangles(&self) -> Vec<Triangle> {
        igi_triangles_of(&self.loaded.scene)
    }

    /// The named cameras at the scene's poses, `width` × `height`, vertical
    /// field of view `vfov_deg`.
    pub fn cameras(&self, vfov_deg: f64, width: usize, height: usize) -> Vec<(String, ViewCamera)> {
        self.loaded
            .description
            .poses
            .iter()
            .map(|p| (p.name.clone(), pose_camera(p, vfov_deg, width, height)))
            .collect()
    }

    /// Views of the ceiling (which the scene's poses, looking down, barely
    /// see, yet which reflects most of the lamps' light into the room): from
    /// each pose position, the pose's azimuth at `elevation_deg` above the horizon.
    pub fn ceiling_cameras(
        &self,
        elevation_deg: f64,
        vfov_deg: f64,
        width: usize,
        height: usize,
    ) -> Vec<(String, ViewCamera)> {
        self.loaded
            .description
            .poses
            .iter()
            .map(|p| {
                let up = campanile_config::scene::CameraPose {
                    elevation_deg,
                    ..p.clone()
                };
                (format!("{}-up", p.name), pose_camera(&up, vfov_deg, width, height))
            })
            .collect()
    }

    /// The lamps as the solver takes them (true positions, radii, intensities).
    pub fn igi_lights(&self) -> Vec<IgiLight> {
        let bulbs: Vec<SphereLight> = self.lamps.iter().map(|(_, b)| *b).collect();
        igi_lights_of(&bulbs)
    }

    /// One photograph of the room lit by `bulbs` (visible in view) and
    /// `points` (invisible), with the true materials.
    pub fn photograph(
        &self,
        bulbs: &[SphereLight],
        points: &[PointLight],
        camera: &ViewCamera,
        settings: &PhotoSettings,
    ) -> RadianceImage {
        photograph(&self.loaded.scene, points, bulbs, camera, settings)
    }

    /// The solver's input: every lamp on, the views `cameras` (for
    /// example [`RoomIgi::cameras`] and [`RoomIgi::highlight_cameras`]).
    pub fn igi_input(&self, cameras: Vec<(String, ViewCamera)>, settings: &PhotoSettings) -> IgiInput {
        let bulbs: Vec<SphereLight> = self.lamps.iter().map(|(_, b)| *b).collect();
        let views = cameras
            .into_iter()
            .enumerate()
            .map(|(k, (name, camera))| View {
                name,
                camera,
                image: self.photograph(
                    &bulbs,
                    &[],
                    &camera,
                    &PhotoSettings {
                        seed: settings.seed.wrapping_add(k as u64 * 1000),
                        ..*settings
                    },
                ),
                mask: None,
            })
            .collect();
        IgiInput {
            triangles: self.igi_triangles(),
            surfaces: self.material_names(),
            lights: self.igi_lights(),
            views,
        }
    }
}

impl RoomIgi {
    /// Highlight views (as §4.7.1's zoomed views): for each lamp and each
    /// scene surface whose true material has a specular lobe, the first
    /// scene pose position (in file order) from which the lamp's mirror
    /// reflection on one of the surface's triangles is visible and lit;
    /// a camera there aimed at that point, `px` square, `vfov_deg` wide.
    pub fn highlight_cameras(&self, vfov_deg: f64, px: usize) -> Vec<(String, ViewCamera)> {
        let scene = &self.loaded.scene;
        let positions: Vec<Vector3<f64>> = self
            .loaded
            .description
            .poses
            .iter()
            .map(|p| Vector3::new(p.position_m.0, p.position_m.1, p.position_m.2))
            .collect();
        let mut out = Vec::new();
        for (lamp, bulb) in &self.lamps {
            for (s, surface) in scene.surfaces().iter().enumerate() {
                let found = positions.iter().find_map(|p| {
                    scene
                        .triangles()
                        .iter()
                        .filter(|t| t.surface as usize == s)
                        .find_map(|t| {
                            scene.materials()[t.material as usize].specular?;
                            let n = t.normal;
                            let (dp, dl) = ((p - t.vertices[0]).dot(&n), (bulb.center - t.vertices[0]).dot(&n));
                            if dp * dl <= 0.0 || dp.abs() < 1e-6 {
                                return None;
                            }
                            // The lamp mirrored in the plane, joined to the camera.
                            let mirrored = bulb.center - n * (2.0 * dl);
                            let k = dp / (dp - (mirrored - t.vertices[0]).dot(&n));
                            let m = p + (mirrored - p) * k;
                            let (e1, e2, q) = (
                                t.vertices[1] - t.vertices[0],
                                t.vertices[2] - t.vertices[0],
                                m - t.vertices[0],
                            );
                            let (d11, d12, d22) = (e1.dot(&e1), e1.dot(&e2), e2.dot(&e2));
                            let (q1, q2) = (q.dot(&e1), q.dot(&e2));
                            let det = d11 * d22 - d12 * d12;
                            let u = (d22 * q1 - d12 * q2) / det;
                            let v = (d11 * q2 - d12 * q1) / det;
                            let inside = u > 0.02 && v > 0.02 && u + v < 0.98;
                            let lift = m + n * dp.signum() * 1e-4;
                            (inside && scene.segment_clear(p, &lift) && scene.segment_clear(&bulb.center, &lift))
                                .then_some((*p, m))
                        })
                });
                if let Some((p, m)) = found {
                    out.push((
                        format!("highlight-{surface}-{lamp}"),
                        ViewCamera {
                            position: p,
                            look: m - p,
                            up: Vector3::z(),
                            vfov_rad: vfov_deg.to_radians(),
                            width: px,
                            height: px,
                        },
                    ));
                }
            }
        }
        out
    }
}

/// The triangles of `scene` as inverse global illumination takes them:
/// each triangle's surface is its material (the solver's surfaces are the
/// groups that share specular parameters); the true room's
/// ([`RoomIgi::igi_triangles`]) or one rebuilt from scans.
pub fn igi_triangles_of(scene: &Scene) -> Vec<Triangle> {
    scene
        .triangles()
        .iter()
        .map(|t| Triangle {
            surface: t.material,
            ..*t
        })
        .collect()
}

/// Distance from a highlight to the camera of [`RoomIgi::mirror_cameras`], metres.
pub const MIRROR_CAMERA_DISTANCE_M: f64 = 1.2;

impl RoomIgi {
    /// Highlight views from free positions, for the glossy surfaces whose
    /// highlight no scene pose sees ([`RoomIgi::highlight_cameras`] finds
    /// none for them: the metal sphere, whose flat facets mirror each lamp
    /// toward a few directions only). For each lamp and each such surface,
    /// the first of its triangles (in file order) that the lamp lights, at
    /// whose centre the lamp's mirror direction, followed `distance_m`,
    /// reaches a free point of the room with a clear view back: a camera
    /// there aimed at that centre, `px` square, `vfov_deg` wide. Without
    /// them the solver cannot measure such a surface's lobe and keeps it
    /// diffuse, and the room relit under new lamps lacks the light the
    /// lobe throws on the walls (BENCHMARKS.md: the metal sphere's
    /// reflections of the lamps, about 4.8 % per 4×4 block on the paint).
    pub fn mirror_cameras(&self, vfov_deg: f64, px: usize, distance_m: f64) -> Vec<(String, ViewCamera)> {
        let scene = &self.loaded.scene;
        let seen: Vec<String> = self
            .highlight_cameras(vfov_deg, px)
            .into_iter()
            .map(|(name, _)| name)
            .collect();
        let mut out = Vec::new();
        for (lamp, bulb) in &self.lamps {
            for (s, surface) in scene.surfaces().iter().enumerate() {
                let name = format!("highlight-{surface}-{lamp}");
                if seen.contains(&name) {
                    continue;
                }
                let found = scene
                    .triangles()
                    .iter()
                    .filter(|t| t.surface as usize == s)
                    .find_map(|t| {
                        scene.materials()[t.material as usize].specular?;
                        let c = (t.vertices[0] + t.vertices[1] + t.vertices[2]) / 3.0;
                        let to_lamp = (bulb.center - c).normalize();
                        let n = t.normal;
                        let cos = to_lamp.dot(&n);
                        let mirror = n * (2.0 * cos) - to_lamp;
                        // Lit, and a look direction not along "up".
                        if cos <= 0.1 || mirror.z.abs() > 0.95 {
                            return None;
                        }
                        let lift = c + n * 1e-4;
                        let p = c + mirror * distance_m;
                        (scene.segment_clear(&lift, &bulb.center) && scene.segment_clear(&lift, &p)).then_some((p, c))
                    });
                if let Some((p, c)) = found {
                    out.push((
                        format!("{name}-free"),
                        ViewCamera {
                            position: p,
                            look: c - p,
                            up: Vector3::z(),
                            vfov_rad: vfov_deg.to_radians(),
                            width: px,
                            height: px,
                        },
                    ));
                }
            }
        }
        out
    }
}

/// Pixel side of the blocks over which relit images are compared.
pub const RELIT_BLOCK_PX: usize = 4;

/// Two lamps that no capture of the room uses (the relighting check):
/// warm at (2.0, 2.2, 2.4) m, cool at (3.6, 2.8, 2.0) m, both 5 cm bulbs.
pub fn new_lamps() -> [SphereLight; 2] {
    [
        SphereLight::with_intensity(Vector3::new(2.0, 2.2, 2.4), 0.05, [2.5, 2.4, 2.0]),
        SphereLight::with_intensity(Vector3::new(3.6, 2.8, 2.0), 0.05, [1.4, 1.7, 2.3]),
    ]
}

/// `bulbs` as the solver's and the relighting renderer's lights (the same
/// position, radius and radiant intensity).
pub fn igi_lights_of(bulbs: &[SphereLight]) -> Vec<IgiLight> {
    bulbs
        .iter()
        .map(|b| IgiLight {
            position: b.center,
            radius: b.radius,
            intensity: b.radiance.map(|l| l * std::f64::consts::PI * b.radius * b.radius),
        })
        .collect()
}

/// The relit check's error of `image` against `reference`: the relative
/// RMSE ([`campanile_process::igi::relight::relative_rmse`]) of their
/// [`RELIT_BLOCK_PX`]-pixel block means, over the blocks whose reference
/// red is below 20 W sr⁻¹ m⁻² (no bulb in them); `None` when no block
/// counts or the sizes differ.
pub fn relit_block_error(image: &RadianceImage, reference: &RadianceImage) -> Option<f64> {
    let (a, r) = (
        block_average(image, RELIT_BLOCK_PX),
        block_average(reference, RELIT_BLOCK_PX),
    );
    campanile_process::igi::relight::relative_rmse(&a, &r, |i| r.data[i * 3] < 20.0)
}

/// `image` averaged over `k × k` pixel blocks (a partial block at the edge
/// is dropped): comparisons of path-traced images at the scale where
/// their Monte Carlo noise has averaged out.
pub fn block_average(image: &RadianceImage, k: usize) -> RadianceImage {
    let k = k.max(1);
    let (w, h) = (image.width / k, image.height / k);
    let mut data = vec![0f32; w * h * 3];
    for y in 0..h {
        for x in 0..w {
            for c in 0..3 {
                let mut s = 0.0f64;
                for dy in 0..k {
                    for dx in 0..k {
                        s += f64::from(image.radiance(x * k + dx, y * k + dy, c));
                    }
                }
                data[(y * w + x) * 3 + c] = (s / (k * k) as f64) as f32;
            }
        }
    }
    RadianceImage {
        width: w,
        height: h,
        data,
    }
}

impl RoomIgi {
    /// The albedo map of solver surface `surface` (a material index)
    /// against the true texture: the median over seen texels of the
    /// relative error of the mean over channels, and the texel count.
    pub fn albedo_map_error(
        &self,
        map: &campanile_process::igi::albedo_map::AlbedoMap,
        surface: usize,
    ) -> (f64, usize) {
        let mut errs = self.albedo_map_relative_errors(map, surface);
        if errs.is_empty() {
            return (f64::NAN, 0);
        }
        for e in &mut errs {
            *e = e.abs();
        }
        errs.sort_by(f64::total_cmp);
        (errs[errs.len() / 2], errs.len())
    }

    /// The albedo map's bias on solver surface `surface`: the median over
    /// seen texels of the signed relative error of the mean over channels
    /// (`NaN` when no texel was seen).
    pub fn albedo_map_bias(&self, map: &campanile_process::igi::albedo_map::AlbedoMap, surface: usize) -> f64 {
        let mut errs = self.albedo_map_relative_errors(map, surface);
        if errs.is_empty() {
            return f64::NAN;
        }
        errs.sort_by(f64::total_cmp);
        errs[errs.len() / 2]
    }

    /// Signed relative error of the mean over channels, per seen texel.
    fn albedo_map_relative_errors(
        &self,
        map: &campanile_process::igi::albedo_map::AlbedoMap,
        surface: usize,
    ) -> Vec<f64> {
        self.albedo_map_pairs(map, surface)
            .into_iter()
            .map(|(got, want)| got / want - 1.0)
            .collect()
    }

    /// Whether the albedo map keeps the true texture on solver surface
    /// `surface`: the Pearson correlation over seen texels between the
    /// map's and the true texture's mean over channels (1: the texture's
    /// pattern kept up to a scale; `NaN` for a texture without variation,
    /// or fewer than two texels).
    pub fn albedo_map_texture_correlation(
        &self,
        map: &campanile_process::igi::albedo_map::AlbedoMap,
        surface: usize,
    ) -> f64 {
        let pairs = self.albedo_map_pairs(map, surface);
        let n = pairs.len() as f64;
        if pairs.len() < 2 {
            return f64::NAN;
        }
        let (ma, mb) = (
            pairs.iter().map(|p| p.0).sum::<f64>() / n,
            pairs.iter().map(|p| p.1).sum::<f64>() / n,
        );
        let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
        for (a, b) in &pairs {
            sab += (a - ma) * (b - mb);
            saa += (a - ma) * (a - ma);
            sbb += (b - mb) * (b - mb);
        }
        // A constant texture's f32 round-off is no variation.
        if saa > 0.0 && sbb > 1e-9 * n * mb * mb {
            sab / (saa * sbb).sqrt()
        } else {
            f64::NAN
        }
    }

    /// Per seen texel of solver surface `surface`: the map's and the true
    /// texture's albedo (at the texel centre), each the mean over channels.
    fn albedo_map_pairs(&self, map: &campanile_process::igi::albedo_map::AlbedoMap, surface: usize) -> Vec<(f64, f64)> {
        let Some(appearance) = self.loaded.appearances.get(surface) else {
            return Vec::new();
        };
        let mut out = Vec::new();
        for (tri, texels) in self.loaded.scene.triangles().iter().zip(&map.triangles) {
            if tri.material as usize != surface {
                continue;
            }
            for j in 0..texels.size[1] {
                for i in 0..texels.size[0] {
                    let k = j * texels.size[0] + i;
                    if texels.weight[k] <= 0.0 {
                        continue;
                    }
                    let st = [
                        texels.origin[0] + (i as f64 + 0.5) * map.texel_m,
                        texels.origin[1] + (j as f64 + 0.5) * map.texel_m,
                    ];
                    let t = appearance.albedo.albedo(st);
                    let got: f64 = texels.albedo[k].iter().map(|v| f64::from(*v)).sum::<f64>() / 3.0;
                    let want: f64 = t.iter().sum::<f64>() / 3.0;
                    out.push((got, want));
                }
            }
        }
        out
    }
}

/// Scattering events per light path in the room's photographs and in the
/// renders compared with them. The room is a closed box whose paint
/// reflects 70 %: its light falls by a factor of about 0.6 per bounce
/// (measured: a wide view gains 15 % from 4 to 16 events), so paths cut
/// after 4 events miss about 13 % of the light, and a solver that gathers
/// one more bounce from the photographed radiance than the photographs
/// hold then recovers ρd 5–14 % low (`examples/igi_room_budget.rs`). After
/// 12 events the missing light is 0.6¹² ≈ 0.2 %.
pub const ROOM_BOUNCES: u32 = 12;

/// Elevation of the ceiling views, degrees.
pub const CEILING_ELEVATION_DEG: f64 = 35.0;

/// What [`RoomIgi::write_scene_file`] photographs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SceneFileShot {
    /// Vertical field of view of the wide views, degrees.
    pub wide_vfov_deg: f64,
    /// Wide views' width and height, pixels.
    pub wide_px: (usize, usize),
    /// Highlight views' field of view (degrees) and side (pixels).
    pub highlight: (f64, usize),
    /// Bulb views' field of view (degrees) and side (pixels).
    pub bulb: (f64, usize),
    /// Noise against time of every photograph.
    pub photo: PhotoSettings,
}

impl Default for SceneFileShot {
    fn default() -> Self {
        SceneFileShot {
            wide_vfov_deg: 60.0,
            wide_px: (96, 72),
            highlight: (20.0, 40),
            bulb: (8.0, 64),
            photo: PhotoSettings {
                indirect_samples: 16,
                max_bounces: ROOM_BOUNCES,
                seed: 7,
            },
        }
    }
}

fn write_exr(image: &RadianceImage, path: &Path) -> Result<(), WorldError> {
    let map = campanile_process::hdr::merge::RadianceMap {
        width: image.width,
        height: image.height,
        rgb: image.data.clone(),
        variance: vec![0.0; image.data.len()],
        mask: vec![0; image.width * image.height],
    };
    campanile_process::exr_io::write_radiance_exr(&map, path).map_err(|e| WorldError::Config {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}

impl RoomIgi {
    /// Photographs the room and writes a `campanile igi` scene file
    /// (`dir/scene.ron`, the OBJ beside it, EXR images under `dir/images`):
    /// every lamp on, seen from the scene's poses, the highlight views,
    /// the ceiling views and the free-position highlight views; each lamp given by three HDR images of its bulb (lit alone),
    /// from the first three pose positions, to be triangulated. Returns the
    /// scene file's path.
    pub fn write_scene_file(&self, dir: &Path, shot: &SceneFileShot) -> Result<std::path::PathBuf, WorldError> {
        use std::fmt::Write as _;
        let io = |p: &Path, e: std::io::Error| WorldError::Config {
            path: p.to_path_buf(),
            message: e.to_string(),
        };
        let images = dir.join("images");
        std::fs::create_dir_all(&images).map_err(|e| io(&images, e))?;
        let obj_src = super::scene_file::examples_dir().join(&self.loaded.description.geometry);
        let obj = dir.join("room.obj");
        std::fs::copy(&obj_src, &obj).map_err(|e| io(&obj_src, e))?;
        let mut cams = self.cameras(shot.wide_vfov_deg, shot.wide_px.0, shot.wide_px.1);
        cams.extend(self.highlight_cameras(shot.highlight.0, shot.highlight.1));
        cams.extend(self.ceiling_cameras(
            CEILING_ELEVATION_DEG,
            shot.wide_vfov_deg,
            shot.wide_px.0,
            shot.wide_px.1,
        ));
        cams.extend(self.mirror_cameras(shot.highlight.0, shot.highlight.1, MIRROR_CAMERA_DISTANCE_M));
        let mut text = String::from(
            "// Written by the simulator: the room with every lamp on.\nIgiScene(\n    geometry: \"room.obj\",\n    surfaces: [\n",
        );
        for m in self.material_names() {
            let groups: Vec<String> = self
                .loaded
                .description
                .surfaces
                .iter()
                .filter(|s| s.material == m)
                .flat_map(|s| s.groups.iter().map(|g| format!("{g:?}")))
                .collect();
            let _ = writeln!(text, "        (name: {m:?}, groups: [{}]),", groups.join(", "));
        }
        text.push_str("    ],\n    cameras: [\n");
        let cam_line = |text: &mut String, name: &str, c: &ViewCamera| {
            let _ = writeln!(
                text,
                "        (name: {name:?}, position_m: ({:?}, {:?}, {:?}), look: ({:?}, {:?}, {:?}), up: (0.0, 0.0, 1.0), vfov_deg: {:?}, width: {}, height: {}),",
                c.position.x,
                c.position.y,
                c.position.z,
                c.look.x,
                c.look.y,
                c.look.z,
                c.vfov_rad.to_degrees(),
                c.width,
                c.height
            );
        };
        for (n, c) in &cams {
            cam_line(&mut text, n, c);
        }
        // Bulb views.
        let positions: Vec<Vector3<f64>> = cams.iter().take(3).map(|(_, c)| c.position).collect();
        let mut bulb_entries = String::new();
        for (lamp, bulb) in &self.lamps {
            let mut entries = Vec::new();
            for (k, p) in positions.iter().enumerate() {
                let name = format!("bulb-{lamp}-{k}");
                let cam = ViewCamera {
                    position: *p,
                    look: bulb.center - p,
                    up: Vector3::z(),
                    vfov_rad: shot.bulb.0.to_radians(),
                    width: shot.bulb.1,
                    height: shot.bulb.1,
                };
                cam_line(&mut text, &name, &cam);
                let img = self.photograph(
                    std::slice::from_ref(bulb),
                    &[],
                    &cam,
                    &PhotoSettings {
                        indirect_samples: 0,
                        max_bounces: 1,
                        ..shot.photo
                    },
                );
                let file = format!("images/{name}.exr");
                write_exr(&img, &dir.join(&file))?;
                entries.push(format!("(camera: {name:?}, image: {file:?})"));
            }
            let _ = writeln!(
                bulb_entries,
                "        Bulb(name: {lamp:?}, images: [{}]),",
                entries.join(", ")
            );
        }
        text.push_str("    ],\n    lights: [\n");
        text.push_str(&bulb_entries);
        text.push_str("    ],\n    images: [\n");
        let bulbs: Vec<SphereLight> = self.lamps.iter().map(|(_, b)| *b).collect();
        for (k, (n, c)) in cams.iter().enumerate() {
            let img = self.photograph(
                &bulbs,
                &[],
                c,
                &PhotoSettings {
                    seed: shot.photo.seed.wrapping_add(k as u64 * 1000),
                    ..shot.photo
                },
            );
            let file = format!("images/{n}.exr");
            write_exr(&img, &dir.join(&file))?;
            let _ = writeln!(text, "        (camera: {n:?}, image: {file:?}),");
        }
        text.push_str("    ],\n)\n");
        let path = dir.join("scene.ron");
        std::fs::write(&path, text).map_err(|e| io(&path, e))?;
        Ok(path)
    }
}
