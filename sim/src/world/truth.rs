//! The ground truth of the built-in worlds: what each scene material is
//! really made of. The solvers must recover these numbers.
//!
//! - **campanile** (thesis §5.2, §5.4): near-Lambertian outdoor surfaces, so
//!   the pseudo-albedos for sun and for sky + environment both equal the
//!   diffuse albedo texture below (stone blocks, copper seams, grass).
//! - **room** (thesis §4.7.2): Ward materials, isotropic and anisotropic,
//!   plastic and metal, with known parameters.
//!
//! Materials of other scenes get a neutral grey Lambertian albedo of 0.5.

use campanile_process::brdf::{BrdfError, WardLobe, WardVariant};
use campanile_process::render::Texture;

/// A Ward specular lobe (thesis eq. A.1/A.2, 1992 normalization).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Finish {
    /// Specular reflectance ρs per channel.
    pub rho_s: [f64; 3],
    /// Roughness along the principal x axis.
    pub alpha_x: f64,
    /// Roughness along the principal y axis (= `alpha_x` when isotropic).
    pub alpha_y: f64,
    /// Orientation γ of the principal axes, degrees, about the normal.
    pub gamma_deg: f64,
}

/// What one material is made of.
#[derive(Debug, Clone, PartialEq)]
pub struct Appearance {
    /// Diffuse albedo ρd.
    pub albedo: Texture,
    /// Specular lobe, if any.
    pub finish: Option<Finish>,
}

impl Finish {
    /// The lobe in the thesis's 1992 normalization.
    pub fn lobe(&self) -> Result<WardLobe, BrdfError> {
        WardLobe::new(
            self.rho_s,
            self.alpha_x,
            self.alpha_y,
            self.gamma_deg.to_radians(),
            WardVariant::Ward1992,
        )
    }
}

impl Appearance {
    /// The specular lobe, if any.
    pub fn lobe(&self) -> Result<Option<WardLobe>, BrdfError> {
        self.finish.as_ref().map(Finish::lobe).transpose()
    }

    pub(crate) fn diffuse(albedo: Texture) -> Appearance {
        Appearance { albedo, finish: None }
    }
}

/// Whether a built-in world is lit by the sky or by lamps.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Setting {
    /// Sun, sky and landscape.
    Outdoor,
    /// The station's lamps only.
    Indoor,
}

/// The setting of scene `scene`: the room is indoors, everything else outdoors.
pub fn setting(scene: &str) -> Setting {
    if scene == "room" {
        Setting::Indoor
    } else {
        Setting::Outdoor
    }
}

/// The grey given to materials the simulator has no truth for.
pub const DEFAULT_ALBEDO: f64 = 0.5;

/// The true appearance of material `material` in scene `scene`.
pub fn appearance(scene: &str, material: &str) -> Appearance {
    match (scene, material) {
        ("campanile", "granite") => Appearance::diffuse(Texture::Bricks {
            brick: [0.56, 0.47, 0.38],
            mortar: [0.78, 0.75, 0.68],
            size_m: [1.2, 0.6],
            joint_m: 0.05,
            variation: 0.12,
            seed: 11,
        }),
        ("campanile", "roof-copper") => Appearance::diffuse(Texture::Stripes {
            colours: [[0.22, 0.46, 0.38], [0.17, 0.36, 0.30]],
            period_m: 1.0,
            vertical: true,
        }),
        ("campanile", "ground") => Appearance::diffuse(Texture::Noise {
            mean: [0.20, 0.24, 0.15],
            amplitude: 0.15,
            cell_m: 1.0,
            seed: 12,
        }),
        ("campanile", "landscape") => Appearance::diffuse(Texture::Noise {
            mean: [0.10, 0.14, 0.09],
            amplitude: 0.3,
            cell_m: 8.0,
            seed: 13,
        }),
        ("room", "paint") => Appearance::diffuse(Texture::Constant([0.72, 0.70, 0.66])),
        ("room", "wood") => Appearance {
            albedo: Texture::Stripes {
                colours: [[0.46, 0.31, 0.18], [0.38, 0.25, 0.14]],
                period_m: 0.06,
                vertical: true,
            },
            finish: Some(Finish {
                rho_s: [0.05; 3],
                alpha_x: 0.15,
                alpha_y: 0.15,
                gamma_deg: 0.0,
            }),
        },
        ("room", "brushed") => Appearance {
            albedo: Texture::Constant([0.20, 0.20, 0.22]),
            finish: Some(Finish {
                rho_s: [0.10; 3],
                alpha_x: 0.05,
                alpha_y: 0.30,
                gamma_deg: 45.0,
            }),
        },
        ("room", "paper") => Appearance::diffuse(Texture::Stripes {
            colours: [[0.70, 0.18, 0.12], [0.80, 0.72, 0.20]],
            period_m: 0.1,
            vertical: false,
        }),
        ("room", "plastic") => Appearance {
            albedo: Texture::Constant([0.08, 0.22, 0.55]),
            finish: Some(Finish {
                rho_s: [0.06; 3],
                alpha_x: 0.08,
                alpha_y: 0.08,
                gamma_deg: 0.0,
            }),
        },
        ("room", "metal") => Appearance {
            albedo: Texture::Constant([0.02, 0.02, 0.01]),
            finish: Some(Finish {
                rho_s: [0.60, 0.48, 0.28],
                alpha_x: 0.10,
                alpha_y: 0.10,
                gamma_deg: 0.0,
            }),
        },
        _ => Appearance::diffuse(Texture::Constant([DEFAULT_ALBEDO; 3])),
    }
}
