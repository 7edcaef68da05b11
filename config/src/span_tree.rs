//! A tolerant reader of RON text that records where every value sits, so
//! that an error found on a deserialized value (a field path) can be shown
//! at its file line and column, and a parser error position can be named by
//! the field it falls in. `ron` itself keeps no spans on values.
//!
//! The reader only needs the shape of the text: structs, tuples, lists,
//! maps, and scalars it skips over. On text it cannot read it returns
//! `None`, and callers fall back to the parser's own position.

use crate::validate::{FieldPath, Segment};

/// A value and the byte range `[start, end)` it spans.
#[derive(Debug, Clone)]
pub struct Node {
    /// First byte of the value.
    pub start: usize,
    /// One past its last byte.
    pub end: usize,
    /// What kind of value.
    pub kind: Kind,
}

/// The shape of a value.
#[derive(Debug, Clone)]
pub enum Kind {
    /// A number, string, char or other atom.
    Scalar,
    /// `Name` or `Name(...)`: a named struct, enum variant, `Some(x)`, `true`…
    Named { name: String, body: Option<Body> },
    /// `(...)`: an unnamed struct or tuple.
    Paren(Body),
    /// `[...]`.
    List(Vec<Node>),
    /// `{...}`.
    Map(Vec<(Node, Node)>),
}

/// The inside of parentheses.
#[derive(Debug, Clone)]
pub enum Body {
    /// `field: value, ...`
    Fields(Vec<Field>),
    /// `value, ...`
    Elems(Vec<Node>),
}

/// A `name: value` pair.
#[derive(Debug, Clone)]
pub struct Field {
    /// The field name.
    pub name: String,
    /// First byte of the name.
    pub key_start: usize,
    /// The value.
    pub value: Node,
}

#[derive(Debug, Clone, PartialEq)]
enum Tok {
    Open(u8),
    Close(u8),
    Comma,
    Colon,
    Ident(String),
    Scalar,
}

/// Reads `text` into a tree, or `None` if it is not well-formed RON.
pub fn parse(text: &str) -> Option<Node> {
    let (toks, complete) = lex(text);
    if !complete {
        return None;
    }
    let mut p = Parser { toks: &toks, i: 0 };
    let node = p.value()?;
    (p.i == toks.len()).then_some(node)
}

/// The first identifier of the text, e.g. `Station`, even if the rest of the
/// text is malformed.
pub fn first_name(text: &str) -> Option<(String, usize)> {
    match lex(text).0.into_iter().next() {
        Some((Tok::Ident(name), start, _)) => Some((name, start)),
        _ => None,
    }
}

/// Splits the text into tokens; the flag says whether all of it could be.
fn lex(text: &str) -> (Vec<(Tok, usize, usize)>, bool) {
    let mut out = Vec::new();
    let complete = lex_into(text, &mut out).is_some();
    (out, complete)
}

fn lex_into(text: &str, out: &mut Vec<(Tok, usize, usize)>) -> Option<()> {
    let b = text.as_bytes();
    let mut i = 0;
    let ident_start = |c: u8| c.is_ascii_alphabetic() || c == b'_' || c >= 0x80;
    let ident_char = |c: u8| c.is_ascii_alphanumeric() || c == b'_' || c >= 0x80;
    while i < b.len() {
        let c = b[i];
        let start = i;
        match c {
            b' ' | b'\t' | b'\n' | b'\r' => i += 1,
            b'/' if b.get(i + 1) == Some(&b'/') => {
                while i < b.len() && b[i] != b'\n' {
                    i += 1;
                }
            }
            b'/' if b.get(i + 1) == Some(&b'*') => {
                let mut depth = 0usize;
                loop {
                    if i + 1 >= b.len() {
                        return None;
                    }
                    if b[i] == b'/' && b[i + 1] == b'*' {
                        depth += 1;
                        i += 2;
                    } else if b[i] == b'*' && b[i + 1] == b'/' {
                        depth -= 1;
                        i += 2;
                        if depth == 0 {
                            break;
                        }
                    } else {
                        i += 1;
                    }
                }
            }
            b'#' => {
                // `#![enable(...)]` attribute: skip to the matching `]`.
                let mut depth = 0usize;
                loop {
                    match b.get(i)? {
                        b'[' => depth += 1,
                        b']' => {
                            // A `]` before any `[` is not an attribute: no tree.
                            depth = depth.checked_sub(1)?;
                            if depth == 0 {
                                i += 1;
                                break;
                            }
                        }
                        _ => {}
                    }
                    i += 1;
                }
            }
            b'(' | b'[' | b'{' => {
                out.push((Tok::Open(c), start, start + 1));
                i += 1;
            }
            b')' | b']' | b'}' => {
                out.push((Tok::Close(c), start, start + 1));
                i += 1;
            }
            b',' => {
                out.push((Tok::Comma, start, start + 1));
                i += 1;
            }
            b':' => {
                out.push((Tok::Colon, start, start + 1));
                i += 1;
            }
            b'"' => {
                i = skip_quoted(b, i, b'"')?;
                out.push((Tok::Scalar, start, i));
            }
            b'\'' => {
                i = skip_quoted(b, i, b'\'')?;
                out.push((Tok::Scalar, start, i));
            }
            b'b' if matches!(b.get(i + 1), Some(b'"') | Some(b'\'')) => {
                i = skip_quoted(b, i + 1, b[i + 1])?;
                out.push((Tok::Scalar, start, i));
            }
            b'r' if matches!(b.get(i + 1), Some(b'"') | Some(b'#')) => {
                let mut j = i + 1;
                let mut hashes = 0;
                while b.get(j) == Some(&b'#') {
                    hashes += 1;
                    j += 1;
                }
                if b.get(j) == Some(&b'"') {
                    // Raw string: ends at `"` followed by the same number of `#`.
                    j += 1;
                    loop {
                        if j >= b.len() {
                            return None;
                        }
                        if b[j] == b'"' && b[j + 1..].iter().take(hashes).filter(|&&h| h == b'#').count() == hashes {
                            j += 1 + hashes;
                            break;
                        }
                        j += 1;
                    }
                    out.push((Tok::Scalar, start, j));
                    i = j;
                } else if hashes == 1
                    && b.get(j)
                        .is_some_and(|&c| ident_char(c) || c == b'-' || c == b'.' || c == b'+')
                {
                    // Raw identifier `r#name`.
                    let name_start = j;
                    while b
                        .get(j)
                        .is_some_and(|&c| ident_char(c) || c == b'-' || c == b'.' || c == b'+')
                    {
                        j += 1;
                    }
                    out.push((Tok::Ident(text[name_start..j].to_owned()), start, j));
                    i = j;
                } else {
                    return None;
                }
            }
            c if ident_start(c) => {
                while i < b.len() && ident_char(b[i]) {
                    i += 1;
                }
                out.push((Tok::Ident(text.get(start..i)?.to_owned()), start, i));
            }
            c if c.is_ascii_digit() || c == b'-' || c == b'+' || c == b'.' => {
                i += 1;
                while i < b.len() {
                    let d = b[i];
                    let exp_sign =
                        (d == b'+' || d == b'-') && matches!(b[i - 1], b'e' | b'E') && !text[start..i].contains("0x");
                    if d.is_ascii_alphanumeric() || d == b'_' || d == b'.' || exp_sign {
                        i += 1;
                    } else {
                        break;
                    }
                }
                out.push((Tok::Scalar, start, i));
            }
            _ => return None,
        }
    }
    Some(())
}

/// Skips a quoted literal starting at `b[i] == quote`; returns the index past
/// its closing quote.
fn skip_quoted(b: &[u8], mut i: usize, quote: u8) -> Option<usize> {
    i += 1;
    while i < b.len() {
        match b[i] {
            b'\\' => i += 2,
            c if c == quote => return Some(i + 1),
            _ => i += 1,
        }
    }
    None
}

struct Parser<'a> {
    toks: &'a [(Tok, usize, usize)],
    i: usize,
}

impl Parser<'_> {
    fn peek(&self, k: usize) -> Option<&Tok> {
        self.toks.get(self.i + k).map(|t| &t.0)
    }

    fn value(&mut self) -> Option<Node> {
        let (tok, start, end) = self.toks.get(self.i)?.clone();
        self.i += 1;
        match tok {
            Tok::Scalar => Some(Node {
                start,
                end,
                kind: Kind::Scalar,
            }),
            Tok::Ident(name) => {
                if self.peek(0) == Some(&Tok::Open(b'(')) {
                    self.i += 1;
                    let (body, end) = self.body()?;
                    Some(Node {
                        start,
                        end,
                        kind: Kind::Named { name, body: Some(body) },
                    })
                } else {
                    Some(Node {
                        start,
                        end,
                        kind: Kind::Named { name, body: None },
                    })
                }
            }
            Tok::Open(b'(') => {
                let (body, end) = self.body()?;
                Some(Node {
                    start,
                    end,
                    kind: Kind::Paren(body),
                })
            }
            Tok::Open(b'[') => {
                let (elems, end) = self.elems(b']')?;
                Some(Node {
                    start,
                    end,
                    kind: Kind::List(elems),
                })
            }
            Tok::Open(b'{') => {
                let mut entries = Vec::new();
                loop {
                    if let Some(&(Tok::Close(b'}'), _, end)) = self.toks.get(self.i) {
                        self.i += 1;
                        return Some(Node {
                            start,
                            end,
                            kind: Kind::Map(entries),
                        });
                    }
                    let k = self.value()?;
                    self.expect(&Tok::Colon)?;
                    let v = self.value()?;
                    entries.push((k, v));
                    self.separator(b'}')?;
                }
            }
            _ => None,
        }
    }

    fn expect(&mut self, t: &Tok) -> Option<()> {
        (self.peek(0)? == t).then(|| self.i += 1)
    }

    /// After an element: a comma, or the closing delimiter (not consumed).
    fn separator(&mut self, close: u8) -> Option<()> {
        match self.peek(0)? {
            Tok::Comma => {
                self.i += 1;
                Some(())
            }
            Tok::Close(c) if *c == close => Some(()),
            _ => None,
        }
    }

    /// The inside of `( ... )`, after the `(`; returns the end offset.
    fn body(&mut self) -> Option<(Body, usize)> {
        let is_fields = matches!(self.peek(0), Some(Tok::Ident(_))) && self.peek(1) == Some(&Tok::Colon);
        if !is_fields {
            let (elems, end) = self.elems(b')')?;
            return Some((Body::Elems(elems), end));
        }
        let mut fields = Vec::new();
        loop {
            match self.toks.get(self.i)?.clone() {
                (Tok::Close(b')'), _, end) => {
                    self.i += 1;
                    return Some((Body::Fields(fields), end));
                }
                (Tok::Ident(name), key_start, _) => {
                    self.i += 1;
                    self.expect(&Tok::Colon)?;
                    let value = self.value()?;
                    fields.push(Field { name, key_start, value });
                    self.separator(b')')?;
                }
                _ => return None,
            }
        }
    }

    fn elems(&mut self, close: u8) -> Option<(Vec<Node>, usize)> {
        let mut elems = Vec::new();
        loop {
            if let Some(&(Tok::Close(c), _, end)) = self.toks.get(self.i) {
                if c != close {
                    return None;
                }
                self.i += 1;
                return Some((elems, end));
            }
            elems.push(self.value()?);
            self.separator(close)?;
        }
    }
}

impl Node {
    /// `Some(x)` is transparent: paths go straight through it.
    fn unwrap_some(&self) -> &Node {
        let mut n = self;
        while let Kind::Named {
            name,
            body: Some(Body::Elems(e)),
        } = &n.kind
        {
            if name == "Some" && e.len() == 1 {
                n = &e[0];
            } else {
                break;
            }
        }
        n
    }

    fn child(&self, seg: &Segment) -> Option<&Node> {
        let n = self.unwrap_some();
        match (seg, &n.kind) {
            (
                Segment::Field(f),
                Kind::Named {
                    body: Some(Body::Fields(fs)),
                    ..
                }
                | Kind::Paren(Body::Fields(fs)),
            ) => fs.iter().find(|x| &x.name == f).map(|x| &x.value),
            (Segment::Index(i), Kind::List(e))
            | (
                Segment::Index(i),
                Kind::Named {
                    body: Some(Body::Elems(e)),
                    ..
                }
                | Kind::Paren(Body::Elems(e)),
            ) => e.get(*i),
            _ => None,
        }
    }

    /// The byte offset of the value at `path`, or of the deepest part of
    /// the path that exists (a defaulted field is absent from the text).
    pub fn offset_of(&self, path: &FieldPath) -> usize {
        let mut n = self;
        for seg in &path.0 {
            match n.child(seg) {
                Some(c) => n = c,
                None => break,
            }
        }
        n.unwrap_some().start
    }

    /// The path of the innermost field or element that contains `offset`.
    pub fn path_at(&self, offset: usize) -> FieldPath {
        let mut path = Vec::new();
        let mut n = self;
        'descend: loop {
            let inner = n.unwrap_some();
            let contains = |s: usize, e: usize| s <= offset && offset < e;
            match &inner.kind {
                Kind::Named {
                    body: Some(Body::Fields(fs)),
                    ..
                }
                | Kind::Paren(Body::Fields(fs)) => {
                    for f in fs {
                        if contains(f.key_start, f.value.end) {
                            path.push(Segment::Field(f.name.clone()));
                            n = &f.value;
                            continue 'descend;
                        }
                    }
                }
                Kind::List(e)
                | Kind::Named {
                    body: Some(Body::Elems(e)),
                    ..
                }
                | Kind::Paren(Body::Elems(e)) => {
                    for (i, c) in e.iter().enumerate() {
                        if contains(c.start, c.end) {
                            path.push(Segment::Index(i));
                            n = c;
                            continue 'descend;
                        }
                    }
                }
                _ => {}
            }
            return FieldPath(path);
        }
    }

    /// The name of the top-level value, e.g. `Station` in `Station(...)`.
    pub fn name(&self) -> Option<&str> {
        match &self.kind {
            Kind::Named { name, .. } => Some(name),
            _ => None,
        }
    }
}

/// 1-based line and column (in characters) of a byte offset.
pub fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let offset = offset.min(text.len());
    let before = &text[..text.floor_char_boundary(offset)];
    let line = before.matches('\n').count() + 1;
    let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, col)
}

/// The byte offset of a 1-based line and column (in characters).
pub fn offset_of_line_col(text: &str, line: usize, col: usize) -> usize {
    let mut offset = 0;
    for (k, l) in text.split_inclusive('\n').enumerate() {
        if k + 1 == line {
            return offset + l.char_indices().nth(col.saturating_sub(1)).map_or(l.len(), |(i, _)| i);
        }
        offset += l.len();
    }
    text.len()
}

/// The path of the field being written at `offset`, read from the tokens
/// before it alone. Used when the text is malformed past that point (a
/// truncated file, an unterminated string), where no tree can be built.
pub fn path_before(text: &str, offset: usize) -> FieldPath {
    struct Frame {
        some: bool,
        list: bool,
        field: Option<String>,
        index: usize,
        entered: bool,
    }
    let (toks, _) = lex(text);
    let toks: Vec<_> = toks.into_iter().filter(|t| t.1 < offset).collect();
    let mut stack: Vec<Frame> = Vec::new();
    for (k, (tok, _, _)) in toks.iter().enumerate() {
        if let Some(top) = stack.last_mut() {
            top.entered = true;
        }
        match tok {
            Tok::Open(c) => {
                let some = *c == b'(' && k > 0 && toks[k - 1].0 == Tok::Ident("Some".into());
                stack.push(Frame {
                    some,
                    list: *c != b'(',
                    field: None,
                    index: 0,
                    entered: false,
                });
            }
            Tok::Close(_) => {
                stack.pop();
            }
            Tok::Comma => {
                if let Some(top) = stack.last_mut() {
                    top.index += 1;
                    top.field = None;
                    top.entered = false;
                }
            }
            Tok::Ident(name) if toks.get(k + 1).is_some_and(|t| t.0 == Tok::Colon) => {
                if let Some(top) = stack.last_mut()
                    && !top.list
                {
                    top.field = Some(name.clone());
                }
            }
            _ => {}
        }
    }
    let mut path = Vec::new();
    for f in &stack {
        if f.some {
            continue;
        }
        match &f.field {
            Some(name) => path.push(Segment::Field(name.clone())),
            // After a comma the next element's index is known even before it starts.
            None if f.entered || f.index > 0 => path.push(Segment::Index(f.index)),
            None => break,
        }
    }
    FieldPath(path)
}

/// The text of the token that starts at or covers `offset`, if it is a
/// scalar or an identifier (at most 60 characters).
pub fn token_text_at(text: &str, offset: usize) -> Option<String> {
    let (toks, _) = lex(text);
    let (tok, s, e) = toks.into_iter().find(|t| t.1 <= offset && offset < t.2.max(t.1 + 1))?;
    match tok {
        Tok::Scalar | Tok::Ident(_) => {
            let t = text.get(s..e)?;
            Some(if t.chars().count() > 60 {
                format!("{}…", t.chars().take(60).collect::<String>())
            } else {
                t.to_owned()
            })
        }
        _ => None,
    }
}

/// The start of the first token at or after `offset`, skipping blanks and comments.
pub fn next_token_start(text: &str, offset: usize) -> Option<usize> {
    let (toks, _) = lex(text);
    toks.into_iter().find(|t| t.2 > offset).map(|t| t.1.max(offset))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A stray `#` before a `]` (no attribute's `[`) is not a tree, and not
    /// a panic: the case proptest found in `roundtrip::mangled_files_give_errors_not_panics`.
    #[test]
    fn a_hash_before_a_closing_bracket_gives_no_tree() {
        for text in ["#]", "Station(#] name: \"x\")", "#![enable(x)]]", "# ]] ["] {
            let _ = parse(text);
            let _ = first_name(text);
            let _ = next_token_start(text, 0);
        }
        assert!(parse("#]").is_none());
        assert!(parse("#![enable(implicit_some)]\nStation(name: \"x\")").is_some());
    }
}
