//! The scene files that come with tetlab (`assets/scenes/*.toml`), built into the library so
//! that a link or a menu can name one by its file name, on the desktop and in the browser,
//! where there is no file system ([`ShippedScene`]).

use super::{Scene, SceneError};
use std::path::Path;

/// A scene file of `assets/scenes`, built into the library.
#[derive(Clone, Copy, Debug)]
pub struct ShippedScene {
    /// Its file name, e.g. `stacked-cubes.toml`.
    pub file: &'static str,
    /// Where the file was when tetlab was built: its mesh files are found beside it.
    pub path: &'static str,
    /// The file's text.
    pub text: &'static str,
}

include!(concat!(env!("OUT_DIR"), "/shipped_scenes.rs"));

impl ShippedScene {
    /// The shipped scene file named `file` (`stacked-cubes.toml`).
    ///
    /// ```
    /// use tetlab_core::scene::ShippedScene;
    /// let stack = ShippedScene::named("stacked-cubes.toml").unwrap();
    /// let scene = stack.scene().unwrap();
    /// assert_eq!(scene.bodies.len(), 2);
    /// assert!(ShippedScene::named("teapot.toml").is_none());
    /// ```
    pub fn named(file: &str) -> Option<&'static ShippedScene> {
        SHIPPED.iter().find(|s| s.file == file)
    }

    /// The file names of every shipped scene, in file-name order, for a message or a menu.
    pub fn names() -> impl Iterator<Item = &'static str> {
        SHIPPED.iter().map(|s| s.file)
    }

    /// Its scene: the built-in bodies made, the mesh files read from beside where the file was
    /// when tetlab was built (a scene that needs one that is not there, as in the browser, is
    /// an error naming it).
    pub fn scene(&self) -> Result<Scene, SceneError> {
        Scene::parse_file(Path::new(self.path), self.text)
    }
}
