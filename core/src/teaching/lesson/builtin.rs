//! The lessons that come with tetlab, built into the library, and what a lesson says about
//! itself before it is opened.

use super::format::{line_of, resolve_scene};
use super::*;

/// A lesson that comes with tetlab: a file of `assets/lessons`, built into the library.
#[derive(Clone, Copy, Debug)]
pub struct BuiltinLesson {
    /// Its file name, e.g. `01-distance.toml`.
    pub file: &'static str,
    /// Where the file was when tetlab was built (mesh scenes are found relative to it).
    pub path: &'static str,
    /// The file's text.
    pub text: &'static str,
}

include!(concat!(env!("OUT_DIR"), "/lessons.rs"));

/// What a lesson file says about itself before its scene is built: its title and its scene, so
/// that a lesson can be listed (and its missing mesh named) even when it cannot be opened.
#[derive(Clone, Debug, PartialEq)]
pub struct LessonHeader {
    /// Its title.
    pub title: String,
    /// Its scene: a built-in name, or a mesh path resolved against the lesson's folder.
    pub scene: String,
}

/// The two fields [`LessonHeader`] reads; the rest of the file is left to [`Lesson::parse`].
#[derive(serde::Deserialize)]
struct RawHeader {
    title: String,
    scene: String,
}

impl LessonHeader {
    /// The title and scene of lesson `text` from `path`.
    pub fn parse(path: &Path, text: &str) -> Result<LessonHeader, LessonError> {
        let text = crate::input::text_file::without_byte_order_mark(text);
        let raw: RawHeader = toml::from_str(text).map_err(|e| LessonError {
            path: path.to_owned(),
            line: e.span().map(|s| line_of(text, s.start)),
            message: e.message().trim().to_owned(),
        })?;
        Ok(LessonHeader {
            title: raw.title,
            scene: resolve_scene(path, &raw.scene),
        })
    }

    /// The mesh file the lesson needs, when it needs one that is not there.
    pub fn missing_mesh(&self) -> Option<&str> {
        let builtin = crate::scene::Builtin::from_name(&self.scene).is_some();
        let here = crate::input::text_file::available(Path::new(&self.scene));
        (!builtin && !here).then_some(self.scene.as_str())
    }
}

impl BuiltinLesson {
    /// Its title and scene ([`LessonHeader::parse`]).
    pub fn header(&self) -> Result<LessonHeader, LessonError> {
        LessonHeader::parse(Path::new(self.path), self.text)
    }
}
