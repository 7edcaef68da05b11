//! Texture maps from registered photographs against the simulator's truth
//! (thesis §3.4, issue 27): the example campanile floodlit at night (exact
//! direct light, Lambertian, so the true radiance texture is known
//! exactly: `campanile_sim::world::texture_truth`), photographed from the
//! scene file's poses through the station's lens (distortion included) with
//! 2% noise per pixel, then textured at 0.25 m per texel.
//!
//! Figures: texture PSNR over the texels seen (peak = the truth's brightest
//! texel), the RMS error of texels along the faces' borders against inside
//! (seam visibility), coverage. Hard cases: a face no photo sees
//! (reported, filled, not counted as seen), a grazing view (dropped or
//! down-weighted: it must not cost accuracy), an occluder in front of a
//! wall (never painted on the wall), the edge of a photo through a face.

use campanile_config::scene::CameraPose as ScenePose;
use campanile_process::camera::image::RadianceImage;
use campanile_process::pose::Pinhole;
use campanile_process::render::{Scene, Triangle};
use campanile_process::texture::seam::on_border;
use campanile_process::texture::synthesis::TexelStatus;
use campanile_process::texture::{
    Patch, Synthesis, SynthesisSettings, TexturePhoto, patches, pose_from_angles, synthesize,
};
use campanile_sim::world::examples_dir;
use campanile_sim::world::texture_truth::TextureWorld;
use nalgebra::Vector3;

const W: usize = 640;
const H: usize = 480;
const TEXEL_M: f64 = 0.25;

fn station_pinhole() -> Pinhole {
    let s = campanile_config::load_station(&examples_dir().join("sim-station.ron"))
        .expect("the example station")
        .value;
    let c = &s.camera;
    Pinhole::of_camera(c).rescaled((c.resolution.width as usize, c.resolution.height as usize), W, H)
}

fn scene_pose(name: &str) -> ScenePose {
    let d = campanile_config::document::load_scene(&examples_dir().join("campanile-scene.ron"))
        .expect("the example scene")
        .value;
    d.pose(name).expect("a pose of the example").clone()
}

/// The photograph from `pose` (position, azimuth, elevation, roll).
fn photo(world: &TextureWorld, label: &str, pose: ([f64; 3], f64, f64, f64), seed: u64) -> TexturePhoto {
    let (p, az, el, roll) = pose;
    let pose = pose_from_angles(Vector3::from(p), az, el, roll).expect("a pose");
    let blank = RadianceImage {
        width: W,
        height: H,
        data: vec![0.0; W * H * 3],
    };
    let mut photo = TexturePhoto::new(label, blank, &pose, station_pinhole()).expect("a photo");
    photo.image = world.photograph(&photo.rig, seed);
    photo
}

fn named(world: &TextureWorld, name: &str, seed: u64) -> TexturePhoto {
    let p = scene_pose(name);
    let (x, y, z) = p.position_m;
    photo(world, name, ([x, y, z], p.azimuth_deg, p.elevation_deg, 0.0), seed)
}

/// Error figures of a synthesis against the truth, over the texels seen.
#[derive(Debug)]
struct Figures {
    psnr_db: f64,
    rms_border: f64,
    rms_interior: f64,
    seen: usize,
    peak: f64,
}

fn figures(world: &TextureWorld, ps: &[Patch], syn: &Synthesis, viewpoint: &Vector3<f64>) -> Figures {
    let (mut se_b, mut nb, mut se_i, mut ni, mut peak) = (0.0, 0usize, 0.0, 0usize, 0f64);
    for (patch, tex) in ps.iter().zip(&syn.textures) {
        let truth = world.true_texture(patch, viewpoint, 8);
        for j in 0..patch.rows {
            for i in 0..patch.cols {
                let k = j * patch.cols + i;
                if tex.status[k] != TexelStatus::Seen {
                    continue;
                }
                let e: f64 = (0..3)
                    .map(|c| (f64::from(tex.rgb[k][c]) - truth[k][c]).powi(2))
                    .sum::<f64>()
                    / 3.0;
                peak = peak.max(truth[k].iter().copied().fold(0.0, f64::max));
                if on_border(patch, i, j) {
                    se_b += e;
                    nb += 1;
                } else {
                    se_i += e;
                    ni += 1;
                }
            }
        }
    }
    let mse = (se_b + se_i) / (nb + ni).max(1) as f64;
    Figures {
        psnr_db: 10.0 * (peak * peak / mse).log10(),
        rms_border: (se_b / nb.max(1) as f64).sqrt(),
        rms_interior: (se_i / ni.max(1) as f64).sqrt(),
        seen: nb + ni,
        peak,
    }
}

fn faces(scene: &Scene, names: &[&str]) -> Vec<Patch> {
    let names: Vec<String> = names.iter().map(|s| s.to_string()).collect();
    patches(scene, Some(&names), TEXEL_M, 10_000_000).expect("patches")
}

/// The south and east faces from three of the example's poses. The truth
/// is each texel's mean over 8 × 8 points. What bounds the PSNR: the noise
/// (2% per pixel, about 4 pixels per texel from each of two photos) alone
/// would leave ≈ 0.7% of the value, about 45 dB against the peak; the
/// texture's 5 cm mortar joints, blurred by the photos' pixels (≈ 0.1 m at
/// 60 m) and by bilinear resampling, cost more. Measured 32.6 dB
/// (2026-11-27; deterministic seeds); the bound of 31 dB leaves 1.5 dB, and
/// a wrong weight, a misplaced projection or an occluder's leak (≥ 10% at
/// some texels) falls below it. Border texels lose the sub-samples whose
/// pixels touch another face, which moves their mean inward by up to half
/// a texel: measured 1.59× the interior's RMS error; bound 2×.
#[test]
fn floodlit_tower_texture_meets_the_truth() {
    let world = TextureWorld::campanile().expect("the world");
    let ps = faces(&world.scene, &["south-face", "east-face"]);
    let photos = [
        named(&world, "view-se", 1),
        named(&world, "view-sw", 2),
        named(&world, "view-ne", 3),
    ];
    let syn = synthesize(&world.scene, &ps, &photos, &SynthesisSettings::default()).expect("synthesis");
    let viewpoint = Vector3::new(40.0, -40.0, 1.5);
    let f = figures(&world, &ps, &syn, &viewpoint);
    let r = &syn.report;
    println!("main: {f:?}; coverage {:.3}; {r:?}", r.coverage());
    assert!(f.seen > 10_000, "{f:?}");
    assert!(f.peak > 0.1, "{f:?}");
    assert!(f.psnr_db >= 31.0, "PSNR {:.2} dB < 31 dB: {f:?}", f.psnr_db);
    assert!(
        f.rms_border <= 2.0 * f.rms_interior,
        "seams: border RMS {:.4} vs interior {:.4}",
        f.rms_border,
        f.rms_interior
    );
    // The tops of the faces are above every frame: reported, not invented.
    assert!(r.unseen > 0 && r.coverage() > 0.5, "{r:?}");
    let filled: usize = syn
        .textures
        .iter()
        .map(|t| t.status.iter().filter(|s| **s == TexelStatus::Filled).count())
        .sum();
    assert_eq!(filled, r.unseen);
    // Exact poses: every photograph agrees best with the others unmoved.
    for o in &r.offsets {
        let o = o.expect("each photo shares texels");
        assert!(o.length_px() < 0.1, "{o:?}");
    }
    let seams = campanile_process::texture::seam_figures(&ps, &syn.textures);
    let q = campanile_process::texture::judge(r, &seams, &Default::default());
    assert!(
        q.reasons.iter().all(|r| r.starts_with("coverage")),
        "only the unseen tops make it poor: {:?}",
        q.reasons
    );
}

/// The photographs of [`floodlit_tower_texture_meets_the_truth`] with
/// view-se registered off: `az_off` degrees in azimuth, `side_m` metres
/// across its optical axis.
fn misregistered(world: &TextureWorld, az_off: f64, side_m: f64) -> [TexturePhoto; 3] {
    let se = named(world, "view-se", 1);
    let p = scene_pose("view-se");
    let (x, y, z) = p.position_m;
    let az = p.azimuth_deg.to_radians();
    let side = Vector3::new(az.cos(), -az.sin(), 0.0) * side_m;
    let pose = pose_from_angles(
        Vector3::new(x, y, z) + side,
        p.azimuth_deg + az_off,
        p.elevation_deg,
        0.0,
    )
    .expect("pose");
    let photo = TexturePhoto::new("view-se", se.image, &pose, station_pinhole()).expect("photo");
    [photo, named(world, "view-sw", 2), named(world, "view-ne", 3)]
}

/// The registration check against the truth of the poses. view-se is
/// about 60 m from the faces it shares; its 640-pixel frame spans 60°
/// (554 px focal length): 0.5° of azimuth moves its image 4.8 px, 5 cm
/// sideways 0.46 px. Measured (2026-11-27, deterministic seeds): exact
/// poses ≤ 0.02 px for each photograph (asserted < 0.1 px above); 0.5° off:
/// view-se's best shift 4.14 px; 5 cm off: 0.47 px. The verdict's limit is
/// 0.3 px, so both are `poor` with the reason named; the other two
/// photographs, compared with a mean that holds view-se, show shifts too
/// (the check finds the disagreeing pair, not the culprit alone).
#[test]
fn a_misregistered_photo_is_found_by_its_shift() {
    use campanile_process::texture::{judge, seam_figures};
    let world = TextureWorld::campanile().expect("the world");
    let ps = faces(&world.scene, &["south-face", "east-face"]);
    for (az_off, side_m, low, high) in [(0.5, 0.0, 3.5, 5.5), (0.0, 0.05, 0.3, 0.6)] {
        let photos = misregistered(&world, az_off, side_m);
        let syn = synthesize(&world.scene, &ps, &photos, &SynthesisSettings::default()).expect("synthesis");
        let o = syn.report.offsets[0].expect("view-se shares texels");
        println!("{az_off}° {side_m} m: offsets {:?}", syn.report.offsets);
        assert!(
            o.length_px() > low && o.length_px() < high,
            "{az_off}° / {side_m} m: view-se's shift {o:?}, expected {low}–{high} px"
        );
        let q = judge(&syn.report, &seam_figures(&ps, &syn.textures), &Default::default());
        assert_eq!(q.verdict, "poor");
        assert!(
            q.reasons.iter().any(|r| r.contains("photograph 1 agrees best")),
            "{:?}",
            q.reasons
        );
    }
}

/// The independent check's false `poor` (BENCHMARKS.md "Texture maps"):
/// the whole tower at 0.125 m from the three exact photographs. Without
/// the mixed-pixel margin (`edge_margin_px: 0`) the border spread is 4.3×
/// the interior's (measured 0.137 against 0.032 on 256 border texels, the
/// worst at the tower's corners); with it no border texel is seen by two
/// photographs through pixels wholly on the face, so the figure has
/// nothing to flag, and the registration check finds every photograph
/// within 0.1 px of its place. About 4 s in the dev profile on top of the
/// tests above (CI's budget): run with `--ignored`.
#[test]
#[ignore = "4 s; the measurement behind the mixed-pixel margin"]
fn whole_tower_exact_poses_show_no_seams() {
    use campanile_process::texture::{judge, seam_figures};
    let world = TextureWorld::campanile().expect("the world");
    let names: Vec<String> = ["south-face", "east-face", "north-face", "west-face", "pillars", "roof"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    let ps = patches(&world.scene, Some(&names), 0.125, 10_000_000).expect("patches");
    let photos = [
        named(&world, "view-se", 1),
        named(&world, "view-sw", 2),
        named(&world, "view-ne", 3),
    ];
    let mixed = SynthesisSettings {
        edge_margin_px: 0,
        ..Default::default()
    };
    let before = synthesize(&world.scene, &ps, &photos, &mixed).expect("synthesis");
    let s0 = seam_figures(&ps, &before.textures);
    println!("margin 0: {s0:?}, ratio {:.2}", s0.ratio());
    assert!(s0.ratio() > 3.0, "{s0:?}");
    let after = synthesize(&world.scene, &ps, &photos, &SynthesisSettings::default()).expect("synthesis");
    let s1 = seam_figures(&ps, &after.textures);
    let q = judge(&after.report, &s1, &Default::default());
    println!(
        "margin 1: {s1:?}, ratio {:.2}; {:?}; {:?}",
        s1.ratio(),
        after.report.offsets,
        q.reasons
    );
    assert!(s1.ratio() <= 2.0, "{s1:?}");
    assert!(
        after
            .report
            .offsets
            .iter()
            .all(|o| o.is_some_and(|o| o.length_px() < 0.1))
    );
    assert!(q.reasons.iter().all(|r| r.starts_with("coverage")), "{:?}", q.reasons);
}

#[test]
fn hard_cases_unseen_grazing_occluded_and_a_photo_edge() {
    let world = TextureWorld::campanile().expect("the world");
    // A face no photo sees: the north face from the two southern views.
    let north = faces(&world.scene, &["north-face"]);
    let south_views = [named(&world, "view-se", 1), named(&world, "view-sw", 2)];
    let syn = synthesize(&world.scene, &north, &south_views, &SynthesisSettings::default()).expect("synthesis");
    assert_eq!(syn.report.unseen, syn.report.texels_on_faces, "{:?}", syn.report);
    assert_eq!(syn.report.coverage(), 0.0);

    let south = faces(&world.scene, &["south-face"]);
    let viewpoint = Vector3::new(0.0, -40.0, 1.5);
    let base = synthesize(&world.scene, &south, &south_views, &SynthesisSettings::default()).expect("synthesis");
    let f0 = figures(&world, &south, &base, &viewpoint);

    // A grazing view along the south face (about 87° from its normal):
    // dropped (cos θ under 0.1), so it costs nothing.
    let mut with_grazing = south_views.to_vec();
    with_grazing.push(photo(&world, "grazing", ([60.0, -8.5, 20.0], 272.0, 5.0, 0.0), 4));
    let g = synthesize(&world.scene, &south, &with_grazing, &SynthesisSettings::default()).expect("synthesis");
    let fg = figures(&world, &south, &g, &viewpoint);
    println!("grazing: {fg:?} against {f0:?}; grazing texels {:?}", g.report.grazing);
    assert!(g.report.grazing[2] > 1000, "{:?}", g.report);
    assert!(
        fg.psnr_db >= f0.psnr_db - 0.3,
        "{:.2} vs {:.2} dB",
        fg.psnr_db,
        f0.psnr_db
    );

    // A photo whose frame's edge crosses the face (a zoom on its lower
    // left, rolled 10°): no step where it ends.
    let mut with_edge = south_views.to_vec();
    with_edge.push(photo(&world, "edge", ([-2.0, -14.0, 1.5], 5.0, 20.0, 10.0), 5));
    let e = synthesize(&world.scene, &south, &with_edge, &SynthesisSettings::default()).expect("synthesis");
    let fe = figures(&world, &south, &e, &viewpoint);
    println!("edge: {fe:?}; used {:?}", e.report.used);
    assert!(
        e.report.used[2] > 500 && e.report.used[2] < e.report.texels_on_faces,
        "{:?}",
        e.report
    );
    assert!(
        fe.psnr_db >= f0.psnr_db - 0.3,
        "{:.2} vs {:.2} dB",
        fe.psnr_db,
        f0.psnr_db
    );

    // An occluder: a 2 m × 6 m slab 8 m in front of the south face.
    let mut tris = world.scene.triangles().to_vec();
    let mut surfaces = world.scene.surfaces().to_vec();
    surfaces.push("slab".into());
    let s = (surfaces.len() - 1) as u32;
    let v = |x: f64, z: f64| Vector3::new(x, -13.5, z);
    tris.push(Triangle::new([v(-1.0, 0.0), v(1.0, 0.0), v(1.0, 6.0)], 0, s).expect("slab"));
    tris.push(Triangle::new([v(-1.0, 0.0), v(1.0, 6.0), v(-1.0, 6.0)], 0, s).expect("slab"));
    let occluded_world = TextureWorld {
        scene: Scene::new(tris, world.scene.materials().to_vec(), surfaces).expect("scene"),
        ..world.clone()
    };
    let views = [
        named(&occluded_world, "view-se", 1),
        named(&occluded_world, "view-sw", 2),
        photo(&occluded_world, "front", ([0.0, -40.0, 1.5], 0.0, 12.0, 0.0), 6),
    ];
    let o = synthesize(&occluded_world.scene, &south, &views, &SynthesisSettings::default()).expect("synthesis");
    let fo = figures(&occluded_world, &south, &o, &viewpoint);
    println!("occluder: {fo:?}; occluded {:?}", o.report.occluded);
    // The diagonal views see the slab beside the face; the front view sees it before the face.
    assert!(o.report.occluded[2] > 50, "{:?}", o.report);
    assert!(fo.psnr_db >= 31.0, "{fo:?}");
}
