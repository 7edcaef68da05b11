//! The Thorlabs FW102C filter wheel's command line.
//!
//! Commands are ASCII, terminated by a carriage return: `pos=n` selects
//! filter `n` (1-based), `pos?` asks for the current one, `pcount?` for the
//! number of positions (6 or 12), `*idn?` for the identity. The wheel echoes
//! each command, prints a query's result on its own line, and ends every
//! answer with the `>` prompt; a bad command is answered with
//! `Command error CMD_NOT_DEFINED` (or `CMD_ARG_INVALID`) before the prompt.

pub mod device;
#[cfg(feature = "std")]
pub mod host;

use crate::flir_ptu::parse_i64;

/// The prompt that ends every answer.
pub const PROMPT: u8 = b'>';

/// Commands this crate sends.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Command {
    /// `pos=n`: move to filter `n` (1-based).
    SetPosition(u8),
    /// `pos?`.
    GetPosition,
    /// `pcount?`.
    GetCount,
    /// `*idn?`.
    Identify,
}

/// Longest encoded command.
pub const MAX_COMMAND: usize = 10;

impl Command {
    /// The command bytes, CR included; returns the length.
    pub fn encode(&self, out: &mut [u8; MAX_COMMAND]) -> usize {
        let text: &[u8] = match self {
            Command::SetPosition(_) => b"pos=",
            Command::GetPosition => b"pos?",
            Command::GetCount => b"pcount?",
            Command::Identify => b"*idn?",
        };
        let mut n = text.len();
        out[..n].copy_from_slice(text);
        if let Command::SetPosition(p) = self {
            if *p >= 100 {
                out[n] = b'0' + p / 100;
                n += 1;
            }
            if *p >= 10 {
                out[n] = b'0' + p / 10 % 10;
                n += 1;
            }
            out[n] = b'0' + p % 10;
            n += 1;
        }
        out[n] = b'\r';
        n + 1
    }
}

/// One answer (the bytes up to, not including, the `>` prompt), parsed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Response<'a> {
    /// The echoed command.
    pub echo: &'a [u8],
    /// The result line of a query, if any.
    pub value: Option<&'a [u8]>,
    /// The error text, if the wheel refused the command.
    pub error: Option<&'a [u8]>,
}

impl<'a> Response<'a> {
    /// Parse an answer. Never panics.
    pub fn parse(bytes: &'a [u8]) -> Self {
        let mut lines = bytes.split(|&b| b == b'\r' || b == b'\n').filter(|l| !l.is_empty());
        let echo = lines.next().unwrap_or(b"");
        let mut value = None;
        let mut error = None;
        for l in lines {
            if l.starts_with(b"Command error") {
                error = Some(l);
            } else if value.is_none() {
                value = Some(l);
            }
        }
        // An error may also be the only line (no echo).
        if echo.starts_with(b"Command error") {
            error = Some(echo);
        }
        Self { echo, value, error }
    }

    /// The query result as an integer.
    pub fn integer(&self) -> Option<i64> {
        parse_i64(self.value?)
    }
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

    #[test]
    fn manual_commands() {
        assert_eq!(enc(Command::SetPosition(3)), b"pos=3\r");
        assert_eq!(enc(Command::SetPosition(12)), b"pos=12\r");
        assert_eq!(enc(Command::GetPosition), b"pos?\r");
        assert_eq!(enc(Command::GetCount), b"pcount?\r");
        assert_eq!(enc(Command::Identify), b"*idn?\r");
    }

    #[test]
    fn parses_answers() {
        let r = Response::parse(b"pos?\r4\r");
        assert_eq!((r.echo, r.integer(), r.error), (&b"pos?"[..], Some(4), None));
        let r = Response::parse(b"pos=9\rCommand error CMD_ARG_INVALID\r");
        assert_eq!(r.error, Some(&b"Command error CMD_ARG_INVALID"[..]));
        let r = Response::parse(b"pos=2\r");
        assert_eq!((r.value, r.error), (None, None));
    }

    proptest! {
        #[test]
        fn parse_never_panics(bytes in proptest::collection::vec(any::<u8>(), 0..100)) {
            let r = Response::parse(&bytes);
            let _ = r.integer();
        }
    }
}
