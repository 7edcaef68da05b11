//! Texture maps (thesis §3.4) on the floodlit campanile: time and error of
//! synthesis at several texel sizes, then the atlas stored in standard HDR
//! formats, PSNR against size. The truth is exact
//! (`campanile_sim::world::texture_truth`); PSNR is over the texels on the
//! faces that a photograph saw, peak = the truth's brightest texel.
//!
//! Storage: the page's texels through each format and back, compared with
//! the truth (and with the uncompressed texture, to show what the format
//! itself loses). Bytes are the file's size; "per texel" divides by the
//! page's texels (padding and empty space included, as stored).
//!
//! ```text
//! cargo run -p campanile-sim --example texture_bench
//! ```

use std::path::Path;
use std::time::Instant;

use campanile_process::camera::image::RadianceImage;
use campanile_process::hdr::merge::RadianceMap;
use campanile_process::pose::Pinhole;
use campanile_process::radiance_file::read_radiance_image;
use campanile_process::rgbe_file::write_rgbe;
use campanile_process::texture::synthesis::TexelStatus;
use campanile_process::texture::{
    AtlasSettings, Patch, SynthesisSettings, TexturePhoto, pack, patches, pose_from_angles, synthesize,
};
use campanile_sim::world::examples_dir;
use campanile_sim::world::texture_truth::TextureWorld;
use exr::prelude::*;
use nalgebra::Vector3;

const W: usize = 1024;

/// Writes the page to a path in one format.
type Writer<'a> = Box<dyn Fn(&Path) + 'a>;
const H: usize = 768;

fn photos(world: &TextureWorld) -> Vec<TexturePhoto> {
    let s = campanile_config::load_station(&examples_dir().join("sim-station.ron"))
        .expect("station")
        .value;
    let c = &s.camera;
    let pinhole = Pinhole::of_camera(c).rescaled((c.resolution.width as usize, c.resolution.height as usize), W, H);
    let scene = campanile_config::document::load_scene(&examples_dir().join("campanile-scene.ron"))
        .expect("scene")
        .value;
    ["view-se", "view-sw", "view-ne", "view-nw"]
        .iter()
        .enumerate()
        .map(|(k, name)| {
            let p = scene.pose(name).expect("pose");
            let (x, y, z) = p.position_m;
            let pose = pose_from_angles(Vector3::new(x, y, z), p.azimuth_deg, p.elevation_deg, 0.0).expect("pose");
            let blank = RadianceImage {
                width: W,
                height: H,
                data: vec![0.0; W * H * 3],
            };
            let mut photo = TexturePhoto::new(name, blank, &pose, pinhole).expect("photo");
            photo.image = world.photograph(&photo.rig, k as u64 + 1);
            photo
        })
        .collect()
}

/// Per patch, per texel: the page pixel index of each seen texel and its truth.
fn truths(world: &TextureWorld, ps: &[Patch], statuses: &[Vec<TexelStatus>]) -> Vec<Vec<(usize, [f64; 3])>> {
    ps.iter()
        .zip(statuses)
        .map(|(p, st)| {
            let centre = p.texel_centre(p.cols / 2, p.rows / 2);
            let viewpoint = centre + p.normal * 50.0;
            let viewpoint = if viewpoint.norm() > centre.norm() {
                viewpoint
            } else {
                centre - p.normal * 50.0
            };
            let t = world.true_texture(p, &viewpoint, 8);
            (0..p.cols * p.rows)
                .filter(|&k| st[k] == TexelStatus::Seen)
                .map(|k| (k, t[k]))
                .collect()
        })
        .collect()
}

fn psnr(values: &dyn Fn(usize, usize) -> [f64; 3], truth: &[Vec<(usize, [f64; 3])>]) -> f64 {
    let (mut se, mut n, mut peak) = (0.0, 0usize, 0f64);
    for (pi, list) in truth.iter().enumerate() {
        for &(k, t) in list {
            let v = values(pi, k);
            se += (0..3).map(|c| (v[c] - t[c]).powi(2)).sum::<f64>() / 3.0;
            n += 1;
            peak = peak.max(t.iter().copied().fold(0.0, f64::max));
        }
    }
    10.0 * (peak * peak / (se / n.max(1) as f64)).log10()
}

fn write_exr(page: &RadianceImage, path: &Path, compression: Compression, half: bool) {
    let n = page.width * page.height;
    let plane = |c: usize| -> FlatSamples {
        let v = (0..n).map(|p| page.data[p * 3 + c]);
        if half {
            FlatSamples::F16(v.map(f16::from_f32).collect())
        } else {
            FlatSamples::F32(v.collect())
        }
    };
    let channels: Vec<AnyChannel<FlatSamples>> = ["B", "G", "R"]
        .iter()
        .map(|name| {
            AnyChannel::new(
                *name,
                plane(["R", "G", "B"].iter().position(|x| x == name).unwrap_or(0)),
            )
        })
        .collect();
    let layer = Layer::new(
        (page.width, page.height),
        LayerAttributes::default(),
        Encoding {
            compression,
            blocks: Blocks::ScanLines,
            line_order: LineOrder::Increasing,
        },
        AnyChannels::sort(SmallVec::from_vec(channels)),
    );
    Image::from_layer(layer).write().to_file(path).expect("exr written");
}

fn main() {
    let dir = std::env::temp_dir().join(format!("campanile-texture-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("dir");
    let world = TextureWorld::campanile().expect("world");
    let t = Instant::now();
    let shots = photos(&world);
    println!("4 photographs {W}×{H} rendered in {:.2} s", t.elapsed().as_secs_f64());
    let surfaces: Vec<String> = ["south-face", "east-face", "north-face", "west-face"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    println!("| texel | texels on faces | coverage | PSNR (dB) | synthesis (s) | pack (s) |");
    let mut kept = None;
    for texel in [0.5, 0.25, 0.125] {
        let ps = patches(&world.scene, Some(&surfaces), texel, 50_000_000).expect("patches");
        let t = Instant::now();
        let syn = synthesize(&world.scene, &ps, &shots, &SynthesisSettings::default()).expect("synthesis");
        let t_syn = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let atlas = pack(&world.scene, &ps, &syn.textures, &AtlasSettings::default()).expect("pack");
        let t_pack = t.elapsed().as_secs_f64();
        let statuses: Vec<Vec<TexelStatus>> = syn.textures.iter().map(|t| t.status.clone()).collect();
        let truth = truths(&world, &ps, &statuses);
        let db = psnr(&|pi, k| syn.textures[pi].rgb[k].map(f64::from), &truth);
        println!(
            "| {texel} m | {} | {:.3} | {db:.2} | {t_syn:.2} | {t_pack:.3} |",
            syn.report.texels_on_faces,
            syn.report.coverage()
        );
        if texel == 0.25 {
            kept = Some((ps, syn, atlas, truth));
        }
    }
    let Some((ps, _syn, atlas, truth)) = kept else {
        return;
    };
    // Storage of the 0.25 m atlas.
    let page = &atlas.pages[0];
    let image = RadianceImage {
        width: page.width,
        height: page.height,
        data: page.rgb.clone(),
    };
    let texels = page.width * page.height;
    let value_at = |img: &RadianceImage, pi: usize, k: usize| -> [f64; 3] {
        let p = &ps[pi];
        let (i, j) = (k % p.cols, k / p.cols);
        let pl = atlas.placements[pi];
        let (x, y) = (pl.x + atlas.gutter + i, pl.y + atlas.gutter + p.rows - 1 - j);
        let o = (y * img.width + x) * 3;
        [0, 1, 2].map(|c| f64::from(img.data[o + c]))
    };
    let reference = psnr(&|pi, k| value_at(&image, pi, k), &truth);
    println!(
        "\natlas {}×{} ({} pages), {} texels; uncompressed f32 = {} bytes",
        page.width,
        page.height,
        atlas.pages.len(),
        texels,
        texels * 12
    );
    println!(
        "| format | bytes | bytes/texel | ratio to f32 | ratio to half | PSNR vs truth (dB) | PSNR vs uncompressed (dB) | write+read (s) |"
    );
    let formats: Vec<(&str, Writer, &str)> = vec![
        (
            "EXR f32 uncompressed",
            Box::new(|p: &Path| write_exr(&image, p, Compression::Uncompressed, false)),
            "exr",
        ),
        (
            "EXR half uncompressed",
            Box::new(|p: &Path| write_exr(&image, p, Compression::Uncompressed, true)),
            "exr",
        ),
        (
            "EXR half PIZ (lossless)",
            Box::new(|p: &Path| write_exr(&image, p, Compression::PIZ, true)),
            "exr",
        ),
        (
            "EXR half ZIP (lossless)",
            Box::new(|p: &Path| write_exr(&image, p, Compression::ZIP16, true)),
            "exr",
        ),
        (
            "EXR f32 PXR24 (lossy 24-bit)",
            Box::new(|p: &Path| write_exr(&image, p, Compression::PXR24, false)),
            "exr",
        ),
        (
            "EXR half B44 (lossy)",
            Box::new(|p: &Path| write_exr(&image, p, Compression::B44, true)),
            "exr",
        ),
        (
            "EXR half B44A (lossy)",
            Box::new(|p: &Path| write_exr(&image, p, Compression::B44A, true)),
            "exr",
        ),
        (
            "RGBE .hdr (RLE)",
            Box::new(|p: &Path| {
                let map = RadianceMap {
                    width: image.width,
                    height: image.height,
                    rgb: image.data.clone(),
                    variance: Vec::new(),
                    mask: vec![0; texels],
                };
                write_rgbe(&map, p).expect("rgbe");
            }),
            "hdr",
        ),
    ];
    for (k, (name, write, ext)) in formats.iter().enumerate() {
        let path = dir.join(format!("page{k}.{ext}"));
        let t = Instant::now();
        write(&path);
        let back = read_radiance_image(&path).expect("read back").image;
        let secs = t.elapsed().as_secs_f64();
        let bytes = std::fs::metadata(&path).expect("size").len() as usize;
        let db = psnr(&|pi, k| value_at(&back, pi, k), &truth);
        // Against the uncompressed texture: the format's own loss.
        let own = {
            let (mut se, mut n, mut peak) = (0.0, 0usize, 0f64);
            for (pi, list) in truth.iter().enumerate() {
                for &(kk, _) in list {
                    let (a, b) = (value_at(&image, pi, kk), value_at(&back, pi, kk));
                    se += (0..3).map(|c| (a[c] - b[c]).powi(2)).sum::<f64>() / 3.0;
                    n += 1;
                    peak = peak.max(a.iter().copied().fold(0.0, f64::max));
                }
            }
            if se == 0.0 {
                f64::INFINITY
            } else {
                10.0 * (peak * peak / (se / n as f64)).log10()
            }
        };
        println!(
            "| {name} | {bytes} | {:.2} | {:.2}× | {:.2}× | {db:.2} | {own:.1} | {secs:.3} |",
            bytes as f64 / texels as f64,
            (texels * 12) as f64 / bytes as f64,
            (texels * 6) as f64 / bytes as f64,
        );
    }
    println!("(uncompressed texture against the truth: {reference:.2} dB)");
    let _ = std::fs::remove_dir_all(&dir);
}
