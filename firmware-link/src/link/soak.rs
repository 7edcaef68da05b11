//! A seeded soak run: many campanile-link moves through a fault-injecting
//! link to an emulated device, checking that every move is applied exactly
//! once. The fault-tolerance test and the benchmark example both run it.

use super::device::{DeviceConfig, Effect, LinkDevice};
use super::host::{LinkClient, LinkStats, RetryPolicy};
use crate::driver_error::DriverError;
use crate::emulator::Emulator;
use crate::transport::fault::{FaultConfig, FaultyStream};
use crate::transport::memory::duplex;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::time::Duration;

/// The byte-fault chance (drop and corruption, each) up to which the
/// soak proves the link: 10 000 commands at 5 % drop + 5 % corruption
/// complete, each applied exactly once, under [`PROVEN_POLICY`]. At 10 % +
/// 10 % an exchange of about 50 bytes rarely survives (0.8⁵⁰ ≈ 10⁻⁵): a
/// command took 17 751 attempts on average over 100 commands (9 simulated
/// minutes at 30 ms) and some more than 10⁵, so the link cannot hold it.
pub const PROVEN_FAULT_CHANCE: f64 = 0.05;

/// The retry policy that holds a link with [`PROVEN_FAULT_CHANCE`]: 30 ms
/// per attempt, at most 5000 attempts. At 5 % + 5 % an attempt succeeds
/// with a chance of about 1 %, so a command takes about 100 attempts (3 s)
/// and fails all 5000 with a chance of about e⁻⁴⁶.
pub const PROVEN_POLICY: RetryPolicy = RetryPolicy {
    timeout: Duration::from_millis(30),
    max_attempts: 5000,
};

/// What to run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SoakConfig {
    /// Number of move commands.
    pub commands: u32,
    /// Seed of the command sequence.
    pub seed: u64,
    /// Faults on the host's side of the link (both directions).
    pub faults: FaultConfig,
    /// Client retry policy.
    pub policy: RetryPolicy,
}

impl SoakConfig {
    /// The scenario: 2% byte drop, 2% corruption, random stalls
    /// (0.2% of calls stall for 250 ms) and short delays.
    pub fn standard(commands: u32, seed: u64) -> Self {
        Self {
            commands,
            seed,
            faults: FaultConfig {
                seed: seed ^ 0x5eed,
                drop_chance: 0.02,
                corrupt_chance: 0.02,
                duplicate_chance: 0.0,
                delay_chance: 0.01,
                max_delay: Duration::from_millis(5),
                stall_chance: 0.002,
                stall: Duration::from_millis(250),
                disconnect_after: None,
            },
            policy: RetryPolicy {
                timeout: Duration::from_millis(30),
                max_attempts: 500,
            },
        }
    }

    /// [`SoakConfig::standard`] with `chance` of byte drop and `chance` of
    /// corruption, under [`PROVEN_POLICY`].
    pub fn with_faults(commands: u32, seed: u64, chance: f64) -> Self {
        let mut c = Self::standard(commands, seed);
        c.faults.drop_chance = chance;
        c.faults.corrupt_chance = chance;
        c.policy = PROVEN_POLICY;
        c
    }
}

/// What happened.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SoakReport {
    /// Moves commanded (and acknowledged).
    pub commands: u32,
    /// Targets the host commanded, in order (µrad).
    pub commanded: Vec<(i32, i32)>,
    /// Targets the device applied, in order (µrad), from its effects.
    pub applied: Vec<(i32, i32)>,
    /// Where the host expects the head to end (µrad).
    pub expected_final: (i32, i32),
    /// Where the emulated head ended (µrad), after coming to rest.
    pub final_position: (i32, i32),
    /// Client counters.
    pub link: LinkStats,
    /// Requests the device answered from its replay cache.
    pub device_replays: u32,
    /// Bad frames the device discarded.
    pub device_bad_frames: u32,
    /// Fault counters: bytes, dropped, corrupted, duplicated, delays, stalls.
    pub faults: [u64; 6],
    /// Simulated (tokio) time the run took.
    pub link_time: Duration,
}

/// Run the soak. Call inside a tokio runtime (paused time makes it fast).
pub async fn run(config: SoakConfig) -> Result<SoakReport, DriverError> {
    let device_config = DeviceConfig {
        speed: 20_000_000,
        ..DeviceConfig::default()
    };
    let (host_end, device_end) = duplex(1 << 14);
    let emulator = Emulator::spawn(LinkDevice::new(device_config), device_end, Duration::from_millis(5));
    let faulty = FaultyStream::new(host_end, config.faults);
    let fault_stats = faulty.stats();
    let mut client = LinkClient::new(faulty, config.policy, (config.seed as u16).wrapping_mul(7919));
    let mut rng = ChaCha8Rng::seed_from_u64(config.seed);
    let (pan_min, pan_max) = device_config.pan_range;
    let (tilt_min, tilt_max) = device_config.tilt_range;
    let start = tokio::time::Instant::now();
    let mut target = device_config.home;
    let mut commanded = Vec::with_capacity(config.commands as usize);
    for _ in 0..config.commands {
        let state = if rng.random_bool(0.7) {
            // An offset that keeps the target within the limits.
            let dp = rng.random_range((pan_min - target.0).max(-50_000)..=(pan_max - target.0).min(50_000));
            let dt = rng.random_range((tilt_min - target.1).max(-50_000)..=(tilt_max - target.1).min(50_000));
            target = (target.0 + dp, target.1 + dt);
            client.move_by(dp, dt).await?
        } else {
            target = (
                rng.random_range(pan_min..=pan_max),
                rng.random_range(tilt_min..=tilt_max),
            );
            client.move_to(target.0, target.1).await?
        };
        if (state.target_pan, state.target_tilt) != target {
            return Err(DriverError::Protocol(format!(
                "ack carries target ({}, {}), host commanded {target:?}",
                state.target_pan, state.target_tilt
            )));
        }
        commanded.push(target);
    }
    let rest = client
        .wait_idle(Duration::from_millis(50), Duration::from_secs(600))
        .await?;
    let link_time = start.elapsed();
    let applied = emulator
        .effects()
        .iter()
        .filter_map(|e| match *e {
            Effect::HeadMove { pan, tilt, .. } => Some((pan, tilt)),
            _ => None,
        })
        .collect();
    let (final_position, device_stats) = {
        let fw = emulator.firmware();
        let s = fw.head_state();
        ((s.pan, s.tilt), fw.stats())
    };
    debug_assert_eq!((rest.pan, rest.tilt), final_position);
    Ok(SoakReport {
        commands: config.commands,
        commanded,
        applied,
        expected_final: target,
        final_position,
        link: client.stats(),
        device_replays: device_stats.replays,
        device_bad_frames: device_stats.bad_frames,
        faults: fault_stats.snapshot(),
        link_time,
    })
}
