//! A whitespace tokenizer over a text file that knows line numbers, shared by
//! the ASCII readers so that every parse error can name its line.

use super::IoError;
pub(crate) use crate::file::as_text;
use std::path::Path;
use std::str::FromStr;

/// Tokens of a text file, with the 1-based line of each; `#` starts a comment
/// to the end of the line when `hash_comments` is set.
pub struct Tokens<'a> {
    path: &'a Path,
    text: &'a str,
    pos: usize,
    line: usize,
    hash_comments: bool,
    last_line: usize,
}

impl<'a> Tokens<'a> {
    /// A tokenizer over `text`, read from `path` (for messages).
    pub fn new(path: &'a Path, text: &'a str, hash_comments: bool) -> Tokens<'a> {
        Tokens {
            path,
            text,
            pos: 0,
            line: 1,
            hash_comments,
            last_line: 1,
        }
    }

    /// Line of the token returned last.
    #[allow(clippy::misnamed_getters)] // `line` is where the cursor is; this is the token's
    pub fn line(&self) -> usize {
        self.last_line
    }

    /// The file these tokens come from.
    pub fn path(&self) -> &Path {
        self.path
    }

    fn skip_space(&mut self) {
        let b = self.text.as_bytes();
        while self.pos < b.len() {
            match b[self.pos] {
                b'\n' => {
                    self.line += 1;
                    self.pos += 1;
                }
                b'#' if self.hash_comments => {
                    while self.pos < b.len() && b[self.pos] != b'\n' {
                        self.pos += 1;
                    }
                }
                c if c.is_ascii_whitespace() => self.pos += 1,
                _ => break,
            }
        }
    }

    /// The next token, or `None` at the end of the file.
    #[allow(clippy::should_implement_trait)]
    pub fn next(&mut self) -> Option<&'a str> {
        self.skip_space();
        let b = self.text.as_bytes();
        if self.pos >= b.len() {
            self.last_line = self.line;
            return None;
        }
        let start = self.pos;
        while self.pos < b.len() && !b[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        self.last_line = self.line;
        Some(&self.text[start..self.pos])
    }

    /// The next token without consuming it.
    pub fn peek(&mut self) -> Option<&'a str> {
        let (pos, line, last) = (self.pos, self.line, self.last_line);
        let t = self.next();
        self.pos = pos;
        self.line = line;
        self.last_line = last;
        t
    }

    /// An error at the line of the last token.
    pub fn error(&self, message: impl Into<String>) -> IoError {
        IoError::at(self.path, self.last_line, message)
    }

    /// The next token parsed as `T`; `what` names it in the message.
    pub fn parse<T: FromStr>(&mut self, what: &str) -> Result<T, IoError> {
        match self.next() {
            None => Err(IoError::at(
                self.path,
                self.line,
                format!("file ends where {what} was expected (truncated?)"),
            )),
            Some(tok) => tok
                .parse::<T>()
                .map_err(|_| self.error(format!("expected {what}, found '{}'", shorten(tok)))),
        }
    }

    /// The next token parsed as a finite `f64`.
    pub fn coord(&mut self, what: &str) -> Result<f64, IoError> {
        let x: f64 = self.parse(what)?;
        if !x.is_finite() {
            return Err(self.error(format!("{what} is {x}, not a finite number")));
        }
        Ok(x)
    }

    /// The next token as a 1-based index in `1..=n`, returned 0-based.
    pub fn index1(&mut self, what: &str, n: usize) -> Result<u32, IoError> {
        let i: i64 = self.parse(what)?;
        if i < 1 || i as u64 > n as u64 {
            return Err(self.error(format!("{what} {i} is out of range 1..={n}")));
        }
        Ok((i - 1) as u32)
    }

    /// Skips the rest of the current line.
    pub fn skip_line(&mut self) {
        let b = self.text.as_bytes();
        while self.pos < b.len() && b[self.pos] != b'\n' {
            self.pos += 1;
        }
    }
}

fn shorten(s: &str) -> String {
    if s.chars().count() > 24 {
        format!("{}…", s.chars().take(24).collect::<String>())
    } else {
        s.to_string()
    }
}

/// The records of a line-oriented text file: each non-blank line, with `#`
/// comments removed, split into whitespace-separated fields, with its 1-based
/// line number. Used by the TetGen and GiD readers, whose records never span
/// lines.
pub(crate) struct Records<'a> {
    path: &'a Path,
    lines: std::iter::Enumerate<std::str::Lines<'a>>,
    /// Line of the record returned last (or of the end of the file).
    pub line: usize,
    fields: Vec<&'a str>,
}

impl<'a> Records<'a> {
    /// Records of `text`, read from `path`.
    pub fn new(path: &'a Path, text: &'a str) -> Records<'a> {
        Records {
            path,
            lines: text.lines().enumerate(),
            line: 0,
            fields: Vec::new(),
        }
    }

    /// The next record, or `None` at the end of the file.
    pub fn next_record(&mut self) -> Option<Vec<&'a str>> {
        for (i, l) in self.lines.by_ref() {
            self.line = i + 1;
            let l = l.split('#').next().unwrap_or("");
            self.fields.clear();
            self.fields.extend(l.split_whitespace());
            if !self.fields.is_empty() {
                return Some(self.fields.clone());
            }
        }
        self.line += 1;
        None
    }

    /// The next record, which must exist and have at least `min` fields.
    pub fn record(&mut self, what: &str, min: usize) -> Result<Vec<&'a str>, IoError> {
        let path = self.path;
        match self.next_record() {
            None => Err(IoError::at(
                path,
                self.line,
                format!("file ends where {what} was expected (truncated?)"),
            )),
            Some(f) if f.len() < min => Err(IoError::at(
                path,
                self.line,
                format!("{what} needs at least {min} fields, found {}", f.len()),
            )),
            Some(_) => Ok(self.fields.clone()),
        }
    }

    /// An error at the line of the record returned last.
    pub fn error(&self, message: impl Into<String>) -> IoError {
        IoError::at(self.path, self.line, message)
    }

    /// Field `s` parsed as `T`; `what` names it in the message.
    pub fn parse<T: FromStr>(&self, s: &str, what: &str) -> Result<T, IoError> {
        s.parse::<T>()
            .map_err(|_| self.error(format!("expected {what}, found '{}'", shorten(s))))
    }

    /// Field `s` as a finite coordinate.
    pub fn coord(&self, s: &str, what: &str) -> Result<f64, IoError> {
        let x: f64 = self.parse(s, what)?;
        if !x.is_finite() {
            return Err(self.error(format!("{what} is {x}, not a finite number")));
        }
        Ok(x)
    }

    /// Field `s` as a non-negative count no larger than `max`.
    pub fn count(&self, s: &str, what: &str, max: usize) -> Result<usize, IoError> {
        let n: i64 = self.parse(s, what)?;
        if n < 0 {
            return Err(self.error(format!("{what} {n} is negative")));
        }
        if n as u64 > max as u64 {
            return Err(self.error(format!(
                "{what} {n} is more than the file can hold (corrupt or truncated)"
            )));
        }
        Ok(n as usize)
    }
}
