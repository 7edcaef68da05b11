//! Criterion benchmarks of response recovery and merging on a 512×384,
//! 7-exposure, 8-bit bracket of the synthetic chart. The comparison with
//! OpenCV (and the figures in BENCHMARKS) comes from `bench/hdr/run.sh`.

use std::hint::black_box;

use campanile_process::camera::sensor::CameraModel;
use campanile_process::camera::test_chart::{SEVEN_STOP_TIMES_S, hdr_chart};
use campanile_process::hdr::bracket::Bracket;
use campanile_process::hdr::debevec::{DebevecOptions, calibrate_debevec};
use campanile_process::hdr::merge::{MergeOptions, merge, merge_into};
use campanile_process::hdr::sampling::SampleOptions;
use criterion::{Criterion, Throughput, criterion_group, criterion_main};

fn bracket() -> Bracket {
    let cam = CameraModel::typical(8);
    let scene = hdr_chart(512, 384);
    let images = SEVEN_STOP_TIMES_S
        .iter()
        .enumerate()
        .map(|(j, &t)| cam.photograph(&scene, t, 7 + j as u64))
        .collect();
    Bracket::new(images, SEVEN_STOP_TIMES_S.to_vec()).expect("valid bracket")
}

fn benches(c: &mut Criterion) {
    let b = bracket();
    let mut g = c.benchmark_group("hdr");
    g.sample_size(20);
    for samples in [1000usize, 4000] {
        let opts = DebevecOptions {
            sampling: SampleOptions {
                samples,
                ..Default::default()
            },
            ..Default::default()
        };
        g.bench_function(format!("calibrate_debevec_{samples}_samples"), |bench| {
            bench.iter(|| calibrate_debevec(black_box(&b), &opts).expect("calibrates"))
        });
    }
    let curve = calibrate_debevec(&b, &DebevecOptions::default())
        .expect("calibrates")
        .curve;
    let opts = MergeOptions::default();
    let mut out = merge(&b, &curve, &opts).expect("merges");
    g.throughput(Throughput::Elements((b.width() * b.height() * b.len()) as u64));
    g.bench_function("merge_7x512x384", |bench| {
        bench.iter(|| merge_into(black_box(&b), &curve, &opts, &mut out).expect("merges"))
    });
    g.finish();
}

criterion_group!(hdr, benches);
criterion_main!(hdr);
