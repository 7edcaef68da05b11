//! Whether the process that wrote a heartbeat still runs.
//!
//! A heartbeat names its writer by host name, boot id, PID and the
//! process's start time (field 22 of `/proc/PID/stat`, in clock ticks
//! since boot). On the same host and boot, the writer runs when
//! `/proc/PID/stat` exists with that start time: a PID that is gone, or
//! reused by another process (another start time), means the station was
//! killed (a station that stops writes `stopped`, `finished` or `failed`).
//! A heartbeat from another host can only be judged by its age.

use std::path::Path;

/// Who wrote a heartbeat.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ProcessIdentity {
    /// The host name.
    pub host: String,
    /// `/proc/sys/kernel/random/boot_id`, when readable.
    pub boot_id: Option<String>,
    /// The process start time, clock ticks after boot.
    pub start_ticks: u64,
}

impl ProcessIdentity {
    /// This process, or `None` where `/proc` cannot tell (not Linux).
    pub fn of_self() -> Option<Self> {
        Some(Self {
            host: host_name()?,
            boot_id: boot_id(),
            start_ticks: start_ticks(std::process::id())?,
        })
    }
}

/// This computer's host name (`/proc/sys/kernel/hostname`, or `/etc/hostname`).
pub fn host_name() -> Option<String> {
    ["/proc/sys/kernel/hostname", "/etc/hostname"]
        .iter()
        .find_map(|p| read_trimmed(Path::new(p)))
}

fn boot_id() -> Option<String> {
    read_trimmed(Path::new("/proc/sys/kernel/random/boot_id"))
}

fn read_trimmed(path: &Path) -> Option<String> {
    let text = std::fs::read_to_string(path).ok()?;
    let text = text.trim();
    (!text.is_empty()).then(|| text.to_owned())
}

/// Start time of process `pid` in clock ticks after boot, `None` when there
/// is no such process (or no `/proc`).
pub fn start_ticks(pid: u32) -> Option<u64> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    parse_start_ticks(&stat)
}

/// Field 22 of a `/proc/PID/stat` line. The command name (field 2) is in
/// parentheses and may hold spaces and parentheses, so fields are counted
/// from the last `)`: field 3 is the first after it.
fn parse_start_ticks(stat: &str) -> Option<u64> {
    let after = &stat[stat.rfind(')')? + 1..];
    after.split_whitespace().nth(22 - 3)?.parse().ok()
}

/// What can be said of a heartbeat's writer.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Liveness {
    /// Same host, same boot, the PID runs with the same start time.
    Running,
    /// The writer is gone; why (PID gone, PID reused, host restarted).
    NotRunning(String),
    /// Written on another host, named here: only its age tells.
    OtherHost(String),
    /// Cannot be checked (an older heartbeat without the identity, or no
    /// `/proc` here); why.
    Unknown(String),
}

/// Whether process `pid`, identified by `identity` when it wrote its
/// heartbeat, still runs here.
pub fn liveness(pid: u32, identity: Option<&ProcessIdentity>) -> Liveness {
    let Some(id) = identity else {
        return Liveness::Unknown(format!(
            "the heartbeat names no host or start time (written by an older campanile), so whether pid {pid} \
             still runs cannot be checked"
        ));
    };
    let Some(here) = host_name() else {
        return Liveness::Unknown("this computer's host name cannot be read".to_owned());
    };
    if here != id.host {
        return Liveness::OtherHost(id.host.clone());
    }
    if let (Some(then), Some(now)) = (&id.boot_id, boot_id())
        && *then != now
    {
        return Liveness::NotRunning(format!("{here} has restarted since pid {pid} wrote it"));
    }
    match start_ticks(pid) {
        None => Liveness::NotRunning(format!("pid {pid} is gone")),
        Some(t) if t != id.start_ticks => Liveness::NotRunning(format!(
            "pid {pid} is another process now (started at tick {t}, not {})",
            id.start_ticks
        )),
        Some(_) => Liveness::Running,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn field_22_is_counted_after_the_last_parenthesis() {
        let stat = "4242 (a (b) c) S 1 4242 4242 0 -1 4194560 500 0 0 0 7 3 0 0 20 0 1 0 987654 1000 200";
        assert_eq!(parse_start_ticks(stat), Some(987_654));
        assert_eq!(parse_start_ticks("4242 (x) S 1 2"), None);
    }

    #[test]
    fn this_process_runs_and_a_dead_pid_does_not() {
        let Some(me) = ProcessIdentity::of_self() else {
            return; // no /proc: nothing to check
        };
        assert_eq!(liveness(std::process::id(), Some(&me)), Liveness::Running);
        let older = ProcessIdentity {
            start_ticks: me.start_ticks + 1,
            ..me.clone()
        };
        assert!(
            matches!(liveness(std::process::id(), Some(&older)), Liveness::NotRunning(w) if w.contains("another process"))
        );
        let elsewhere = ProcessIdentity {
            host: format!("{}-elsewhere", me.host),
            ..me
        };
        assert_eq!(
            liveness(std::process::id(), Some(&elsewhere)),
            Liveness::OtherHost(elsewhere.host.clone())
        );
        assert!(matches!(liveness(1, None), Liveness::Unknown(_)));
    }
}
