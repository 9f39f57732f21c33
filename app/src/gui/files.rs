//! The seam between the workbench and files, so that the rest of the GUI never touches the file
//! system (a browser has none). A `.toml` file is a lesson; anything else a mesh.

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
pub fn open_dropped(file: &dyn eframe::egui::DroppedFile) -> Result<Opened, String> {
    open_path(&file.path().to_string_lossy())
}

/// In a browser a dropped file is read asynchronously: the reading starts here, and what it gives
/// arrives in `inbox` (see [`Inbox`]) a few frames later.
#[cfg(target_arch = "wasm32")]
pub fn open_dropped(file: eframe::egui::DroppedFileHandle, inbox: &Inbox) {
    let inbox = inbox.clone();
    wasm_bindgen_futures::spawn_local(async move {
        let name = file.path().to_path_buf();
        let opened = match file.bytes_async().await {
            Ok(bytes) => open_bytes(&name, &bytes),
            Err(error) => Err(format!("{}: {error}", name.display())),
        };
        inbox.0.borrow_mut().push(opened);
    });
}

/// Files read in the background (in a browser), waiting to be opened by the app.
#[cfg(target_arch = "wasm32")]
#[derive(Clone, Default)]
pub struct Inbox(std::rc::Rc<std::cell::RefCell<Vec<Result<Opened, String>>>>);

#[cfg(target_arch = "wasm32")]
impl Inbox {
    /// What has arrived since the last call.
    pub fn take(&self) -> Vec<Result<Opened, String>> {
        std::mem::take(&mut *self.0.borrow_mut())
    }
}

/// Opens a file given by name and contents: a lesson (.toml) or a Gmsh mesh (.msh). A TetGen mesh
/// is two files, which a browser hands over one by one.
#[cfg(target_arch = "wasm32")]
fn open_bytes(name: &std::path::Path, bytes: &[u8]) -> Result<Opened, String> {
    let text =
        std::str::from_utf8(bytes).map_err(|_| format!("{}: not a text file", name.display()))?;
    let extension = name.extension().and_then(|e| e.to_str()).unwrap_or("");
    match extension {
        "toml" => Lesson::parse(name, text)
            .map(|lesson| Opened::Lesson(Box::new(lesson)))
            .map_err(|e| e.to_string()),
        "msh" => {
            let (mesh, report) =
                tetlab_core::mesh::gmsh::parse(name, text).map_err(|e| e.to_string())?;
            let stem = name
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default();
            Ok(Opened::Scene(Scene::from_mesh(stem, mesh, report)))
        }
        "node" | "ele" => Err(format!(
            "{}: a TetGen mesh is two files (.node and .ele); in the browser, drop a Gmsh .msh file",
            name.display()
        )),
        _ => Err(format!(
            "{}: not a mesh (.msh) or a lesson (.toml)",
            name.display()
        )),
    }
}
