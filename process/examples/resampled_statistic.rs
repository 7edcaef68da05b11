//! Prints the resampling statistic of `hdr::resampled` for each image file
//! given, on the same central crop (at most 512² pixels) of the green channel
//! that `check_not_resampled` examines. Used by `validation/hdr/resampled.py`
//! to measure the detector on real camera files and on resampled copies.
//!
//! Usage: `resampled_statistic FILE...`
//! Prints a CSV on stdout: `file,width,height,rows,columns,mean,pairs`
//! (`rows`, `columns`, `mean` and `pairs` empty when the crop has too few
//! usable pairs for a verdict). A file that cannot be read is reported on
//! stderr and the example exits 1 after the others.

use std::path::Path;

use campanile_process::camera::image::CodeImage;
use campanile_process::hdr::image_file::read_code_image;
use campanile_process::hdr::resampled::second_difference_autocorrelation;

/// Side of the central crop, as in `check_not_resampled`.
const CHECK_SIZE: usize = 512;

fn central_crop(img: &CodeImage) -> CodeImage {
    let (cw, ch) = (img.width.min(CHECK_SIZE), img.height.min(CHECK_SIZE));
    let (x0, y0) = ((img.width - cw) / 2, (img.height - ch) / 2);
    let mut data = Vec::with_capacity(cw * ch * 3);
    for y in y0..y0 + ch {
        data.extend_from_slice(&img.data[(y * img.width + x0) * 3..(y * img.width + x0 + cw) * 3]);
    }
    CodeImage {
        width: cw,
        height: ch,
        bits: img.bits,
        data,
        label: img.label.clone(),
    }
}

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
        let crop = central_crop(&img);
        match second_difference_autocorrelation(&crop, 1) {
            Some((rh, rv, n)) => println!(
                "{f},{},{},{rh:.4},{rv:.4},{:.4},{n}",
                img.width,
                img.height,
                0.5 * (rh + rv)
            ),
            None => println!("{f},{},{},,,,", img.width, img.height),
        }
    }
    if failed {
        std::process::exit(1);
    }
}
