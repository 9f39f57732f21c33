//! Reading mesh text files line by line, with errors that name the file and line.

use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;

/// A mesh file that could not be read: which file, which line (when one is to blame), and why.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshError {
    /// The file.
    pub path: PathBuf,
    /// The 1-based line, when one line is to blame.
    pub line: Option<usize>,
    /// What is wrong.
    pub message: String,
}

impl MeshError {
    /// An error about line `line` of `path`.
    pub fn at(path: &Path, line: usize, message: impl Into<String>) -> Self {
        Self {
            path: path.to_owned(),
            line: Some(line),
            message: message.into(),
        }
    }

    /// An error about the file as a whole.
    pub(crate) fn whole_file(path: &Path, message: impl Into<String>) -> Self {
        Self {
            path: path.to_owned(),
            line: None,
            message: message.into(),
        }
    }
}

impl fmt::Display for MeshError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(line) => write!(f, "{}:{}: {}", self.path.display(), line, self.message),
            None => write!(f, "{}: {}", self.path.display(), self.message),
        }
    }
}

impl std::error::Error for MeshError {}

/// The most values (attributes, markers) a header may declare for each line that follows.
pub(super) const MAX_VALUES_PER_LINE: usize = 1 << 16;

/// The non-blank lines of a text file, split into words, with `#` comments removed when asked.
pub(crate) struct Lines<'a> {
    path: &'a Path,
    lines: std::iter::Enumerate<std::str::Lines<'a>>,
    comments: bool,
    /// The number of the last line read (1-based), or 0.
    last_line: usize,
}

/// One line: its 1-based number and its words.
pub(crate) struct Line<'a> {
    pub number: usize,
    pub words: Vec<&'a str>,
    path: &'a Path,
}

impl<'a> Lines<'a> {
    /// Reads `path` whole as text ([`crate::input::text_file::read`]) for [`Lines::new`].
    pub(super) fn read(path: &Path) -> Result<String, MeshError> {
        crate::input::text_file::read(path).map_err(|e| MeshError {
            path: path.to_owned(),
            line: e.line,
            message: e.message,
        })
    }

    /// Lines of `text` read from `path`; `comments` removes everything from a `#` on.
    pub(super) fn new(path: &'a Path, text: &'a str, comments: bool) -> Self {
        Self {
            path,
            lines: crate::input::text_file::without_byte_order_mark(text)
                .lines()
                .enumerate(),
            comments,
            last_line: 0,
        }
    }

    /// The next line with any words on it, or an error saying the file ended while `expecting`.
    pub(super) fn next_line(&mut self, expecting: &str) -> Result<Line<'a>, MeshError> {
        self.next_or_end().ok_or_else(|| {
            MeshError::at(
                self.path,
                self.last_line + 1,
                format!("file ends; expected {expecting}"),
            )
        })
    }

    /// The next line with any words on it, or `None` at the end of the file.
    pub(super) fn next_or_end(&mut self) -> Option<Line<'a>> {
        for (index, raw) in self.lines.by_ref() {
            let content = if self.comments {
                raw.split('#').next().unwrap_or_default()
            } else {
                raw
            };
            let words: Vec<&str> = content.split_whitespace().collect();
            self.last_line = index + 1;
            if !words.is_empty() {
                return Some(Line {
                    number: index + 1,
                    words,
                    path: self.path,
                });
            }
        }
        None
    }
}

impl Line<'_> {
    /// An error about this line.
    pub(super) fn error(&self, message: impl Into<String>) -> MeshError {
        MeshError::at(self.path, self.number, message)
    }

    /// Requires at least `n` words, naming what they are.
    pub(super) fn expect_at_least(&self, n: usize, what: &str) -> Result<(), MeshError> {
        if self.words.len() < n {
            Err(self.error(format!(
                "expected {what} ({n} values), found {}",
                self.words.len()
            )))
        } else {
            Ok(())
        }
    }

    /// Word `i` as an integer, naming what it is in the error.
    pub(super) fn integer<T: FromStr>(&self, i: usize, what: &str) -> Result<T, MeshError> {
        let word = self.word(i, what)?;
        word.parse().map_err(|_| {
            self.error(format!(
                "{what}: '{word}' is not a non-negative integer in range"
            ))
        })
    }

    /// Word `i` as a finite number, naming what it is in the error.
    pub(super) fn number(&self, i: usize, what: &str) -> Result<f64, MeshError> {
        let word = self.word(i, what)?;
        match word.parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(x),
            Ok(_) => Err(self.error(format!("{what}: '{word}' is not a finite number"))),
            Err(_) => Err(self.error(format!("{what}: '{word}' is not a number"))),
        }
    }

    /// Word `i` as a coordinate within [`crate::input::limits::MAX_COORDINATE`].
    pub(super) fn coordinate(&self, i: usize, what: &str) -> Result<f64, MeshError> {
        let x = self.number(i, what)?;
        crate::input::limits::coordinate(x).map_err(|e| self.error(format!("{what}: {e}")))
    }

    /// Word `i` as a count of tets (or of elements that may be tets), at most
    /// [`crate::input::limits::MAX_TETS`].
    pub(super) fn tet_count(&self, i: usize, what: &str) -> Result<usize, MeshError> {
        let count: usize = self.integer(i, what)?;
        crate::input::limits::tet_count(count).map_err(|e| self.error(format!("{what}: {e}")))
    }

    /// Word `i` as a count of values per line (attributes, markers), at most
    /// [`MAX_VALUES_PER_LINE`]: more than any line of a mesh holds.
    pub(super) fn per_line(&self, i: usize, what: &str) -> Result<usize, MeshError> {
        let count: usize = self.integer(i, what)?;
        if count <= MAX_VALUES_PER_LINE {
            Ok(count)
        } else {
            Err(self.error(format!(
                "{what}: {count} is more than the {MAX_VALUES_PER_LINE} values a line may hold"
            )))
        }
    }

    fn word(&self, i: usize, what: &str) -> Result<&str, MeshError> {
        self.words
            .get(i)
            .copied()
            .ok_or_else(|| self.error(format!("missing {what}")))
    }
}

/// Checks that the four node numbers of a tet, as written in the file, are distinct.
pub(crate) fn check_distinct(line: &Line<'_>, written: [u64; 4]) -> Result<(), MeshError> {
    for a in 0..4 {
        for b in a + 1..4 {
            if written[a] == written[b] {
                return Err(line.error(format!("the tet uses node {} twice", written[a])));
            }
        }
    }
    Ok(())
}
