//! The seam between the workbench and files, so that the rest of the GUI never touches the file
//! system (a browser has none).

use eframe::egui::DroppedFile;
use tetlab_core::scene::Scene;

/// Loads a mesh file by path.
#[cfg(not(target_arch = "wasm32"))]
pub fn load_path(path: &str) -> Result<Scene, String> {
    Scene::load(std::path::Path::new(path)).map_err(|e| e.to_string())
}

/// Paths cannot be opened in a browser.
#[cfg(target_arch = "wasm32")]
pub fn load_path(path: &str) -> Result<Scene, String> {
    Err(format!("{path}: a browser cannot open files by path"))
}

/// Loads a file dropped on the window. On the desktop it has an absolute path.
#[cfg(not(target_arch = "wasm32"))]
pub fn load_dropped(file: &dyn DroppedFile) -> Result<Scene, String> {
    load_path(&file.path().to_string_lossy())
}

/// In a browser a dropped file is read asynchronously; the web build does that.
#[cfg(target_arch = "wasm32")]
pub fn load_dropped(file: &dyn DroppedFile) -> Result<Scene, String> {
    Err(format!(
        "{}: dropping files is not supported in this build",
        file.path().display()
    ))
}
