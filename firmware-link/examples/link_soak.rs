//! campanile-link soak benchmark: N moves through a fault-injecting link to
//! the emulated device, on tokio's paused clock. Prints the retry count and
//! the throughput (simulated link time and wall time).
//!
//! ```text
//! cargo run --release -p campanile-firmware-link --example link_soak -- \
//!     [--commands 10000] [--seed 42] [--drop-chance 0.02] [--corrupt-chance 0.02] \
//!     [--max-attempts N (30 ms each; default 500)]
//! ```

use campanile_firmware_link::link::soak::{PROVEN_POLICY, SoakConfig, run};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut commands = 10_000u32;
    let mut seed = 42u64;
    let mut drop = 0.02f64;
    let mut corrupt = 0.02f64;
    let mut max_attempts = None;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let v = args.next().ok_or(format!("{a} needs a value"))?;
        match a.as_str() {
            "--commands" => commands = v.parse()?,
            "--seed" => seed = v.parse()?,
            "--drop-chance" => drop = v.parse()?,
            "--corrupt-chance" => corrupt = v.parse()?,
            "--max-attempts" => max_attempts = Some(v.parse()?),
            other => return Err(format!("unknown flag {other}").into()),
        }
    }
    let mut config = SoakConfig::standard(commands, seed);
    config.faults.drop_chance = drop;
    config.faults.corrupt_chance = corrupt;
    if let Some(n) = max_attempts {
        config.policy = PROVEN_POLICY;
        config.policy.max_attempts = n;
    }
    let rt = tokio::runtime::Builder::new_current_thread()
        .enable_time()
        .start_paused(true)
        .build()?;
    let wall = Instant::now();
    let r = rt.block_on(run(config))?;
    let wall = wall.elapsed();
    let ok = r.applied == r.commanded && r.final_position == r.expected_final;
    let [bytes, dropped, corrupted, _, delays, stalls] = r.faults;
    println!("commands            {}", r.commands);
    println!(
        "exactly once        {ok} (applied {}, final {:?}, expected {:?})",
        r.applied.len(),
        r.final_position,
        r.expected_final
    );
    println!(
        "retries             {} ({:.2} per command)",
        r.link.retries,
        r.link.retries as f64 / f64::from(r.commands)
    );
    println!("host bad frames     {}", r.link.bad_frames);
    println!("device bad frames   {}", r.device_bad_frames);
    println!("device replays      {}", r.device_replays);
    println!(
        "faults              {bytes} bytes: {dropped} dropped, {corrupted} corrupted, {delays} delays, {stalls} stalls"
    );
    println!(
        "simulated link time {:.1} s -> {:.0} commands/s",
        r.link_time.as_secs_f64(),
        f64::from(r.commands) / r.link_time.as_secs_f64()
    );
    println!(
        "wall time           {:.3} s -> {:.0} commands/s",
        wall.as_secs_f64(),
        f64::from(r.commands) / wall.as_secs_f64()
    );
    if ok {
        Ok(())
    } else {
        Err("a move was lost or applied twice".into())
    }
}
