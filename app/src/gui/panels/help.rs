//! The keyboard shortcuts and mouse controls.

use crate::gui::shortcuts::SHORTCUTS;
use eframe::egui;

/// Shows the help as a window while `open` is true.
pub fn show(ctx: &egui::Context, open: &mut bool) {
    egui::Window::new("Help")
        .open(open)
        .resizable(false)
        .show(ctx, |ui| {
            egui::Grid::new("shortcuts").striped(true).show(ui, |ui| {
                for (key, _, what) in SHORTCUTS {
                    ui.monospace(key.name());
                    ui.label(what);
                    ui.end_row();
                }
                for (gesture, what) in [
                    (
                        "left-drag a particle",
                        "move it (grab while playing, place while paused)",
                    ),
                    ("left-drag elsewhere", "orbit"),
                    ("right- / middle-drag", "pan"),
                    ("wheel", "zoom"),
                    ("click a particle", "select it and its tet"),
                    ("drop a .msh/.node/.ele file", "load it"),
                    ("drop a lesson .toml file", "open the lesson"),
                    (
                        "two views (comparing)",
                        "keys act on both; a drag moves particles in its own view",
                    ),
                ] {
                    ui.monospace(gesture);
                    ui.label(what);
                    ui.end_row();
                }
            });
        });
}
