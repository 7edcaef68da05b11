//! Times `sun_positions` on a CSV of requests (the format of
//! `campanile sun --csv`), and writes the positions, for `bench/sun/run.sh`.
//!
//!     cargo run --release -p campanile-process --example sun_throughput -- IN.csv OUT.csv REPEATS

use std::time::Instant;

use campanile_process::sun::{Observer, SunRequest, sun_positions};
use chrono::{DateTime, Utc};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let [_, input, output, repeats] = args.as_slice() else {
        return Err("usage: sun_throughput IN.csv OUT.csv REPEATS".into());
    };
    let repeats: usize = repeats.parse()?;
    let mut rd = csv::Reader::from_path(input)?;
    let mut reqs = Vec::new();
    for rec in rd.records() {
        let r = rec?;
        let f = |i: usize| -> Result<f64, Box<dyn std::error::Error>> { Ok(r[i].parse::<f64>()?) };
        reqs.push(SunRequest {
            time: DateTime::parse_from_rfc3339(&r[0])?.with_timezone(&Utc),
            observer: Observer::from_degrees(f(1)?, f(2)?, f(3)?, f(4)?, f(5)?),
            delta_t_s: Some(f(6)?),
        });
    }
    let mut answers = sun_positions(&reqs);
    let start = Instant::now();
    for _ in 0..repeats {
        answers = sun_positions(&reqs);
    }
    let secs = start.elapsed().as_secs_f64();
    let mut wr = csv::Writer::from_path(output)?;
    wr.write_record(["zenith_deg", "azimuth_deg"])?;
    for a in &answers {
        let a = a.as_ref().map_err(|e| e.to_string())?;
        wr.write_record([
            format!("{:.9}", a.position.zenith_rad.to_degrees()),
            format!("{:.9}", a.position.azimuth_rad.to_degrees()),
        ])?;
    }
    wr.flush()?;
    println!("{}", (reqs.len() * repeats) as f64 / secs);
    Ok(())
}
