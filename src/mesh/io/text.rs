//! Allocation-free helpers for the text formats: a line reader that reuses one buffer, a
//! whitespace tokenizer over bytes, a token stream across lines, and number parsing.

use std::io::BufRead;

/// Reads lines into one reused buffer, without their `\n` / `\r\n` terminator, counting lines
/// (1-based) and bytes consumed.
pub(crate) struct LineReader<R> {
    reader: R,
    buf: Vec<u8>,
    line_no: usize,
    bytes_read: u64,
}

impl<R: BufRead> LineReader<R> {
    pub(crate) fn new(reader: R) -> Self {
        LineReader {
            reader,
            buf: Vec::with_capacity(256),
            line_no: 0,
            bytes_read: 0,
        }
    }

    /// Reads the next line; `Ok(false)` at the end of the input.
    pub(crate) fn next_line(&mut self) -> std::io::Result<bool> {
        self.buf.clear();
        let n = self.reader.read_until(b'\n', &mut self.buf)?;
        if n == 0 {
            return Ok(false);
        }
        self.bytes_read += n as u64;
        self.line_no += 1;
        if self.buf.last() == Some(&b'\n') {
            self.buf.pop();
        }
        if self.buf.last() == Some(&b'\r') {
            self.buf.pop();
        }
        Ok(true)
    }

    /// The current line (without terminator).
    pub(crate) fn line(&self) -> &[u8] {
        &self.buf
    }

    /// The 1-based number of the current line (0 before the first).
    pub(crate) fn line_no(&self) -> usize {
        self.line_no
    }

    /// Bytes consumed so far, terminators included.
    pub(crate) fn bytes_read(&self) -> u64 {
        self.bytes_read
    }

    /// The underlying reader, positioned just after the last line read.
    pub(crate) fn into_inner(self) -> R {
        self.reader
    }
}

/// ASCII whitespace as the C locale's `isspace` sees it.
#[inline]
pub(crate) fn is_space(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\r' | b'\n' | 0x0b | 0x0c)
}

/// The whitespace-separated tokens of `line`.
#[inline]
pub(crate) fn tokens(line: &[u8]) -> impl Iterator<Item = &[u8]> {
    line.split(|&b| is_space(b)).filter(|t| !t.is_empty())
}

/// `line` without anything from the first `#` on.
pub(crate) fn strip_comment(line: &[u8]) -> &[u8] {
    match line.iter().position(|&b| b == b'#') {
        Some(i) => &line[..i],
        None => line,
    }
}

/// Parses a decimal floating-point token (`inf`/`nan` are accepted here and rejected later as
/// non-finite).
#[inline]
pub(crate) fn parse_f64(tok: &[u8]) -> Option<f64> {
    std::str::from_utf8(tok).ok()?.parse().ok()
}

/// Parses a signed decimal integer token.
#[inline]
pub(crate) fn parse_i64(tok: &[u8]) -> Option<i64> {
    std::str::from_utf8(tok).ok()?.parse().ok()
}

/// Parses an unsigned decimal integer token.
#[inline]
pub(crate) fn parse_u64(tok: &[u8]) -> Option<u64> {
    std::str::from_utf8(tok).ok()?.parse().ok()
}

/// A token for error messages: at most 40 bytes, lossily decoded.
pub(crate) fn show(tok: &[u8]) -> String {
    let cut = &tok[..tok.len().min(40)];
    let mut s = String::from_utf8_lossy(cut).into_owned();
    if tok.len() > cut.len() {
        s.push('…');
    }
    s
}

/// Whitespace-separated tokens across lines, tracking the line number of the last token.
pub(crate) struct TokenStream<R> {
    lines: LineReader<R>,
    pos: usize,
}

impl<R: BufRead> TokenStream<R> {
    /// Starts after the current line of `lines` (which is not tokenized).
    pub(crate) fn new(lines: LineReader<R>) -> Self {
        let pos = lines.line().len();
        TokenStream { lines, pos }
    }

    /// The next token, or `None` at the end of the input.
    pub(crate) fn next_token(&mut self) -> std::io::Result<Option<&[u8]>> {
        loop {
            let line = self.lines.line();
            let start = self.pos
                + line[self.pos..]
                    .iter()
                    .take_while(|&&b| is_space(b))
                    .count();
            if start < line.len() {
                let len = line[start..].iter().take_while(|&&b| !is_space(b)).count();
                self.pos = start + len;
                return Ok(Some(&self.lines.line()[start..start + len]));
            }
            self.pos = 0;
            if !self.lines.next_line()? {
                return Ok(None);
            }
        }
    }

    /// The 1-based line number of the last token returned.
    pub(crate) fn line_no(&self) -> usize {
        self.lines.line_no()
    }
}
