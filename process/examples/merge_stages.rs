//! The stages of `campanile hdr merge` on one bracket of files, timed
//! apart, for `bench/hdr/merge_stages.sh`: decoding every frame alone (one
//! after another, as the streamed merge's decoder thread does), the streamed
//! merge (`merge_files`: frames decoded on their own thread while the
//! previous one is added to the sums), the in-memory merge of the decoded
//! frames, and the OpenEXR encode of the result. The CLI is bounded by
//! decoding and encoding when the streamed merge takes about as long as
//! decoding alone.
//!
//! Usage: `merge_stages DIR [REPEATS]`, where DIR holds `exposure_*.png`,
//! `times.txt` and `campanile_curve.csv` (what `hdr_bench DIR W H` writes).
//! Prints one `key=value` line per figure (best of REPEATS, seconds).

use std::path::{Path, PathBuf};
use std::time::Instant;

use campanile_process::exr_io::{ExrPrecision, write_rgb_exr};
use campanile_process::hdr::bracket::Bracket;
use campanile_process::hdr::bracket_files::BracketFiles;
use campanile_process::hdr::curve::ResponseCurve;
use campanile_process::hdr::image_file::read_frame;
use campanile_process::hdr::merge::{MergeOptions, merge};
use campanile_process::hdr::merge_stream::merge_files;

fn best<T>(repeats: usize, mut f: impl FnMut() -> T) -> (f64, T) {
    let mut out = None;
    let mut best = f64::INFINITY;
    for _ in 0..repeats {
        let t0 = Instant::now();
        let v = f();
        best = best.min(t0.elapsed().as_secs_f64());
        out = Some(v);
    }
    (best, out.expect("repeats ≥ 1"))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let dir = Path::new(
        args.get(1)
            .map(String::as_str)
            .ok_or("usage: merge_stages DIR [REPEATS]")?,
    );
    let repeats = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(3usize).max(1);
    let times: Vec<f64> = std::fs::read_to_string(dir.join("times.txt"))?
        .lines()
        .map(str::parse)
        .collect::<Result<_, _>>()?;
    let paths: Vec<PathBuf> = (0..times.len())
        .map(|j| dir.join(format!("exposure_{j}.png")))
        .collect();
    let curve_path = dir.join("campanile_curve.csv");
    let curve = ResponseCurve::from_csv(&std::fs::read_to_string(&curve_path)?, &curve_path)?;
    let opts = MergeOptions::default();

    let (decode_s, frames) = best(repeats, || {
        paths
            .iter()
            .map(|p| read_frame(p).map(|(im, _)| im))
            .collect::<Result<Vec<_>, _>>()
    });
    let frames = frames?;
    let (w, h) = (frames[0].width, frames[0].height);
    let bracket = Bracket::new(frames, times.clone())?;
    let (in_memory_s, map) = best(repeats, || merge(&bracket, &curve, &opts));
    let map = map?;
    drop(bracket);
    let files = BracketFiles::open(&paths, Some(&times))?;
    let (streamed_s, streamed) = best(repeats, || merge_files(&files, &curve, &opts, &|_| {}));
    let (streamed, _) = streamed?;
    let same = streamed.rgb == map.rgb;
    let out = dir.join("merge_stages.exr");
    let (encode_s, written) = best(repeats, || write_rgb_exr(&streamed, &out, ExrPrecision::Float));
    written?;
    println!("width={w}");
    println!("height={h}");
    println!("exposures={}", times.len());
    println!("threads={}", rayon::current_num_threads());
    println!("decode_alone_s={decode_s:.3}");
    println!("in_memory_merge_s={in_memory_s:.3}");
    println!("streamed_merge_s={streamed_s:.3}");
    println!("streamed_over_decode={:.3}", streamed_s / decode_s);
    println!("encode_exr_s={encode_s:.3}");
    println!("bound_decode_plus_encode_s={:.3}", decode_s + encode_s);
    println!("streamed_plus_encode_s={:.3}", streamed_s + encode_s);
    println!("streamed_equals_in_memory={same}");
    Ok(())
}
