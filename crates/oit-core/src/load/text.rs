//! The one tokenizer of the text formats (ASCII STL, OBJ with its MTL, ASCII PLY): a file read
//! in large blocks and handed out as words or lines, each a slice of the block, with the line
//! the reader is on and the bytes it has consumed (PLY's binary data is read from the same
//! blocks); OBJ's lines joined at a trailing backslash; the words of a line; and the numbers
//! those formats write.

use std::io::Read;

/// The block a reader starts with; it grows where one word or line fills it.
const BLOCK: usize = 1 << 16;

/// Whether `b` parts words in OBJ, MTL and PLY: space, tab, LF, form feed, CR.
pub fn whitespace(b: u8) -> bool {
    b.is_ascii_whitespace()
}

/// Whether `b` parts words in ASCII STL: every control byte does, as space, tab, CR and LF do.
pub fn control(b: u8) -> bool {
    b <= b' '
}

/// A text read in blocks: words, lines and raw bytes, each a slice of the block that stays
/// valid until the next read.
pub struct Text<R> {
    r: R,
    buf: Vec<u8>,
    pos: usize,
    end: usize,
    eof: bool,
    /// Bytes read before `buf[0]`.
    before: u64,
    /// The line `pos` is on, from 1.
    pub line_number: usize,
    /// Where in the block the last line `line` gave lies.
    last: std::ops::Range<usize>,
}

impl<R: Read> Text<R> {
    pub fn new(r: R) -> Self {
        Self { r, buf: vec![0; BLOCK], pos: 0, end: 0, eof: false, before: 0, line_number: 1, last: 0..0 }
    }

    /// Bytes consumed from the start of the text.
    pub fn offset(&self) -> u64 {
        self.before + self.pos as u64
    }

    /// Moves what is left to the front and reads more (growing the block when it is full).
    fn refill(&mut self) -> std::io::Result<()> {
        self.buf.copy_within(self.pos..self.end, 0);
        self.before += self.pos as u64;
        self.end -= self.pos;
        self.pos = 0;
        if self.end == self.buf.len() {
            self.buf.resize(self.buf.len() * 2, 0);
        }
        let n = self.r.read(&mut self.buf[self.end..])?;
        self.end += n;
        self.eof = n == 0;
        Ok(())
    }

    /// The next word, blanks (as `blank` says) before it skipped; None at the end of the text.
    #[inline]
    pub fn word(&mut self, blank: impl Fn(u8) -> bool) -> std::io::Result<Option<&[u8]>> {
        loop {
            while self.pos < self.end && blank(self.buf[self.pos]) {
                self.line_number += (self.buf[self.pos] == b'\n') as usize;
                self.pos += 1;
            }
            if self.pos == self.end {
                if self.eof {
                    return Ok(None);
                }
                self.refill()?;
                continue;
            }
            let mut i = self.pos;
            while i < self.end && !blank(self.buf[i]) {
                i += 1;
            }
            if i == self.end && !self.eof {
                self.refill()?;
                continue;
            }
            let start = self.pos;
            self.pos = i;
            return Ok(Some(&self.buf[start..i]));
        }
    }

    /// The rest of the current line with its LF (a last line may have none); None at the end
    /// of the text.
    pub fn line(&mut self) -> std::io::Result<Option<&[u8]>> {
        loop {
            let found = find_lf(&self.buf[self.pos..self.end]);
            if found.is_none() && !self.eof {
                self.refill()?;
                continue;
            }
            if found.is_none() && self.pos == self.end {
                return Ok(None);
            }
            let start = self.pos;
            let stop = found.map_or(self.end, |k| start + k + 1);
            self.pos = stop;
            self.line_number += found.is_some() as usize;
            self.last = start..stop;
            return Ok(Some(&self.buf[start..stop]));
        }
    }

    /// The line `line` gave last, again (until the next read).
    pub fn last_line(&self) -> &[u8] {
        &self.buf[self.last.clone()]
    }

    /// At least `n` bytes from the current one, or all that is left where the text ends first;
    /// `consume` moves past them.
    pub fn peek(&mut self, n: usize) -> std::io::Result<&[u8]> {
        while self.end - self.pos < n && !self.eof {
            self.refill()?;
        }
        Ok(&self.buf[self.pos..self.end])
    }

    /// Moves past `n` bytes that `peek` gave.
    pub fn consume(&mut self, n: usize) {
        debug_assert!(n <= self.end - self.pos);
        self.pos += n;
    }
}

/// Physical lines joined where one ends in a backslash, each with its first line's number.
pub struct Lines<R> {
    text: Text<R>,
    /// A line joined from several, where it is one.
    joined: Vec<u8>,
}

impl<R: Read> Lines<R> {
    pub fn new(reader: R) -> Self {
        Self { text: Text::new(reader), joined: Vec::new() }
    }

    pub fn next(&mut self) -> std::io::Result<Option<(usize, &[u8])>> {
        let number = self.text.line_number;
        let Some(first) = self.text.line()? else { return Ok(None) };
        let Some(head) = trim_end(first).strip_suffix(b"\\") else {
            // The common case, a line of its own: the block's bytes as they are.
            let line = self.text.last_line();
            return Ok(Some((number, trim_end(line))));
        };
        self.joined.clear();
        self.joined.extend_from_slice(head);
        self.joined.push(b' ');
        while let Some(line) = self.text.line()? {
            match trim_end(line).strip_suffix(b"\\") {
                Some(head) => {
                    self.joined.extend_from_slice(head);
                    self.joined.push(b' ');
                }
                None => {
                    self.joined.extend_from_slice(trim_end(line));
                    break;
                }
            }
        }
        Ok(Some((number, &self.joined)))
    }
}

/// A line without the LF and CRs that end it.
fn trim_end(mut line: &[u8]) -> &[u8] {
    while let [head @ .., b'\n' | b'\r'] = line {
        line = head;
    }
    line
}

/// Where the first LF of `s` is: eight bytes a step (a word with no zero byte after the XOR has
/// no LF), then byte by byte.
fn find_lf(s: &[u8]) -> Option<usize> {
    const ONES: u64 = 0x0101_0101_0101_0101;
    const HIGH: u64 = 0x8080_8080_8080_8080;
    let mut i = 0;
    while let Some(chunk) = s.get(i..i + 8) {
        let w = u64::from_le_bytes(chunk.try_into().expect("eight bytes")) ^ (ONES * b'\n' as u64);
        if w.wrapping_sub(ONES) & !w & HIGH != 0 {
            break;
        }
        i += 8;
    }
    s[i..].iter().position(|&b| b == b'\n').map(|k| i + k)
}

/// The whitespace-separated words of a line.
pub fn words(line: &[u8]) -> Words<'_> {
    Words(line)
}

/// The words of a line, in order (`words`).
pub struct Words<'a>(&'a [u8]);

impl<'a> Iterator for Words<'a> {
    type Item = &'a [u8];

    fn next(&mut self) -> Option<&'a [u8]> {
        let s = self.0;
        let mut i = 0;
        while i < s.len() && s[i].is_ascii_whitespace() {
            i += 1;
        }
        let start = i;
        while i < s.len() && !s[i].is_ascii_whitespace() {
            i += 1;
        }
        self.0 = &s[i..];
        (i > start).then(|| &s[start..i])
    }
}

/// The text after a line's first word, trimmed (names and file names may hold spaces).
pub fn rest(line: &[u8]) -> String {
    let line = line.trim_ascii();
    let start = line.iter().position(|b| b.is_ascii_whitespace()).unwrap_or(line.len());
    String::from_utf8_lossy(line[start..].trim_ascii()).into_owned()
}

/// A number of a text format, finite.
pub fn number(token: Option<&[u8]>, what: &str) -> Result<f32, String> {
    let t = token.ok_or_else(|| format!("{what} is missing"))?;
    match decimal(t).or_else(|| std::str::from_utf8(t).ok()?.parse::<f64>().ok()).map(|x| x as f32) {
        Some(x) if x.is_finite() => Ok(x),
        _ => Err(format!("{what} '{}' is not a finite number", short(&String::from_utf8_lossy(t)))),
    }
}

/// The common case of a decimal (`-12.5`, `3e-4`, at most 19 digits) exactly, as the
/// standard parser would give it; None for anything else (the caller falls back to it).
pub fn decimal(t: &[u8]) -> Option<f64> {
    const POW10: [f64; 23] =
        [1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22];
    let (negative, mut t) = match t.first()? {
        b'-' => (true, &t[1..]),
        b'+' => (false, &t[1..]),
        _ => (false, t),
    };
    let (mut mantissa, mut scale) = (0u64, 0i32);
    let mut any = false;
    while let [d @ b'0'..=b'9', tail @ ..] = t {
        mantissa = mantissa.checked_mul(10)?.checked_add((d - b'0') as u64)?;
        any = true;
        t = tail;
    }
    if let [b'.', tail @ ..] = t {
        t = tail;
        while let [d @ b'0'..=b'9', tail @ ..] = t {
            mantissa = mantissa.checked_mul(10)?.checked_add((d - b'0') as u64)?;
            scale -= 1;
            any = true;
            t = tail;
        }
    }
    if !any {
        return None;
    }
    if let [b'e' | b'E', tail @ ..] = t {
        let (negative, mut e) = match tail.first()? {
            b'-' => (true, &tail[1..]),
            b'+' => (false, &tail[1..]),
            _ => (false, tail),
        };
        let mut exponent = 0i32;
        let mut any = false;
        while let [d @ b'0'..=b'9', tail @ ..] = e {
            exponent = (exponent * 10 + (d - b'0') as i32).min(10_000);
            any = true;
            e = tail;
        }
        if !any {
            return None;
        }
        scale += if negative { -exponent } else { exponent };
        t = e;
    }
    // Exact: the mantissa and the power of ten are both representable, one rounding.
    if !t.is_empty() || mantissa > 1 << 53 || scale.unsigned_abs() > 22 {
        return None;
    }
    let x = mantissa as f64;
    let x = if scale < 0 { x / POW10[(-scale) as usize] } else { x * POW10[scale as usize] };
    Some(if negative { -x } else { x })
}

/// At most the first 40 characters of `s`, for messages.
pub fn short(s: &str) -> String {
    s.chars().take(40).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A reader that gives one byte a read: every word and line crosses a block's end.
    struct ByteByByte<'a>(&'a [u8]);

    impl Read for ByteByByte<'_> {
        fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
            let Some((&b, rest)) = self.0.split_first().filter(|_| !buf.is_empty()) else { return Ok(0) };
            buf[0] = b;
            self.0 = rest;
            Ok(1)
        }
    }

    fn all_lines(r: impl Read) -> Vec<(usize, String)> {
        let mut lines = Lines::new(r);
        let mut out = Vec::new();
        while let Some((n, l)) = lines.next().unwrap() {
            out.push((n, String::from_utf8_lossy(l).into_owned()));
        }
        out
    }

    #[test]
    fn lines_join_at_a_backslash_under_their_first_number() {
        let text = b"v 1 \\\r\n2 3\r\n\nf 1\\\n\\\n 2 3\nl \\";
        let want = [(1, "v 1  2 3"), (3, ""), (4, "f 1   2 3"), (7, "l  ")].map(|(n, l)| (n, l.to_string()));
        assert_eq!(all_lines(&text[..]), want);
        assert_eq!(all_lines(ByteByByte(text)), want);
    }

    #[test]
    fn words_lines_and_bytes_read_alike_whatever_the_blocks() {
        let text = b"solid  a b\r\n\x0bfacet\x00normal 1e-3\n\nend";
        let read = |t: &mut Text<&mut dyn Read>| {
            let show = |b: Option<&[u8]>| b.map_or("none".to_string(), |b| String::from_utf8_lossy(b).into_owned());
            let mut out = vec![show(t.word(control).unwrap()), show(t.line().unwrap())];
            // Control bytes other than whitespace part STL's words, not PLY's.
            out.push(show(t.word(whitespace).unwrap()));
            out.extend([show(t.word(control).unwrap()), show(t.line().unwrap()), show(t.line().unwrap())]);
            out.push(format!("line {} at {}", t.line_number, t.offset()));
            let end = t.peek(8).unwrap().to_vec();
            t.consume(end.len());
            out.extend([show(Some(&end)), format!("at {}", t.offset()), show(t.line().unwrap()), show(t.word(control).unwrap())]);
            out
        };
        let whole = read(&mut Text::new(&mut &text[..]));
        let want = ["solid", "  a b\r\n", "\x0bfacet\x00normal", "1e-3", "\n", "\n", "line 4 at 32", "end", "at 35", "none", "none"];
        assert_eq!(whole, want);
        assert_eq!(read(&mut Text::new(&mut ByteByByte(text))), want);
    }
}
