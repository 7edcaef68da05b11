//! What the solver is given: geometry grouped into named surfaces, known
//! lights, and calibrated radiance images with their cameras and optional
//! masks; and the knobs that trade speed against error.

use nalgebra::Vector3;

use super::camera::ViewCamera;
use super::error::IgiError;
use crate::brdf::WardVariant;
use crate::camera::image::RadianceImage;
use crate::render::Triangle;

/// A known light: a small sphere (radius 0 for a point light) of uniform
/// radiant intensity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IgiLight {
    /// Centre, world frame, metres.
    pub position: Vector3<f64>,
    /// Bulb radius, metres (0 for a point light). Pixels whose ray meets
    /// the bulb before a surface are dropped ("a light inside the view");
    /// its light is treated as coming from the centre.
    pub radius: f64,
    /// Radiant intensity per channel, W·sr⁻¹.
    pub intensity: [f64; 3],
}

/// One photograph: a camera, its radiance image and an optional mask.
#[derive(Debug, Clone, PartialEq)]
pub struct View {
    /// Name, for diagnostics.
    pub name: String,
    /// The camera.
    pub camera: ViewCamera,
    /// Radiance, W·m⁻²·sr⁻¹ per channel, `width × height` pixels.
    pub image: RadianceImage,
    /// `true` for pixels to use, row-major; `None` uses every pixel.
    pub mask: Option<Vec<bool>>,
}

/// Everything the solver is given.
#[derive(Debug, Clone)]
pub struct IgiInput {
    /// Triangles; `Triangle::surface` names the surface (a group sharing one
    /// BRDF), `texture_axes[0]` is the tangent from which γ is measured.
    pub triangles: Vec<Triangle>,
    /// Surface names, indexed by `Triangle::surface`.
    pub surfaces: Vec<String>,
    /// The lights that were on for every view.
    pub lights: Vec<IgiLight>,
    /// The photographs.
    pub views: Vec<View>,
}

/// The solver's knobs (speed against error).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IgiOptions {
    /// Ward normalization fitted (the thesis's eq. A.1/A.2 is `Ward1992`).
    pub variant: WardVariant,
    /// Use every `pixel_stride`-th pixel in each direction.
    pub pixel_stride: usize,
    /// Cells per triangle edge of the radiosity grid (`n × n` per triangle).
    pub cells_per_edge: usize,
    /// Cosine-distributed gather rays per cell for the indirect irradiance.
    pub gather_rays: u32,
    /// Lobe-sampled rays per sample for the indirect specular term ΔS.
    pub lobe_rays: u32,
    /// The most [`Self::lobe_rays`] is multiplied by on surfaces with a
    /// large specular share (`delta_s::ray_factor`: the share ρs / (ρd +
    /// ρs) over 5 %, so a metal gets the most). 1 (the default): every
    /// surface the same. On RADIANCE's metal wall (`validation/igi`) 8 took
    /// ρd from 2.5–3 % high to 1.1–1.3 %; on the simulated room's faceted
    /// metal sphere (ρd 0.02) it moved ρd from 3 % to 13 % low, which is
    /// not understood (BENCHMARKS.md), so only the command line's full
    /// setting uses it.
    pub lobe_ray_factor_max: u32,
    /// ΔS rays shared between the pixels of a view's `b × b` blocks on
    /// one triangle (`delta_s`: each pixel scores every ray of its block,
    /// weighted by its own lobe over the density the ray was drawn from),
    /// with the block's rays those of one pixel: the same noise per pixel
    /// for about 1 / b² of the rays. 1 (the default): every pixel traces
    /// its own rays alone.
    pub lobe_ray_block: usize,
    /// At most this many samples per surface in the sparse set the
    /// roughness search uses (§4.5 footnote); the linear step uses all.
    pub sparse_samples: usize,
    /// Cosine rays gathered at each observation's own point for the
    /// indirect irradiance the fit and the diffuse estimate use
    /// (`RadiosityField::gather_points`, on top of the cells' gather, which
    /// the other surfaces' radiance still reads); 0 (the default): read
    /// between the cells' gathered values. A diagnostic of the cells'
    /// resolution, not a cure: on the Mitsuba corridor (`validation/igi`)
    /// 1024 rays a point left the floor's weak lobe α −3.06, −1.87,
    /// −4.10 % over solver seeds 1–3 (cells: −2.75, −2.42, −5.57 %) and
    /// took 19× the gather's time (40 s a pass against 2.1 s); 256 rays gave −6.4 % (BENCHMARKS.md,
    /// "the corridor floor's α").
    pub point_gather_rays: u32,
    /// ΔS iterations (§4.5.1, Fig. 4.6): each re-estimates the diffuse
    /// radiance, the indirect light and the BRDFs. Default 3: on the
    /// §4.7.1 cube the first pass (no ΔS correction) leaves 15 % in ρs,
    /// the second 1.2 %, and from the third on the parameters move only by
    /// the solver's own Monte Carlo noise (BENCHMARKS.md, the IGI sweep).
    /// Without [`Self::interreflection`] at most two passes run (nothing
    /// is gathered; the second only re-weights the fit).
    pub iterations: u32,
    /// Views more grazing than this (angle from the normal) are dropped, radians.
    pub max_view_angle_rad: f64,
    /// Whether the anisotropic model may be chosen.
    pub allow_anisotropic: bool,
    /// Seed of every random choice.
    pub seed: u64,
    /// Whether the images hold interreflected light (§4.3–4.5: indirect
    /// irradiance and the indirect specular term ΔS are estimated and
    /// subtracted). `false` for images of direct light only (a renderer's
    /// single-bounce images, or a scene whose other surfaces are black):
    /// the indirect terms are then zero, and
    /// [`super::interreflection_check`] says whether the images agree.
    pub interreflection: bool,
    /// Measure the Monte Carlo noise of the gathered indirect irradiance
    /// and of ΔS (each drawn in independent stratified groups of rays,
    /// `stratified::variance_groups`) and take it out of the fit's normal
    /// equations (`ward_fit`: noise in a regressor otherwise pulls its
    /// coefficient toward zero), and read the indirect irradiance
    /// between cells rather than cell by cell
    /// (`RadiosityField::e_indirect_at`). On the Mitsuba corridor
    /// (`validation/igi`) the floor's weak lobe (ρs 0.02, α 0.15) came out
    /// ρs −2.4 to −6.1 %, α −4.4 to −8.0 % over seeds 1–4 without, ρs within
    /// 1.4 % and α −2.4 to −5.6 % with it (the command line's settings,
    /// 4096 gather rays). Off in the default (the §4.7.1 cube's test
    /// settings, `sim/tests/igi_cube.rs`): there, with converged indirect
    /// light, the north wall's weak lobe is 1.8–2.1 % high with or without
    /// it, and at the default 256 gather rays its one seed passed the 1 %
    /// bound by chance (seeds 2 and 3: 2.2 %, 1.2 %) and does not with it
    /// (3.1 %). On in the command line's full settings.
    pub correct_noise: bool,
    /// Keep the ΔS rays of the roughness search's samples and weigh them,
    /// at each roughness the search tries, by that lobe
    /// (`delta_s::LobeTerms::estimate`, unbiased for any lobe), instead
    /// of holding ΔS at the lobe it was drawn with (the previous pass's).
    /// Held, ΔS pulls the search against it (a sharper ΔS leaves a broader
    /// direct highlight to fit), and where ΔS is a large part of a
    /// surface's specular light the passes' roughness oscillates about its
    /// fixed point: on the Mitsuba corridor (`validation/igi`) the floor's
    /// weak lobe (ρs 0.02, α 0.15; ΔS two thirds of its specular light)
    /// went 0.1378, 0.1536, 0.1471, 0.1492, 0.1458, 0.1474 over six passes
    /// (solver seed 1), and three passes reported α −2.75, −2.42, −5.57 %
    /// over seeds 1–3; weighed, −1.21, −1.91, −1.36 % (ρs +0.22, −0.59,
    /// +1.80 %) at the command line's settings, every check of that room
    /// passing at each seed, for 20.4–22.9 s a solve against 16.7 s
    /// (BENCHMARKS.md, "the corridor floor's α"). Textured surfaces keep
    /// ΔS as drawn (their per-group fit takes no noise correction). Off in
    /// the default, whose 256 gather rays leave the gather's noise larger
    /// than this; on in the command line's full settings, with
    /// [`Self::correct_noise`].
    pub reweight_delta_s: bool,
}

impl Default for IgiOptions {
    fn default() -> Self {
        IgiOptions {
            variant: WardVariant::Ward1992,
            pixel_stride: 1,
            cells_per_edge: 24,
            gather_rays: 256,
            lobe_rays: 16,
            lobe_ray_factor_max: 1,
            lobe_ray_block: 1,
            sparse_samples: 2500,
            point_gather_rays: 0,
            iterations: 3,
            max_view_angle_rad: 84f64.to_radians(),
            allow_anisotropic: true,
            seed: 1,
            interreflection: true,
            correct_noise: false,
            reweight_delta_s: false,
        }
    }
}

impl IgiOptions {
    /// The ΔS passes that run: [`Self::iterations`] (at least one), at
    /// most two without [`Self::interreflection`] (nothing is gathered; the
    /// second pass only re-weights the fit by the first's estimate).
    pub fn passes(&self) -> u32 {
        if self.interreflection {
            self.iterations.max(1)
        } else {
            self.iterations.clamp(1, 2)
        }
    }

    /// Checks every option.
    pub fn validate(&self) -> Result<(), IgiError> {
        let err = |name, value: String, expected| Err(IgiError::Option { name, value, expected });
        if self.pixel_stride == 0 {
            return err("pixel_stride", "0".into(), "at least 1");
        }
        if self.lobe_ray_block == 0 {
            return err("lobe_ray_block", "0".into(), "at least 1");
        }
        if !(1..=512).contains(&self.cells_per_edge) {
            return err("cells_per_edge", self.cells_per_edge.to_string(), "1 to 512");
        }
        if self.gather_rays == 0 {
            return err("gather_rays", "0".into(), "at least 1");
        }
        if self.lobe_rays == 0 {
            return err("lobe_rays", "0".into(), "at least 1");
        }
        if self.sparse_samples < 16 {
            return err("sparse_samples", self.sparse_samples.to_string(), "at least 16");
        }
        if !(self.max_view_angle_rad > 0.0 && self.max_view_angle_rad < std::f64::consts::FRAC_PI_2) {
            return err(
                "max_view_angle_rad",
                self.max_view_angle_rad.to_string(),
                "an angle in (0, π/2)",
            );
        }
        Ok(())
    }
}

impl IgiInput {
    /// Checks lights, cameras, image and mask sizes, and every radiance
    /// that is not masked out.
    pub fn validate(&self) -> Result<(), IgiError> {
        if self.triangles.is_empty() {
            return Err(IgiError::NoGeometry);
        }
        for (index, l) in self.lights.iter().enumerate() {
            let err = |field, value: String, expected| IgiError::Light {
                index,
                field,
                value,
                expected,
            };
            if !l.position.iter().all(|c| c.is_finite()) {
                return Err(err("position", format!("{:?}", l.position), "finite coordinates"));
            }
            if !(l.radius.is_finite() && l.radius >= 0.0) {
                return Err(err("radius", l.radius.to_string(), "a finite radius >= 0 m"));
            }
            if !l.intensity.iter().all(|i| i.is_finite() && *i >= 0.0) {
                return Err(err(
                    "intensity",
                    format!("{:?}", l.intensity),
                    "finite values >= 0 W/sr",
                ));
            }
        }
        for v in &self.views {
            v.camera.validate(&v.name)?;
            let (w, h) = (v.camera.width, v.camera.height);
            if v.image.width != w || v.image.height != h || v.image.data.len() != w * h * 3 {
                return Err(IgiError::ImageSize {
                    view: v.name.clone(),
                    got_width: v.image.width,
                    got_height: v.image.height,
                    got_values: v.image.data.len(),
                    width: w,
                    height: h,
                });
            }
            if let Some(m) = &v.mask
                && m.len() != w * h
            {
                return Err(IgiError::MaskSize {
                    view: v.name.clone(),
                    got: m.len(),
                    expected: w * h,
                });
            }
            for y in 0..h {
                for x in 0..w {
                    if v.mask.as_ref().is_some_and(|m| !m[y * w + x]) {
                        continue;
                    }
                    for channel in 0..3 {
                        let value = v.image.radiance(x, y, channel);
                        if !(value.is_finite() && value >= 0.0) {
                            return Err(IgiError::Radiance {
                                view: v.name.clone(),
                                x,
                                y,
                                channel,
                                value,
                            });
                        }
                    }
                }
            }
        }
        Ok(())
    }
}

/// The empty unit-cube room of the unit tests: six faces (`s0` … `s5`),
/// no lights, no views.
#[cfg(test)]
pub(crate) fn unit_cube() -> IgiInput {
    IgiInput {
        triangles: crate::render::shapes::cuboid(
            Vector3::zeros(),
            Vector3::repeat(1.0),
            true,
            [0; 6],
            [0, 1, 2, 3, 4, 5],
        ),
        surfaces: (0..6).map(|i| format!("s{i}")).collect(),
        lights: Vec::new(),
        views: Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::igi::recover;

    fn input() -> IgiInput {
        let camera = ViewCamera {
            position: Vector3::repeat(0.5),
            look: -Vector3::z(),
            up: Vector3::y(),
            vfov_rad: 1.0,
            width: 4,
            height: 3,
        };
        IgiInput {
            lights: vec![IgiLight {
                position: Vector3::new(0.5, 0.5, 0.8),
                radius: 0.0,
                intensity: [1.0; 3],
            }],
            views: vec![View {
                name: "v".into(),
                camera,
                image: RadianceImage {
                    width: 4,
                    height: 3,
                    data: vec![0.1; 36],
                },
                mask: None,
            }],
            ..super::unit_cube()
        }
    }

    #[test]
    fn predict_refuses_materials_that_do_not_match_the_surfaces() {
        let opts = IgiOptions {
            cells_per_edge: 2,
            gather_rays: 4,
            ..IgiOptions::default()
        };
        let one = vec![None; 1];
        let e = crate::igi::predict(&input(), &opts, &one).unwrap_err();
        assert!(matches!(e, IgiError::Option { name: "materials", .. }), "{e}");
        assert!(e.to_string().contains("1 entries"), "{e}");
        let all = vec![None; 6];
        let got = crate::igi::predict(&input(), &opts, &all).unwrap();
        assert_eq!(got.len(), 12, "one prediction per usable pixel: {}", got.len());
    }

    #[test]
    fn bad_inputs_are_typed_errors_naming_what_is_wrong() {
        let opts = IgiOptions::default();
        assert!(recover(&input(), &opts).is_ok());
        let mut i = input();
        i.views[0].image.data[(2 * 4 + 1) * 3 + 2] = f32::NAN;
        let e = recover(&i, &opts).unwrap_err();
        assert!(
            matches!(
                e,
                IgiError::Radiance {
                    x: 1,
                    y: 2,
                    channel: 2,
                    ..
                }
            ),
            "{e}"
        );
        assert!(e.to_string().contains("pixel (1, 2)"), "{e}");
        // Masked out, the same pixel is ignored.
        let mut mask = vec![true; 12];
        mask[2 * 4 + 1] = false;
        i.views[0].mask = Some(mask);
        assert!(recover(&i, &opts).is_ok());
        let mut i = input();
        i.views[0].image.width = 5;
        assert!(matches!(recover(&i, &opts), Err(IgiError::ImageSize { .. })));
        let mut i = input();
        i.views[0].mask = Some(vec![true; 5]);
        assert!(matches!(
            recover(&i, &opts),
            Err(IgiError::MaskSize {
                got: 5,
                expected: 12,
                ..
            })
        ));
        let mut i = input();
        i.lights[0].radius = -1.0;
        assert!(matches!(
            recover(&i, &opts),
            Err(IgiError::Light { field: "radius", .. })
        ));
        let mut i = input();
        i.views[0].camera.vfov_rad = 4.0;
        assert!(matches!(
            recover(&i, &opts),
            Err(IgiError::Camera { field: "vfov", .. })
        ));
        let mut i = input();
        i.triangles.clear();
        assert!(matches!(recover(&i, &opts), Err(IgiError::NoGeometry)));
        let bad = IgiOptions {
            pixel_stride: 0,
            ..opts
        };
        assert!(matches!(
            recover(&input(), &bad),
            Err(IgiError::Option {
                name: "pixel_stride",
                ..
            })
        ));
        let bad = IgiOptions {
            lobe_ray_block: 0,
            ..opts
        };
        assert!(matches!(
            recover(&input(), &bad),
            Err(IgiError::Option {
                name: "lobe_ray_block",
                ..
            })
        ));
    }
}
