//! "Open mesh file…": a file browser inside the workbench (no blocking system dialog, nothing to
//! install). It lists folders and the files tetlab can open (.node, .ele, .msh, lesson and constraint .toml);
//! a click on a folder enters it, a click on a file opens it. Desktop only: a browser has no
//! folders to list.

use eframe::egui;
use std::path::{Path, PathBuf};

/// The extensions the browser shows.
pub const OPENABLE: [&str; 4] = ["node", "ele", "msh", "toml"];

/// The browser's state while it is open.
pub struct FileBrowser {
    folder: PathBuf,
    entries: Result<Vec<(String, bool)>, String>,
}

impl FileBrowser {
    /// A browser showing `folder`.
    pub fn new(folder: &Path) -> Self {
        let folder = folder
            .canonicalize()
            .unwrap_or_else(|_| folder.to_path_buf());
        let entries = list(&folder);
        FileBrowser { folder, entries }
    }

    /// The folder shown.
    pub fn folder(&self) -> &Path {
        &self.folder
    }

    /// Shows the browser window. Returns the file chosen, if one was; sets `open` to false when
    /// the window is closed or a file is chosen.
    pub fn show(&mut self, ctx: &egui::Context, open: &mut bool) -> Option<PathBuf> {
        let mut chosen = None;
        let mut enter = None;
        egui::Window::new("Open mesh file")
            .open(open)
            .default_size([420.0, 420.0])
            .show(ctx, |ui| {
                ui.monospace(self.folder.display().to_string());
                ui.separator();
                egui::ScrollArea::vertical().show(ui, |ui| {
                    if let Some(parent) = self.folder.parent()
                        && ui.button("..").clicked()
                    {
                        enter = Some(parent.to_path_buf());
                    }
                    match &self.entries {
                        Ok(entries) => {
                            for (name, is_folder) in entries {
                                let label = if *is_folder {
                                    format!("{name}/")
                                } else {
                                    name.clone()
                                };
                                if ui.button(label).clicked() {
                                    let path = self.folder.join(name);
                                    if *is_folder {
                                        enter = Some(path);
                                    } else {
                                        chosen = Some(path);
                                    }
                                }
                            }
                        }
                        Err(message) => {
                            ui.colored_label(egui::Color32::from_rgb(220, 60, 60), message);
                        }
                    }
                });
            });
        if let Some(folder) = enter {
            *self = FileBrowser::new(&folder);
        }
        if chosen.is_some() {
            *open = false;
        }
        chosen
    }
}

/// The folders and openable files of `folder`, folders first, each group by name; hidden ones
/// (starting with '.') left out.
fn list(folder: &Path) -> Result<Vec<(String, bool)>, String> {
    let read = std::fs::read_dir(folder).map_err(|e| format!("{}: {e}", folder.display()))?;
    let mut entries: Vec<(String, bool)> = read
        .filter_map(Result::ok)
        .filter_map(|entry| {
            let name = entry.file_name().to_string_lossy().into_owned();
            let is_folder = entry.path().is_dir();
            let openable = Path::new(&name)
                .extension()
                .is_some_and(|e| OPENABLE.iter().any(|o| e == *o));
            (!name.starts_with('.') && (is_folder || openable)).then_some((name, is_folder))
        })
        .collect();
    entries.sort_by(|a, b| b.1.cmp(&a.1).then_with(|| a.0.cmp(&b.0)));
    Ok(entries)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn it_lists_folders_then_openable_files() {
        let dir = std::env::temp_dir().join(format!("tetlab-browser-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("sub")).unwrap();
        for name in ["b.msh", "a.node", "notes.txt", ".hidden.msh", "lesson.toml"] {
            std::fs::write(dir.join(name), "").unwrap();
        }
        let names: Vec<(String, bool)> = list(&dir).unwrap();
        assert_eq!(
            names,
            [
                ("sub".to_owned(), true),
                ("a.node".to_owned(), false),
                ("b.msh".to_owned(), false),
                ("lesson.toml".to_owned(), false),
            ]
        );
        assert!(list(&dir.join("missing")).is_err());
    }
}
