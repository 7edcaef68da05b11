//! Photographs with an exact radiance truth, for texture maps (thesis
//! §3.4; issue 27): the example building floodlit at night by point lamps,
//! direct light only. Every surface is Lambertian, so its radiance is the
//! same from every viewpoint and the true radiance texture is a function of
//! the point alone: the renderer's own estimate along a ray that meets the
//! point, exact here (point lamps and one scattering event leave nothing to
//! sample). The photographs are the same renderer's frames (stratified
//! sub-pixel samples, so each pixel averages the texture over its
//! footprint) with a Gaussian noise of [`TextureWorld::noise`] of the value
//! per pixel and channel (a sensor's shot noise at a good exposure).

use campanile_process::camera::image::RadianceImage;
use campanile_process::render::{self, CameraRig, Lighting, PointLight, Ray, RenderSettings, Scene};
use campanile_process::texture::Patch;
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::{LoadedScene, WorldError, examples_dir, load_scene};

/// Radiant intensity of each floodlight, W·sr⁻¹ per channel.
pub const FLOODLIGHT_W_SR: [f64; 3] = [9000.0, 8500.0, 7500.0];

/// A world with exact radiance: a scene lit by point lamps, direct light only.
#[derive(Debug, Clone)]
pub struct TextureWorld {
    /// The scene and its true materials.
    pub scene: Scene,
    /// The lamps.
    pub lamps: Vec<PointLight>,
    /// Relative noise per pixel and channel (standard deviation / value).
    pub noise: f64,
    /// Sub-pixel samples per pixel side (stratified).
    pub samples_per_side: u32,
}

impl TextureWorld {
    /// The example campanile lit by four floodlights at 45 m from its
    /// axis and 25 m up, at the diagonals, with 2% noise.
    pub fn campanile() -> Result<TextureWorld, WorldError> {
        let loaded: LoadedScene = load_scene(&examples_dir().join("campanile-scene.ron"))?;
        let lamps = [(1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0)]
            .map(|(x, y)| PointLight {
                position: Vector3::new(x * 32.0, y * 32.0, 25.0),
                intensity: FLOODLIGHT_W_SR,
            })
            .to_vec();
        Ok(TextureWorld {
            scene: loaded.scene,
            lamps,
            noise: 0.02,
            samples_per_side: 2,
        })
    }

    fn lighting(&self) -> Lighting<'_> {
        Lighting {
            sky: None,
            points: &self.lamps,
            spheres: &[],
        }
    }

    /// The photograph `rig` takes, with the noise drawn from `seed`.
    pub fn photograph(&self, rig: &CameraRig, seed: u64) -> RadianceImage {
        let settings = RenderSettings {
            samples_per_pixel: self.samples_per_side * self.samples_per_side,
            max_bounces: 1,
            seed,
            split_rays: 0,
        };
        let mut image = render::render(&self.scene, rig, &self.lighting(), &settings);
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x7E57_u64);
        for v in &mut image.data {
            // Box–Muller.
            let (u1, u2): (f64, f64) = (rng.random::<f64>().max(1e-300), rng.random());
            let g = (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos();
            *v = (f64::from(*v) * (1.0 + self.noise * g)).max(0.0) as f32;
        }
        image
    }

    /// The true radiance at world point `p` of `patch`, seen from the side
    /// of `viewpoint`.
    pub fn radiance_at(&self, patch: &Patch, p: &Vector3<f64>, viewpoint: &Vector3<f64>) -> [f64; 3] {
        let n = if patch.normal.dot(&(viewpoint - p)) >= 0.0 {
            patch.normal
        } else {
            -patch.normal
        };
        let ray = Ray {
            origin: p + n * 0.05,
            direction: -n,
        };
        let mut rng = ChaCha8Rng::seed_from_u64(0);
        render::trace(&self.scene, &self.lighting(), ray, 1, &mut rng)
    }

    /// The true texture of `patch`: each texel's radiance averaged over
    /// `per_side × per_side` points spread over it (texels off the face: 0).
    pub fn true_texture(&self, patch: &Patch, viewpoint: &Vector3<f64>, per_side: usize) -> Vec<[f64; 3]> {
        let n = per_side.max(1);
        let mut out = vec![[0.0; 3]; patch.cols * patch.rows];
        for j in 0..patch.rows {
            for i in 0..patch.cols {
                if patch.texel_triangle[j * patch.cols + i].is_none() {
                    continue;
                }
                let mut sum = [0.0; 3];
                for a in 0..n {
                    for b in 0..n {
                        let s = patch.origin[0] + (i as f64 + (a as f64 + 0.5) / n as f64) * patch.texel_m;
                        let t = patch.origin[1] + (j as f64 + (b as f64 + 0.5) / n as f64) * patch.texel_m;
                        let l = self.radiance_at(patch, &patch.point_at(s, t), viewpoint);
                        (0..3).for_each(|c| sum[c] += l[c]);
                    }
                }
                out[j * patch.cols + i] = sum.map(|x| x / (n * n) as f64);
            }
        }
        out
    }
}
