//! What the three language readers share: the code of a text with its comments blanked
//! (byte offsets kept, so every span found in the code is a span of the file), line numbers
//! of byte offsets, numbers with their spans, bracket matching and the error that names
//! file, line and field.

use crate::Error;
use std::ops::Range;

/// A program's text with its comments replaced by spaces (same length, same offsets).
pub(crate) struct Code<'a> {
    /// The file's name, for messages.
    pub file: &'a str,
    /// The original text.
    pub text: &'a str,
    /// The text with comments (and string contents) blanked, as bytes.
    pub code: Vec<u8>,
}

impl<'a> Code<'a> {
    /// Blanks every comment from `comment` to the end of its line, and the contents of
    /// every `"…"` string (so a `;` or `[` inside a string is not code).
    pub fn new(text: &'a str, file: &'a str, comment: u8) -> Code<'a> {
        let mut code = text.as_bytes().to_vec();
        let (mut in_string, mut in_comment) = (false, false);
        for b in code.iter_mut() {
            match *b {
                b'\n' => {
                    in_string = false;
                    in_comment = false;
                }
                b'"' if !in_comment => in_string = !in_string,
                c if c == comment && !in_string => {
                    in_comment = true;
                    *b = b' ';
                }
                _ if in_comment || in_string => *b = b' ',
                _ => {}
            }
        }
        Code { file, text, code }
    }

    /// The 1-based line of byte offset `at`.
    pub fn line(&self, at: usize) -> usize {
        self.text.as_bytes()[..at.min(self.text.len())]
            .iter()
            .filter(|&&b| b == b'\n')
            .count()
            + 1
    }

    /// The error for byte offset `at`, naming the file, the line and `field`.
    pub fn err(&self, at: usize, field: &str, msg: impl std::fmt::Display) -> Error {
        Error::File {
            file: self.file.to_string(),
            message: format!("line {}: `{field}`: {msg}", self.line(at)),
        }
    }

    /// The code between `range` as text (comments blanked).
    pub fn slice(&self, range: Range<usize>) -> &str {
        // Blanking replaced whole bytes of comments and strings by ASCII spaces; a multi-byte
        // character outside them is intact, and `range` ends are ASCII positions.
        std::str::from_utf8(&self.code[range]).unwrap_or("")
    }

    /// The offset after the bracket that closes the one at `open` (`{`/`}` or `[`/`]`,
    /// nested), or an error naming `field`.
    pub fn closing(&self, open: usize, field: &str) -> Result<usize, Error> {
        let (o, c) = match self.code[open] {
            b'{' => (b'{', b'}'),
            _ => (b'[', b']'),
        };
        let mut depth = 0usize;
        for (i, &b) in self.code.iter().enumerate().skip(open) {
            if b == o {
                depth += 1;
            } else if b == c {
                depth -= 1;
                if depth == 0 {
                    return Ok(i + 1);
                }
            }
        }
        Err(self.err(open, field, format!("`{}` is never closed", char::from(o))))
    }

    /// The offset of the first byte at or after `at` that is not white space.
    pub fn skip_space(&self, mut at: usize) -> usize {
        while at < self.code.len() && self.code[at].is_ascii_whitespace() {
            at += 1;
        }
        at
    }
}

/// A number with its span in the file.
#[derive(Clone, Debug)]
pub(crate) struct Number {
    /// The value as written.
    pub value: f64,
    /// Its bytes in the file.
    pub span: Range<usize>,
}

/// Whether `b` may continue an identifier.
pub(crate) fn ident_byte(b: u8) -> bool {
    b.is_ascii_alphanumeric() || b == b'_' || b == b'$'
}

/// The number written in `code` over `span` (trimmed of white space), or an error naming
/// `field`.
pub(crate) fn number(code: &Code, span: Range<usize>, field: &str) -> Result<Number, Error> {
    let raw = code.slice(span.clone());
    let lead = raw.len() - raw.trim_start().len();
    let t = raw.trim();
    let start = span.start + lead;
    match t.parse::<f64>() {
        Ok(v) if v.is_finite() && !t.is_empty() => Ok(Number {
            value: v,
            span: start..start + t.len(),
        }),
        _ => Err(code.err(start, field, format!("`{t}` is not a number"))),
    }
}

/// The comma-separated items of the bracket expression `open..close` (the brackets
/// excluded), split at depth 0, as spans.
pub(crate) fn items(code: &Code, open: usize, close: usize) -> Vec<Range<usize>> {
    let mut out = Vec::new();
    let (mut depth, mut start) = (0i32, open + 1);
    for i in open + 1..close - 1 {
        match code.code[i] {
            b'[' | b'{' | b'(' => depth += 1,
            b']' | b'}' | b')' => depth -= 1,
            b',' if depth == 0 => {
                out.push(start..i);
                start = i + 1;
            }
            _ => {}
        }
    }
    out.push(start..close - 1);
    out
}

/// Formats `x` with `decimals` decimals, without a negative zero.
pub(crate) fn fixed(x: f64, decimals: usize) -> String {
    let s = format!("{x:.decimals$}");
    if s.trim_start_matches('-')
        .chars()
        .all(|c| c == '0' || c == '.')
    {
        s.trim_start_matches('-').to_string()
    } else {
        s
    }
}
