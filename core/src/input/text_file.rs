//! A user's text file (a mesh, a lesson) read as UTF-8, with the line of the first byte that is
//! not UTF-8 when it fails; and the byte-order mark some editors put first, which every parser
//! skips (`without_byte_order_mark`) so that it is never quoted, invisibly, in an error about
//! the first word.

use std::path::Path;

/// Why a file could not be read as text: the line (from 1) when one is to blame, and what is
/// wrong.
#[derive(Clone, Debug, PartialEq)]
pub struct TextFileError {
    /// The line of the first byte that is not UTF-8; `None` when the file could not be read.
    pub line: Option<usize>,
    /// What is wrong.
    pub message: String,
}

/// The UTF-8 byte-order mark, U+FEFF.
const BYTE_ORDER_MARK: &str = "\u{feff}";

/// `text` without the byte-order mark it may start with.
pub(crate) fn without_byte_order_mark(text: &str) -> &str {
    text.strip_prefix(BYTE_ORDER_MARK).unwrap_or(text)
}

/// Line and column (from 1, in characters) of byte `offset` of `text`: where an error in a
/// user's file is placed.
///
/// ```
/// use tetlab_core::input::text_file::position;
/// assert_eq!(position("a = 1\nbé = x\n", 10), (2, 4), "é is one character of two bytes");
/// ```
pub fn position(text: &str, offset: usize) -> (usize, usize) {
    let offset = offset.min(text.len());
    let before = &text[..text.floor_char_boundary(offset)];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, column)
}

/// `bytes` as text.
///
/// ```
/// use tetlab_core::input::text_file::decode;
/// assert_eq!(decode(b"4 3 0 0\n"), Ok("4 3 0 0\n"));
/// assert_eq!(decode(b"one\ntwo \xff\n").unwrap_err().line, Some(2));
/// ```
pub fn decode(bytes: &[u8]) -> Result<&str, TextFileError> {
    match std::str::from_utf8(bytes) {
        Ok(text) => Ok(text),
        Err(e) => {
            let line = 1 + bytes[..e.valid_up_to()]
                .iter()
                .filter(|&&b| b == b'\n')
                .count();
            Err(TextFileError {
                line: Some(line),
                message: "not text: invalid UTF-8 (binary files are not supported)".into(),
            })
        }
    }
}

/// The file at `path` as text; where it cannot be read, a file of that name [`provide`]d by a
/// front end without a file system.
pub fn read(path: &Path) -> Result<String, TextFileError> {
    let bytes = match std::fs::read(path) {
        Ok(bytes) => bytes,
        Err(e) => {
            return provided(path).ok_or_else(|| TextFileError {
                line: None,
                message: format!("cannot read: {e}"),
            });
        }
    };
    decode(&bytes).map(str::to_owned)
}

/// Files handed over by a front end that has no file system: a web page fetches the meshes its
/// lessons need from its own site and provides them here, by file name, so that a lesson naming
/// `../shared/meshes/bunny.node` opens as on the desktop.
static PROVIDED: std::sync::Mutex<Vec<(String, String)>> = std::sync::Mutex::new(Vec::new());

/// Provides the text of a file named `name` (a file name, no folder) to [`read`] and
/// `available`, for paths that end in that name and cannot be read.
///
/// ```
/// use std::path::Path;
/// use tetlab_core::input::text_file::{provide, read};
/// let path = Path::new("/nowhere/provided-doctest.node");
/// assert!(read(path).is_err());
/// provide("provided-doctest.node", "1 3 0 0\n0 0 0 0\n".into());
/// assert_eq!(read(path).unwrap(), "1 3 0 0\n0 0 0 0\n");
/// ```
pub fn provide(name: &str, text: String) {
    let mut provided = PROVIDED.lock().unwrap_or_else(|e| e.into_inner());
    provided.retain(|(n, _)| n != name);
    provided.push((name.to_owned(), text));
}

/// The provided text for `path`'s file name, if any.
fn provided(path: &Path) -> Option<String> {
    let name = path.file_name()?.to_str()?;
    let provided = PROVIDED.lock().unwrap_or_else(|e| e.into_inner());
    provided
        .iter()
        .find(|(n, _)| n == name)
        .map(|(_, text)| text.clone())
}

/// Whether `path` can be read: it exists, or a file of its name was [`provide`]d.
pub(crate) fn available(path: &Path) -> bool {
    path.exists() || provided(path).is_some()
}

#[cfg(test)]
mod examples {
    #[allow(unused_imports)]
    use super::*;

    /// The example of `without_byte_order_mark`'s documentation (a unit test: the item is not exported).
    #[test]
    fn without_byte_order_mark_example() {
        use crate::input::text_file::without_byte_order_mark;
        assert_eq!(without_byte_order_mark("\u{feff}4 3 0 0\n"), "4 3 0 0\n");
        assert_eq!(without_byte_order_mark("4 3 0 0\n"), "4 3 0 0\n");
    }
}
