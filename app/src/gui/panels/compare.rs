//! Side-by-side comparison: the same scene with a second set of constraint families.

use super::{Context, Panel};
use crate::gui::request::Request;
use eframe::egui;
use tetlab_core::constraints::{Families, PerFamily};

/// The comparison panel; it owns the families the second view will run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ComparePanel {
    /// The families to compare with.
    pub families: PerFamily<bool>,
}

impl Default for ComparePanel {
    /// The geometric families of a body: the material ones are another model, and contact
    /// another matter (between bodies), each added by choice.
    fn default() -> Self {
        ComparePanel {
            families: PerFamily::builtin_from_fn(|f| {
                let row = f.builtin_row().unwrap();
                row.compliance_from_material.is_none()
                    && row.binding != tetlab_core::constraints::Binding::Contacts
            }),
        }
    }
}

impl Panel for ComparePanel {
    fn ui(&mut self, ui: &mut egui::Ui, context: &Context<'_>, requests: &mut Vec<Request>) {
        let table = context.bench.simulation.families();
        if let Some(request) = show(ui, table, &mut self.families, context.comparison.is_some()) {
            requests.push(Request::Compare(request));
        }
    }
}

/// The comparison controls; the families to compare with when "Compare" is pressed, or
/// `Some(None)` when "Stop comparing" is.
fn show(
    ui: &mut egui::Ui,
    table: &Families,
    families: &mut PerFamily<bool>,
    comparing: bool,
) -> Option<Option<PerFamily<bool>>> {
    ui.heading("Compare");
    ui.horizontal_wrapped(|ui| {
        for (group, members) in table.groups() {
            let mut on = members.families().all(|f| families[f]);
            if ui
                .checkbox(&mut on, super::solver::group_label(table, group))
                .changed()
            {
                for family in members.families() {
                    families.set(family, on);
                }
            }
        }
    });
    let mut request = None;
    ui.horizontal(|ui| {
        if ui
            .button("Compare side by side")
            .on_hover_text("A second view: this scene and state with the families above")
            .clicked()
        {
            request = Some(Some(*families));
        }
        if ui
            .add_enabled(comparing, egui::Button::new("Stop comparing"))
            .clicked()
        {
            request = Some(None);
        }
    });
    request
}
