//! Prints the resampling statistic of `hdr::resampled` for each image file
//! given, on the same central crop (at most 512² pixels) of the green channel
//! that calibration once examined (`hdr::resampled::central_crop_statistic`). Used by `validation/hdr/resampled.py`
//! to measure the detector on real camera files and on resampled copies.
//!
//! Usage: `resampled_statistic FILE...`
//! Prints a CSV on stdout: `file,width,height,rows,columns,mean,pairs`
//! (`rows`, `columns`, `mean` and `pairs` empty when the crop has too few
//! usable pairs for a verdict). A file that cannot be read is reported on
//! stderr and the example exits 1 after the others.

use std::path::Path;

use campanile_process::hdr::image_file::read_code_image;
use campanile_process::hdr::resampled::central_crop_statistic;

fn main() {
    let files: Vec<String> = std::env::args().skip(1).collect();
    if files.is_empty() {
        eprintln!("usage: resampled_statistic FILE...");
        std::process::exit(2);
    }
    println!("file,width,height,rows,columns,mean,pairs");
    let mut failed = false;
    for f in &files {
        let img = match read_code_image(Path::new(f)) {
            Ok(img) => img,
            Err(e) => {
                eprintln!("resampled_statistic: {e}");
                failed = true;
                continue;
            }
        };
        match central_crop_statistic(&img) {
            Some(e) => println!(
                "{f},{},{},{:.4},{:.4},{:.4},{}",
                img.width, img.height, e.rows, e.columns, e.mean, e.pairs
            ),
            None => println!("{f},{},{},,,,", img.width, img.height),
        }
    }
    if failed {
        std::process::exit(1);
    }
}
