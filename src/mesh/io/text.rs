//! Line and token scanning shared by the text parsers (OFF, OBJ).

use super::parse_error;
use crate::mesh::MeshError;

/// Non-blank lines of a text file with `#` comments removed, split into whitespace-separated
/// tokens, each with its 1-based line number.
pub(crate) struct TokenLines<'a> {
    rest: &'a [u8],
    line: usize,
}

impl<'a> TokenLines<'a> {
    pub(crate) fn new(bytes: &'a [u8]) -> Self {
        TokenLines {
            rest: bytes,
            line: 0,
        }
    }

    /// Number of the last line read (0 before any).
    pub(crate) fn line(&self) -> usize {
        self.line
    }

    /// The next raw line (without its end of line), or `None` at the end of the file.
    pub(crate) fn next_raw(&mut self) -> Result<Option<&'a str>, MeshError> {
        if self.rest.is_empty() {
            return Ok(None);
        }
        let end = self
            .rest
            .iter()
            .position(|&b| b == b'\n')
            .unwrap_or(self.rest.len());
        let mut raw = &self.rest[..end];
        self.rest = self.rest.get(end + 1..).unwrap_or(&[]);
        self.line += 1;
        if let Some(stripped) = raw.strip_suffix(b"\r") {
            raw = stripped;
        }
        std::str::from_utf8(raw)
            .map(Some)
            .map_err(|_| parse_error(Some(self.line), "not valid UTF-8 text"))
    }

    /// The tokens of the next line that has any (after removing its `#` comment).
    pub(crate) fn next_tokens(&mut self) -> Result<Option<(usize, Vec<&'a str>)>, MeshError> {
        while let Some(raw) = self.next_raw()? {
            let text = raw.split('#').next().unwrap_or("");
            let tokens: Vec<&str> = text.split_ascii_whitespace().collect();
            if !tokens.is_empty() {
                return Ok(Some((self.line, tokens)));
            }
        }
        Ok(None)
    }
}

/// Parses a coordinate. Accepts what Rust's `f64` parser accepts (including `nan`/`inf`, which
/// validation later rejects with a [`MeshError::NonFinite`] naming the vertex).
fn coordinate(token: &str, line: usize) -> Result<f64, MeshError> {
    token
        .parse::<f64>()
        .map_err(|_| parse_error(Some(line), format!("invalid coordinate `{}`", short(token))))
}

/// The position of a vertex line's first three tokens `t` (line `line`); `index`, the vertex's
/// number where the format counts vertices, names it in the error of a short line.
pub(crate) fn position(
    t: &[&str],
    line: usize,
    index: Option<usize>,
) -> Result<[f64; 3], MeshError> {
    if t.len() < 3 {
        let vertex = index.map_or("vertex".to_string(), |i| format!("vertex {i}"));
        return Err(parse_error(
            Some(line),
            format!("{vertex} has {} coordinates, expected 3", t.len()),
        ));
    }
    Ok([
        coordinate(t[0], line)?,
        coordinate(t[1], line)?,
        coordinate(t[2], line)?,
    ])
}

/// At most 40 characters of `token`, for error messages.
pub(crate) fn short(token: &str) -> String {
    let mut s: String = token.chars().take(40).collect();
    if s.len() < token.len() {
        s.push('…');
    }
    s
}
