//! The keyboard shortcuts and mouse controls.

use super::{Context, Panel};
use crate::gui::request::Request;
use crate::gui::shortcuts::SHORTCUTS;
use eframe::egui;

/// The help window.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Help {
    /// Whether it is shown.
    pub open: bool,
}

impl Panel for Help {
    fn ui(&mut self, ui: &mut egui::Ui, _: &Context<'_>, _: &mut Vec<Request>) {
        show(ui.ctx(), &mut self.open);
    }
}

/// Shows the help as a window while `open` is true.
fn show(ctx: &egui::Context, open: &mut bool) {
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
                        "drop a constraint .toml file",
                        "open it in the constraint editor",
                    ),
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
