//! The FLIR (formerly Directed Perception) PTU ASCII protocol.
//!
//! Commands are `<command><parameter><delimiter>` and queries
//! `<command><delimiter>`, where the delimiter is a space or a carriage
//! return (this crate sends a space, as in the manual's examples:
//! `PP-2500 `). Replies are lines:
//!
//! - `*` after a successful command; `* <result>` after a query (terse mode,
//!   `FT`; verbose mode, `FV`, words the result, e.g.
//!   `* Current Pan position is -2500`);
//! - `! <message>` after a failed command;
//! - `!P` and `!T`, sent asynchronously when the pan or tilt axis hits a
//!   limit, and `!D` (passed through as [`Unsolicited::Other`]), which can
//!   arrive between a command and its reply.
//!
//! With echo on (the power-on default; `ED` turns it off) the unit echoes
//! the command on the same line before its reply (`PP * 22`); the reply
//! parser skips such an echo. Positions are in the unit's native steps;
//! `PR`/`TR` give the resolution in arc-seconds per step.

pub mod device;
#[cfg(feature = "std")]
pub mod host;

/// A pan-tilt axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Axis {
    /// Pan (`P…` commands).
    Pan,
    /// Tilt (`T…` commands).
    Tilt,
}

impl Axis {
    fn letter(self) -> u8 {
        match self {
            Axis::Pan => b'P',
            Axis::Tilt => b'T',
        }
    }
}

/// A settable axis parameter.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Setting {
    /// `PP`/`TP`: absolute position, steps.
    Position,
    /// `PO`/`TO`: offset from the current position, steps.
    Offset,
    /// `PS`/`TS`: speed, steps/s.
    Speed,
    /// `PA`/`TA`: acceleration, steps/s².
    Acceleration,
}

/// A queryable axis value.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Query {
    /// `PP`/`TP`: current position.
    Position,
    /// `PS`/`TS`: speed.
    Speed,
    /// `PA`/`TA`: acceleration.
    Acceleration,
    /// `PR`/`TR`: resolution, arc-seconds per step.
    Resolution,
    /// `PN`/`TN`: minimum position.
    Min,
    /// `PX`/`TX`: maximum position.
    Max,
}

/// Host commands this crate sends.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Command {
    /// `FT`: terse feedback.
    Terse,
    /// `FV`: verbose feedback.
    Verbose,
    /// `ED`: echo off.
    EchoOff,
    /// `EE`: echo on.
    EchoOn,
    /// Set an axis parameter.
    Set(Axis, Setting, i32),
    /// Query an axis value.
    Get(Axis, Query),
    /// `A`: wait until the last position commands are done.
    Await,
    /// `H`: halt both axes.
    Halt,
    /// `LE`: enforce position limits.
    LimitsOn,
    /// `LD`: do not enforce position limits.
    LimitsOff,
    /// `R`: reset (recalibrate) the axes.
    Reset,
}

/// Longest command this crate encodes (`PP-2147483648 `).
pub const MAX_COMMAND: usize = 16;

impl Command {
    /// The command's bytes, delimiter included; returns the length used.
    pub fn encode(&self, out: &mut [u8; MAX_COMMAND]) -> usize {
        let mut n = 0;
        let mut put = |bytes: &[u8]| {
            for &b in bytes {
                if n < MAX_COMMAND {
                    out[n] = b;
                    n += 1;
                }
            }
        };
        match *self {
            Command::Terse => put(b"FT"),
            Command::Verbose => put(b"FV"),
            Command::EchoOff => put(b"ED"),
            Command::EchoOn => put(b"EE"),
            Command::Await => put(b"A"),
            Command::Halt => put(b"H"),
            Command::LimitsOn => put(b"LE"),
            Command::LimitsOff => put(b"LD"),
            Command::Reset => put(b"R"),
            Command::Set(axis, s, v) => {
                let second = match s {
                    Setting::Position => b'P',
                    Setting::Offset => b'O',
                    Setting::Speed => b'S',
                    Setting::Acceleration => b'A',
                };
                put(&[axis.letter(), second]);
                let mut digits = [0u8; 11];
                let len = format_i32(v, &mut digits);
                put(&digits[..len]);
            }
            Command::Get(axis, q) => {
                let second = match q {
                    Query::Position => b'P',
                    Query::Speed => b'S',
                    Query::Acceleration => b'A',
                    Query::Resolution => b'R',
                    Query::Min => b'N',
                    Query::Max => b'X',
                };
                put(&[axis.letter(), second]);
            }
        }
        put(b" ");
        n
    }
}

/// Write `v` in decimal; returns the length (at most 11).
pub(crate) fn format_i32(v: i32, out: &mut [u8; 11]) -> usize {
    let mut tmp = [0u8; 11];
    let mut n = 0;
    let neg = v < 0;
    let mut m = i64::from(v).unsigned_abs();
    loop {
        tmp[n] = b'0' + (m % 10) as u8;
        n += 1;
        m /= 10;
        if m == 0 {
            break;
        }
    }
    let mut len = 0;
    if neg {
        out[0] = b'-';
        len = 1;
    }
    for i in (0..n).rev() {
        out[len] = tmp[i];
        len += 1;
    }
    len
}

/// Parse a decimal integer (optional sign); `None` if not exactly one.
pub(crate) fn parse_i64(s: &[u8]) -> Option<i64> {
    let (neg, digits) = match s.first()? {
        b'-' => (true, &s[1..]),
        b'+' => (false, &s[1..]),
        _ => (false, s),
    };
    if digits.is_empty() || digits.len() > 18 {
        return None;
    }
    let mut v: i64 = 0;
    for &d in digits {
        if !d.is_ascii_digit() {
            return None;
        }
        v = v * 10 + i64::from(d - b'0');
    }
    Some(if neg { -v } else { v })
}

/// An unsolicited line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Unsolicited {
    /// `!P`: the pan axis hit a limit.
    PanLimit,
    /// `!T`: the tilt axis hit a limit.
    TiltLimit,
    /// Another `!X` code (for example `!D`), passed through.
    Other(u8),
}

/// One reply line, parsed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reply<'a> {
    /// `*`: the command succeeded.
    Ack,
    /// `* <result>`: a query's result text.
    Value(&'a [u8]),
    /// `!` or `! <message>`: the command failed.
    Error(&'a [u8]),
    /// `!P`, `!T`, `!D`: asynchronous.
    Unsolicited(Unsolicited),
    /// A line with no `*` or `!` status.
    Unrecognized(&'a [u8]),
}

impl<'a> Reply<'a> {
    /// Parse one line (terminators already removed). Never panics.
    pub fn parse(line: &'a [u8]) -> Self {
        let line = trim(line);
        if line.len() == 2 && line[0] == b'!' && line[1].is_ascii_alphabetic() {
            return Reply::Unsolicited(match line[1].to_ascii_uppercase() {
                b'P' => Unsolicited::PanLimit,
                b'T' => Unsolicited::TiltLimit,
                c => Unsolicited::Other(c),
            });
        }
        // Skip an echoed command: the status starts at the first `*`/`!` that
        // begins the line or follows a space.
        let start = line
            .iter()
            .enumerate()
            .position(|(i, &b)| (b == b'*' || b == b'!') && (i == 0 || line[i - 1] == b' '));
        let Some(start) = start else {
            return Reply::Unrecognized(line);
        };
        let rest = trim(&line[start + 1..]);
        if line[start] == b'!' {
            Reply::Error(rest)
        } else if rest.is_empty() {
            Reply::Ack
        } else {
            Reply::Value(rest)
        }
    }

    /// The integer a query returned: the last word of the result (so both
    /// terse `* -2500` and verbose `* Current Pan position is -2500` work).
    pub fn integer(&self) -> Option<i64> {
        match self {
            Reply::Value(v) => parse_i64(v.rsplit(|&b| b == b' ').next()?),
            _ => None,
        }
    }

    /// The number a query returned, allowing a fraction (e.g. `PR`'s
    /// `185.1428`): the first word that parses, in thousandths.
    pub fn milli(&self) -> Option<i64> {
        let Reply::Value(v) = self else { return None };
        v.split(|&b| b == b' ').find_map(parse_milli)
    }
}

/// Parse `[-]int[.frac]` as thousandths (rounded down in magnitude).
fn parse_milli(s: &[u8]) -> Option<i64> {
    let mut parts = s.splitn(2, |&b| b == b'.');
    let int = parts.next()?;
    let frac = parts.next().unwrap_or(b"");
    let neg = int.first() == Some(&b'-');
    let i = if int == b"-" { 0 } else { parse_i64(int)? };
    let mut f: i64 = 0;
    for k in 0..3 {
        let d = match frac.get(k) {
            Some(d) if d.is_ascii_digit() => i64::from(d - b'0'),
            Some(_) => return None,
            None => 0,
        };
        f = f * 10 + d;
    }
    if frac.iter().any(|d| !d.is_ascii_digit()) {
        return None;
    }
    let v = i.checked_abs()?.checked_mul(1000)?.checked_add(f)?;
    Some(if neg { -v } else { v })
}

fn trim(mut s: &[u8]) -> &[u8] {
    while let [b' ' | b'\r' | b'\n' | b'\t', rest @ ..] = s {
        s = rest;
    }
    while let [rest @ .., b' ' | b'\r' | b'\n' | b'\t'] = s {
        s = rest;
    }
    s
}

/// Whether `b` ends a reply line.
pub fn is_reply_terminator(b: u8) -> bool {
    b == b'\r' || b == b'\n'
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn enc(c: Command) -> Vec<u8> {
        let mut b = [0u8; MAX_COMMAND];
        let n = c.encode(&mut b);
        b[..n].to_vec()
    }

    /// The command lines of the manual's position example
    /// (`PP-2500 *`, `A *`, `PP * Current Pan position is -2500`, …).
    #[test]
    fn manual_examples_encode() {
        assert_eq!(enc(Command::Set(Axis::Pan, Setting::Position, -2500)), b"PP-2500 ");
        assert_eq!(enc(Command::Await), b"A ");
        assert_eq!(enc(Command::Get(Axis::Pan, Query::Position)), b"PP ");
        assert_eq!(enc(Command::Set(Axis::Pan, Setting::Position, 2500)), b"PP2500 ");
        assert_eq!(enc(Command::Terse), b"FT ");
        assert_eq!(enc(Command::EchoOff), b"ED ");
        assert_eq!(enc(Command::Set(Axis::Tilt, Setting::Offset, 100)), b"TO100 ");
        assert_eq!(enc(Command::Set(Axis::Pan, Setting::Speed, 1000)), b"PS1000 ");
        assert_eq!(enc(Command::Set(Axis::Pan, Setting::Acceleration, 2000)), b"PA2000 ");
        assert_eq!(enc(Command::Get(Axis::Pan, Query::Resolution)), b"PR ");
        assert_eq!(enc(Command::Get(Axis::Tilt, Query::Min)), b"TN ");
        assert_eq!(enc(Command::Get(Axis::Pan, Query::Max)), b"PX ");
        assert_eq!(enc(Command::Halt), b"H ");
        assert_eq!(
            enc(Command::Set(Axis::Pan, Setting::Position, i32::MIN)),
            b"PP-2147483648 "
        );
    }

    /// Reply lines as printed in the manual.
    #[test]
    fn manual_examples_parse() {
        assert_eq!(Reply::parse(b"*"), Reply::Ack);
        assert_eq!(Reply::parse(b"PP-2500 *"), Reply::Ack);
        let v = Reply::parse(b"PP * Current Pan position is -2500");
        assert_eq!(v.integer(), Some(-2500));
        assert_eq!(Reply::parse(b"* 22").integer(), Some(22));
        assert_eq!(Reply::parse(b"* 185.1428").milli(), Some(185_142));
        assert_eq!(
            Reply::parse(b"PP3200 ! Maximum allowable Pan position is 3090"),
            Reply::Error(b"Maximum allowable Pan position is 3090")
        );
        assert_eq!(Reply::parse(b"!P"), Reply::Unsolicited(Unsolicited::PanLimit));
        assert_eq!(Reply::parse(b"!T"), Reply::Unsolicited(Unsolicited::TiltLimit));
        assert_eq!(Reply::parse(b"!D"), Reply::Unsolicited(Unsolicited::Other(b'D')));
        assert_eq!(Reply::parse(b"TX * Maximum Tilt position is 604").integer(), Some(604));
    }

    proptest! {
        #[test]
        fn set_round_trips_through_parse(v: i32) {
            let e = enc(Command::Set(Axis::Pan, Setting::Position, v));
            prop_assert_eq!(parse_i64(&e[2..e.len() - 1]), Some(i64::from(v)));
        }

        #[test]
        fn parse_never_panics(line in proptest::collection::vec(any::<u8>(), 0..80)) {
            let r = Reply::parse(&line);
            let _ = r.integer();
            let _ = r.milli();
        }
    }
}
