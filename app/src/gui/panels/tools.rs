//! Tools that deform the body or change the selection. Each adds an [`Action`]; the app does it
//! (to both simulations when two are compared).

use super::{Context, Panel};
use crate::gui::request::Request;
use crate::gui::shortcuts::Action;
use eframe::egui;

/// The tools panel.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Tools;

impl Panel for Tools {
    fn ui(&mut self, ui: &mut egui::Ui, context: &Context<'_>, requests: &mut Vec<Request>) {
        let mut actions = Vec::new();
        show(ui, context, &mut actions);
        requests.extend(actions.into_iter().map(Request::Act));
    }
}

/// The tools' buttons; what they ask for goes to `actions`.
fn show(ui: &mut egui::Ui, context: &Context<'_>, actions: &mut Vec<Action>) {
    let bench = context.bench;
    ui.heading("Tools");
    ui.horizontal_wrapped(|ui| {
        let has_selection = bench.selected_tet.is_some() && bench.selected_particle.is_some();
        if ui
            .add_enabled(has_selection, egui::Button::new("Invert selected tet"))
            .on_hover_text("I: reflect the selected particle through the opposite face")
            .clicked()
        {
            actions.push(Action::InvertSelected);
        }
        for (label, hint, action) in [
            ("Mirror all", "M", Action::Mirror),
            ("Flatten all", "F", Action::Flatten),
            ("Scramble", "S", Action::Scramble),
            ("Reset", "R: back to the rest shape", Action::Reset),
        ] {
            if ui.button(label).on_hover_text(hint).clicked() {
                actions.push(action);
            }
        }
    });
    ui.separator();
    match (bench.selected_particle, bench.selected_tet) {
        (Some(particle), tet) => {
            let pinned = bench.simulation.is_pinned(particle);
            ui.label(format!(
                "selected particle {particle}{}",
                if pinned { " (pinned)" } else { "" }
            ));
            if let Some(tet) = tet {
                ui.label(format!(
                    "selected tet {tet}: {:?}",
                    bench.simulation.tets()[tet]
                ));
            }
            ui.horizontal(|ui| {
                for (label, hint, action) in [
                    (if pinned { "Unpin" } else { "Pin" }, "P", Action::TogglePin),
                    (
                        "Next tet",
                        "T: the next tet of this particle",
                        Action::NextTet,
                    ),
                    (
                        "Inspect",
                        "E: C, grad C, w, lambda of this tet's constraints",
                        Action::Inspector,
                    ),
                    (
                        "Modes",
                        "D: the eigenvalues and modes of this tet's energy",
                        Action::Modes,
                    ),
                ] {
                    if ui.button(label).on_hover_text(hint).clicked() {
                        actions.push(action);
                    }
                }
            });
        }
        (None, _) => {
            ui.label("click a particle to select it");
        }
    }
}
