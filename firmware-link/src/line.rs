//! A fixed-capacity accumulator for terminator-delimited ASCII lines, used by
//! the text protocols (FLIR PTU, FW102C) on both ends.

/// What [`LineBuffer::push`] found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LineEvent {
    /// The byte was stored; no line is complete yet.
    Pending,
    /// A terminator completed a line; read it with [`LineBuffer::line`], then
    /// call [`LineBuffer::clear`].
    Complete,
    /// A line longer than the capacity was discarded up to this terminator.
    Overflowed,
}

/// Collects bytes until one of the terminators arrives. Lines longer than
/// `N` are dropped whole (and reported), never truncated into a wrong
/// command.
#[derive(Debug, Clone)]
pub struct LineBuffer<const N: usize> {
    buf: [u8; N],
    len: usize,
    overflowed: bool,
    complete: bool,
}

impl<const N: usize> Default for LineBuffer<N> {
    fn default() -> Self {
        Self {
            buf: [0; N],
            len: 0,
            overflowed: false,
            complete: false,
        }
    }
}

impl<const N: usize> LineBuffer<N> {
    /// Push one byte. `is_terminator` says which bytes end a line.
    pub fn push(&mut self, byte: u8, is_terminator: impl Fn(u8) -> bool) -> LineEvent {
        if self.complete {
            self.clear();
        }
        if is_terminator(byte) {
            if self.overflowed {
                self.clear();
                return LineEvent::Overflowed;
            }
            self.complete = true;
            return LineEvent::Complete;
        }
        if self.len < N {
            self.buf[self.len] = byte;
            self.len += 1;
        } else {
            self.overflowed = true;
        }
        LineEvent::Pending
    }

    /// The completed line (without its terminator).
    pub fn line(&self) -> &[u8] {
        &self.buf[..self.len]
    }

    /// Forget the current line.
    pub fn clear(&mut self) {
        self.len = 0;
        self.overflowed = false;
        self.complete = false;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splits_lines_and_drops_overlong_ones() {
        let mut lb = LineBuffer::<4>::default();
        let term = |b| b == b'\r';
        let mut got = Vec::new();
        for &b in b"ab\rtoolong\rxy\r" {
            match lb.push(b, term) {
                LineEvent::Complete => got.push(String::from_utf8(lb.line().to_vec()).unwrap()),
                LineEvent::Overflowed => got.push("<overflow>".into()),
                LineEvent::Pending => {}
            }
        }
        assert_eq!(got, ["ab", "<overflow>", "xy"]);
    }
}
