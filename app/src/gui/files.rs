//! The seam between the workbench and files, so that the rest of the GUI never touches the file
//! system (a browser has none). A `.toml` file is a lesson; anything else a mesh.

use eframe::egui::DroppedFile;
use tetlab_core::lesson::Lesson;
use tetlab_core::scene::Scene;

/// What a file held.
pub enum Opened {
    /// A mesh, as a scene.
    Scene(Scene),
    /// A lesson.
    Lesson(Box<Lesson>),
}

/// Opens a mesh or lesson file by path.
#[cfg(not(target_arch = "wasm32"))]
pub fn open_path(path: &str) -> Result<Opened, String> {
    let path = std::path::Path::new(path);
    if path.extension().is_some_and(|e| e == "toml") {
        Lesson::load(path)
            .map(|lesson| Opened::Lesson(Box::new(lesson)))
            .map_err(|e| e.to_string())
    } else {
        Scene::load(path)
            .map(Opened::Scene)
            .map_err(|e| e.to_string())
    }
}

/// Paths cannot be opened in a browser.
#[cfg(target_arch = "wasm32")]
pub fn open_path(path: &str) -> Result<Opened, String> {
    Err(format!("{path}: a browser cannot open files by path"))
}

/// Opens a file dropped on the window. On the desktop it has an absolute path.
#[cfg(not(target_arch = "wasm32"))]
pub fn open_dropped(file: &dyn DroppedFile) -> Result<Opened, String> {
    open_path(&file.path().to_string_lossy())
}

/// In a browser a dropped file is read asynchronously; the web build does that.
#[cfg(target_arch = "wasm32")]
pub fn open_dropped(file: &dyn DroppedFile) -> Result<Opened, String> {
    Err(format!(
        "{}: dropping files is not supported in this build",
        file.path().display()
    ))
}
