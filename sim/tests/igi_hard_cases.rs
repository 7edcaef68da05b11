//! Inverse global illumination's hard cases, each in a black box (five
//! black walls, no interreflection, direct light only, so the photographs
//! are exact and the answers known): a surface whose highlight no camera
//! sees, a near-mirror lobe (α = 0.001), grazing views, a metal sphere
//! without diffuse component, and a lamp inside the view. Each must give
//! the right answer or a diagnostic, never a NaN.

use campanile_process::brdf::{WardLobe, WardMaterial, WardVariant};
use campanile_process::igi::table::errors;
use campanile_process::igi::{
    IgiInput, IgiLight, IgiOptions, IgiResult, SpecularKind, SurfaceModel, View, ViewCamera, recover,
};
use campanile_process::render::{Material, PointLight, Scene, SphereLight, Texture, Triangle, shapes};
use campanile_sim::world::igi_photograph::{PhotoSettings, photograph};
use nalgebra::Vector3;

const DIRECT_ONLY: PhotoSettings = PhotoSettings {
    indirect_samples: 0,
    max_bounces: 1,
    seed: 3,
};

fn options() -> IgiOptions {
    IgiOptions {
        cells_per_edge: 4,
        gather_rays: 16,
        lobe_rays: 4,
        iterations: 2,
        ..IgiOptions::default()
    }
}

fn material(name: &str, m: &WardMaterial) -> Material {
    Material {
        name: name.into(),
        albedo: Texture::Constant(m.rho_d),
        specular: m.lobe,
        emission: [0.0; 3],
    }
}

fn plastic(rho_d: f64, rho_s: f64, alpha: f64) -> WardMaterial {
    WardMaterial::new(
        [rho_d; 3],
        Some(WardLobe::isotropic([rho_s; 3], alpha, WardVariant::Ward1992).unwrap()),
    )
    .unwrap()
}

/// A unit box, black but for its floor (surface 4), plus `extra` triangles
/// (surface 6, material `extra_material`), photographed by `cameras`.
fn black_box(
    floor: &WardMaterial,
    extra: Vec<Triangle>,
    extra_material: &WardMaterial,
    points: &[PointLight],
    bulbs: &[SphereLight],
    cameras: &[ViewCamera],
) -> IgiInput {
    let mut tris = shapes::cuboid(
        Vector3::zeros(),
        Vector3::repeat(1.0),
        true,
        [0, 0, 0, 0, 1, 0],
        [0, 1, 2, 3, 4, 5],
    );
    tris.extend(extra);
    let black = WardMaterial::new([0.0; 3], None).unwrap();
    let names: Vec<String> = ["west", "east", "south", "north", "floor", "ceiling", "object"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    let scene = Scene::new(
        tris.clone(),
        vec![
            material("black", &black),
            material("floor", floor),
            material("object", extra_material),
        ],
        names.clone(),
    )
    .unwrap();
    let mut lights: Vec<IgiLight> = points
        .iter()
        .map(|p| IgiLight {
            position: p.position,
            radius: 0.0,
            intensity: p.intensity,
        })
        .collect();
    lights.extend(bulbs.iter().map(|b| IgiLight {
        position: b.center,
        radius: b.radius,
        intensity: b.radiance.map(|l| l * std::f64::consts::PI * b.radius * b.radius),
    }));
    IgiInput {
        triangles: tris,
        surfaces: names,
        lights,
        views: cameras
            .iter()
            .enumerate()
            .map(|(i, c)| View {
                name: format!("view-{i}"),
                camera: *c,
                image: photograph(&scene, points, bulbs, c, &DIRECT_ONLY),
                mask: None,
            })
            .collect(),
    }
}

fn camera(position: [f64; 3], target: [f64; 3], vfov_deg: f64, px: usize) -> ViewCamera {
    let position = Vector3::from(position);
    let look = Vector3::from(target) - position;
    let up = if look.normalize().z.abs() > 0.9 {
        Vector3::y()
    } else {
        Vector3::z()
    };
    ViewCamera {
        position,
        look,
        up,
        vfov_rad: vfov_deg.to_radians(),
        width: px,
        height: px,
    }
}

fn light(p: [f64; 3]) -> PointLight {
    PointLight {
        position: Vector3::from(p),
        intensity: [1.0; 3],
    }
}

/// Every number of the result is finite.
fn assert_finite(r: &IgiResult) {
    for s in &r.surfaces {
        let mut v: Vec<f64> = s.directional_albedo.to_vec();
        v.push(s.rms_relative);
        v.extend(s.bic.iter().flatten());
        if let Some(m) = &s.material {
            v.extend(m.rho_d);
            if let Some(l) = &m.lobe {
                v.extend(l.rho_s);
                v.extend([l.alpha_x, l.alpha_y, l.gamma_rad]);
            }
        }
        for h in &s.highlights {
            v.extend([h.excess, h.min_delta_deg]);
        }
        assert!(v.iter().all(|x| x.is_finite()), "{}: {v:?}", s.name);
        assert!(!s.reason.is_empty() || s.model == SurfaceModel::Unobserved);
    }
}

#[test]
fn a_surface_whose_highlight_is_out_of_view_is_diffuse_only() {
    let floor = plastic(0.2, 0.05, 0.05);
    // Looking at a floor corner: the light's mirror point (the floor's centre) is out of view.
    let input = black_box(
        &floor,
        Vec::new(),
        &floor,
        &[light([0.5, 0.5, 0.7])],
        &[],
        &[camera([0.5, 0.5, 0.9], [0.12, 0.12, 0.0], 15.0, 48)],
    );
    let r = recover(&input, &options()).unwrap();
    assert_finite(&r);
    let f = &r.surfaces[4];
    assert_eq!(f.model, SurfaceModel::DiffuseOnly, "{}", f.reason);
    assert!(f.reason.contains("no light's mirror direction"), "{}", f.reason);
    let m = f.material.unwrap();
    assert!(m.lobe.is_none());
    // Far from the mirror direction the lobe is ~exp(−tan²25°/α²) = 0: ρd is exact.
    assert!((m.rho_d[0] - 0.2).abs() < 0.002, "{m:?}");
    // The walls no camera sees are reported, not invented.
    assert_eq!(r.surfaces[3].model, SurfaceModel::Unobserved);
    assert!(r.surfaces[3].material.is_none());
}

#[test]
fn a_near_mirror_lobe_gives_a_diagnostic_and_a_clean_diffuse_albedo() {
    let floor = plastic(0.2, 0.05, 0.001);
    let input = black_box(
        &floor,
        Vec::new(),
        &floor,
        &[light([0.6, 0.5, 0.7])],
        &[],
        &[camera([0.5, 0.5, 0.9], [0.55, 0.5, 0.0], 40.0, 64)],
    );
    let r = recover(&input, &options()).unwrap();
    assert_finite(&r);
    let f = &r.surfaces[4];
    let m = f.material.unwrap();
    // The lobe is narrower than a pixel: either no pixel centre caught it
    // (diffuse only, with the mirror cone reported) or a few did (then α is tiny).
    match m.lobe {
        None => {
            assert_eq!(f.model, SurfaceModel::DiffuseOnly);
            assert!(!f.highlights.is_empty(), "the mirror cone is in view: {}", f.reason);
        }
        Some(l) => assert!(l.alpha_x < 0.01, "{l:?}: {}", f.reason),
    }
    assert!((m.rho_d[0] - 0.2).abs() < 0.002, "{m:?}: {}", f.reason);
}

#[test]
fn grazing_views_are_dropped_and_counted() {
    let floor = plastic(0.2, 0.05, 0.05);
    let input = black_box(
        &floor,
        Vec::new(),
        &floor,
        &[light([0.6, 0.5, 0.7])],
        &[],
        &[
            camera([0.5, 0.5, 0.9], [0.55, 0.5, 0.0], 50.0, 64),
            // Along the floor, 2 cm above it: the floor is seen at 85°–89°.
            camera([0.5, 0.01, 0.02], [0.5, 1.0, 0.0], 10.0, 48),
        ],
    );
    let r = recover(&input, &options()).unwrap();
    assert_finite(&r);
    assert!(r.pixels[1].1.grazing > 100, "{:?}", r.pixels[1]);
    let f = &r.surfaces[4];
    assert_eq!(f.model, SurfaceModel::Isotropic, "{}", f.reason);
    let e = errors(&f.material.unwrap(), &floor);
    for (k, v) in e.iter().take(3).enumerate() {
        assert!(v.unwrap() < 1.0, "parameter {k}: {:?} % ({})", v, f.reason);
    }
}

#[test]
fn a_metal_sphere_without_diffuse_component_is_metal() {
    let black = WardMaterial::new([0.0; 3], None).unwrap();
    let metal = WardMaterial::new(
        [0.0; 3],
        Some(WardLobe::isotropic([0.8; 3], 0.1, WardVariant::Ward1992).unwrap()),
    )
    .unwrap();
    let sphere = shapes::sphere(Vector3::new(0.5, 0.5, 0.4), 0.2, 48, 96, 2, 6);
    let input = black_box(
        &black,
        sphere,
        &metal,
        &[light([0.8, 0.2, 0.8])],
        &[],
        &[camera([0.5, 0.05, 0.6], [0.5, 0.5, 0.4], 50.0, 64)],
    );
    let opts = IgiOptions {
        cells_per_edge: 1,
        ..options()
    };
    let r = recover(&input, &opts).unwrap();
    assert_finite(&r);
    let s = &r.surfaces[6];
    assert_eq!(s.kind, SpecularKind::Metal, "{}", s.reason);
    let m = s.material.unwrap();
    let l = m.lobe.unwrap();
    assert!(m.rho_d[0] < 0.002, "{m:?}");
    assert!((l.rho_s[0] - 0.8).abs() < 0.008, "{l:?}");
    assert!(
        (l.alpha_x - 0.1).abs() < 0.001 && (l.alpha_y - 0.1).abs() < 0.001,
        "{l:?}"
    );
}

#[test]
fn a_lamp_inside_the_view_is_masked_and_the_floor_still_recovered() {
    let floor = plastic(0.2, 0.05, 0.05);
    let bulb = SphereLight::with_intensity(Vector3::new(0.5, 0.45, 0.5), 0.04, [1.0; 3]);
    let input = black_box(
        &floor,
        Vec::new(),
        &floor,
        &[],
        &[bulb],
        &[camera([0.5, 0.3, 0.9], [0.5, 0.55, 0.0], 60.0, 64)],
    );
    let r = recover(&input, &options()).unwrap();
    assert_finite(&r);
    assert!(r.pixels[0].1.light_in_view > 10, "{:?}", r.pixels[0]);
    let f = &r.surfaces[4];
    let e = errors(&f.material.unwrap(), &floor);
    for (k, v) in e.iter().take(3).enumerate() {
        assert!(v.unwrap() < 1.0, "parameter {k}: {:?} % ({})", v, f.reason);
    }
}
