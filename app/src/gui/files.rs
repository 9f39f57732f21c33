//! The seam between the workbench and files, so that the rest of the GUI never touches the file
//! system (a browser has none). A `.toml` file is a constraint file when it says what it
//! `applies_to`, a scene of several bodies when it has `[[body]]` tables, and a lesson
//! otherwise; anything else a mesh.

use tetlab_core::constraint_file::ConstraintFile;
use tetlab_core::scene::Scene;
use tetlab_core::teaching::lesson::Lesson;

/// What a file held.
pub enum Opened {
    /// A mesh, or a scene file of several bodies, as a scene.
    Scene(Scene),
    /// A lesson.
    Lesson(Box<Lesson>),
    /// A constraint file, as text: it goes to the editor, which compiles it (and shows its
    /// mistake, if it has one, where it can be mended).
    Constraint {
        /// Where it came from.
        path: std::path::PathBuf,
        /// Its text.
        text: String,
    },
}

/// Opens a mesh or lesson file by path. A TetGen mesh is read from its two files (`.node` and
/// `.ele`); anything else is read here and opened by `open_bytes`, as in a browser.
#[cfg(not(target_arch = "wasm32"))]
pub fn open_path(path: &str) -> Result<Opened, String> {
    let path = std::path::Path::new(path);
    if path.extension().is_some_and(|e| e == "node" || e == "ele") {
        return Scene::load(path)
            .map(Opened::Scene)
            .map_err(|e| e.to_string());
    }
    let bytes = std::fs::read(path).map_err(|e| format!("{}: cannot read: {e}", path.display()))?;
    open_bytes(path, &bytes)
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
fn open_bytes(name: &std::path::Path, bytes: &[u8]) -> Result<Opened, String> {
    let text = tetlab_core::input::text_file::decode(bytes).map_err(|e| {
        let line = e.line.map(|l| format!(":{l}")).unwrap_or_default();
        format!("{}{line}: {}", name.display(), e.message)
    })?;
    let extension = name.extension().and_then(|e| e.to_str()).unwrap_or("");
    match extension {
        "toml" if ConstraintFile::looks_like(text) => Ok(Opened::Constraint {
            path: name.to_owned(),
            text: text.to_owned(),
        }),
        // Its bodies' mesh files are read beside it (in a browser only built-ins can be).
        "toml" if Scene::looks_like_file(text) => Scene::parse_file(name, text)
            .map(Opened::Scene)
            .map_err(|e| e.to_string()),
        "toml" => Lesson::parse(name, text)
            .map(|lesson| Opened::Lesson(Box::new(lesson)))
            .map_err(|e| e.to_string()),
        "msh" => {
            let (mesh, report) =
                tetlab_core::scene::mesh::gmsh::parse(name, text).map_err(|e| e.to_string())?;
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
            "{}: not a mesh (.msh), a lesson, a constraint file or a scene file (.toml)",
            name.display()
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn opened_name(opened: Result<Opened, String>) -> String {
        match opened {
            Ok(Opened::Scene(scene)) => format!("scene {}", scene.name),
            Ok(Opened::Lesson(lesson)) => format!("lesson {}", lesson.title),
            Ok(Opened::Constraint { path, .. }) => format!("constraint {}", path.display()),
            Err(message) => message,
        }
    }

    /// What a browser hands over (a name and the bytes) opens as on the desktop.
    #[test]
    fn dropped_bytes_open_meshes_and_lessons_and_explain_what_they_cannot() {
        if let Some(path) = tetlab_core::input::shared_meshes::for_test("ball_v41.msh") {
            let ball = std::fs::read(path).unwrap();
            assert_eq!(
                opened_name(open_bytes(Path::new("ball_v41.msh"), &ball)),
                "scene ball_v41"
            );
        }
        let lesson = tetlab_core::teaching::lesson::BUILTIN[0];
        assert!(
            opened_name(open_bytes(Path::new(lesson.file), lesson.text.as_bytes()))
                .starts_with("lesson 1.")
        );
        let example = tetlab_core::constraint_file::EXAMPLES[0];
        assert_eq!(
            opened_name(open_bytes(Path::new(example.file), example.text.as_bytes())),
            format!("constraint {}", example.file)
        );
        let broken = b"name = \"x\"\napplies_to = \"edges\"\nvalue = \"length(\"\n";
        assert_eq!(
            opened_name(open_bytes(Path::new("broken.toml"), broken)),
            "constraint broken.toml",
            "a constraint file with a mistake goes to the editor"
        );
        let node = opened_name(open_bytes(Path::new("bunny.node"), b"4 3 0 0\n"));
        assert!(node.contains("two files"), "{node}");
        let bad = opened_name(open_bytes(Path::new("bad.msh"), b"$MeshFormat\n9.9 0 8\n"));
        assert!(bad.starts_with("bad.msh:2:"), "{bad}");
        assert!(
            opened_name(open_bytes(Path::new("x.msh"), &[0xff, 0xfe]))
                .contains("x.msh:1: not text")
        );
        assert!(opened_name(open_bytes(Path::new("notes.txt"), b"hi")).contains("not a mesh"));
    }
}
