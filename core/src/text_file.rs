//! A user's text file (a mesh, a lesson) read as UTF-8, with the line of the first byte that is
//! not UTF-8 when it fails; and the byte-order mark some editors put first, which every parser
//! skips ([`without_byte_order_mark`]) so that it is never quoted, invisibly, in an error about
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
///
/// ```
/// use tetlab_core::text_file::without_byte_order_mark;
/// assert_eq!(without_byte_order_mark("\u{feff}4 3 0 0\n"), "4 3 0 0\n");
/// assert_eq!(without_byte_order_mark("4 3 0 0\n"), "4 3 0 0\n");
/// ```
pub fn without_byte_order_mark(text: &str) -> &str {
    text.strip_prefix(BYTE_ORDER_MARK).unwrap_or(text)
}

/// `bytes` as text.
///
/// ```
/// use tetlab_core::text_file::decode;
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

/// The file at `path` as text.
pub fn read(path: &Path) -> Result<String, TextFileError> {
    let bytes = std::fs::read(path).map_err(|e| TextFileError {
        line: None,
        message: format!("cannot read: {e}"),
    })?;
    decode(&bytes).map(str::to_owned)
}
