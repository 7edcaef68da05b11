//! Issue 3, "Fault tolerance": with 2% byte drop, 2% corruption and random
//! stalls, 10,000 campanile-link commands complete; the emulated head ends
//! where it was commanded, and every move is applied exactly once.

use campanile_firmware_link::link::soak::{PROVEN_FAULT_CHANCE, SoakConfig, run};

#[tokio::test(start_paused = true)]
async fn ten_thousand_moves_through_a_faulty_link() {
    let report = run(SoakConfig::standard(10_000, 42))
        .await
        .expect("every command completes");
    assert_eq!(report.commands, 10_000);
    // No move lost, none applied twice, none reordered.
    assert_eq!(report.applied.len(), 10_000);
    assert_eq!(report.applied, report.commanded);
    assert_eq!(report.final_position, report.expected_final);
    // The faults really happened, and the link really had to retry.
    let [bytes, dropped, corrupted, _, _, stalls] = report.faults;
    assert!(dropped as f64 > 0.015 * bytes as f64, "{:?}", report.faults);
    assert!(corrupted as f64 > 0.015 * bytes as f64, "{:?}", report.faults);
    assert!(stalls > 0);
    assert!(report.link.retries > 1000, "{:?}", report.link);
    assert!(
        report.device_replays > 0,
        "retries whose request had arrived are replayed"
    );
    // 10,000 moves plus at least one status poll at the end.
    assert!(report.link.requests > 10_000);
}

/// Issue 21: the link holds the whole range the capture flags accept: at
/// 5 % byte drop + 5 % corruption, 10,000 commands complete, none lost,
/// doubled or reordered.
#[tokio::test(start_paused = true)]
async fn ten_thousand_moves_at_five_percent_drop_and_corruption() {
    let report = run(SoakConfig::with_faults(10_000, 42, PROVEN_FAULT_CHANCE))
        .await
        .expect("every command completes");
    assert_eq!(report.applied.len(), 10_000);
    assert_eq!(report.applied, report.commanded);
    assert_eq!(report.final_position, report.expected_final);
    let [bytes, dropped, corrupted, ..] = report.faults;
    // 5 % ± 0.5 % of the bytes each.
    for (what, n) in [("dropped", dropped), ("corrupted", corrupted)] {
        let share = n as f64 / bytes as f64;
        assert!((share - 0.05).abs() < 0.005, "{what}: {share} of {bytes} bytes");
    }
    // About 100 attempts per command (an attempt succeeds about 1 % of the time).
    let per_command = report.link.retries as f64 / 10_000.0;
    assert!(
        (30.0..300.0).contains(&per_command),
        "{per_command} retries per command"
    );
}
