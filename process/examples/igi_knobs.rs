//! Runs the IGI solver on a scene file with the knobs given on the command
//! line, writing `OUT/materials.json` as `campanile igi` does (the records
//! only), for error-against-knob studies on the validation rooms
//! (`validation/igi`).
//!
//! `cargo run --release -p campanile-process --example igi_knobs -- SCENE OUT
//! [cells_per_edge gather_rays lobe_rays iterations seed lobe_ray_factor_max lobe_ray_block correct_noise sparse_samples point_gather_rays reweight_delta_s]`
//! (`correct_noise` and `reweight_delta_s` 0 or 1, `IgiOptions::correct_noise`, `IgiOptions::reweight_delta_s`; the command line's
//! full settings are `12 4096 16 3 SEED 8 1 1 2500 0 1`)

use campanile_process::brdf::WardVariant;
use campanile_process::igi::material_record::{records, variant_name};
use campanile_process::igi::scene_file::load;
use campanile_process::igi::{IgiOptions, recover};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 3 {
        eprintln!("usage: igi_knobs SCENE OUT [cells gather lobe iterations seed factor block correct_noise sparse]");
        std::process::exit(2);
    }
    let knob = |i: usize, d: u64| args.get(i).and_then(|a| a.parse().ok()).unwrap_or(d);
    let loaded = match load(std::path::Path::new(&args[1])) {
        Ok(l) => l,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(2);
        }
    };
    let options = IgiOptions {
        variant: loaded
            .ward_variant
            .and_then(|v| v.variant())
            .unwrap_or(WardVariant::Ward1992),
        interreflection: loaded.interreflection.unwrap_or(true),
        cells_per_edge: knob(3, 6) as usize,
        gather_rays: knob(4, 64) as u32,
        lobe_rays: knob(5, 16) as u32,
        lobe_ray_factor_max: knob(8, 1) as u32,
        lobe_ray_block: knob(9, 1) as usize,
        iterations: knob(6, 4) as u32,
        seed: knob(7, 1),
        correct_noise: knob(10, 0) != 0,
        sparse_samples: knob(11, 2500) as usize,
        point_gather_rays: knob(12, 0) as u32,
        reweight_delta_s: knob(13, 0) != 0,
        ..IgiOptions::default()
    };
    let r = match recover(&loaded.input, &options) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(1);
        }
    };
    let cams = &loaded.cameras;
    let inside = cams.iter().map(|(_, c)| c.position).sum::<nalgebra::Vector3<f64>>() / cams.len().max(1) as f64;
    let json = serde_json::json!({
        "variant": variant_name(r.variant),
        "surfaces": records(&loaded.input, &r, &inside),
        "seconds": r.seconds,
    });
    let out = std::path::Path::new(&args[2]);
    std::fs::create_dir_all(out).expect("output directory");
    std::fs::write(out.join("materials.json"), serde_json::to_string_pretty(&json).unwrap()).expect("write");
    for (i, it) in r.iterations.iter().enumerate() {
        println!(
            "pass {}: {:.2} s (gather {:.2}, ΔS {:.2}, fit {:.2}), largest relative change {:.4}",
            i + 1,
            it.seconds,
            it.gather_seconds,
            it.delta_s_seconds,
            it.fit_seconds,
            it.max_relative_change
        );
    }
    println!("{:.2} s; {}", r.seconds, r.interreflection.message);
}
