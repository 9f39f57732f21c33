//! Side-by-side comparison: the same scene with a second set of constraint families.

use eframe::egui;
use tetlab_core::constraints::Family;
use tetlab_core::constraints::PerFamily;

/// Shows the comparison controls; returns the families to compare with when "Compare" is
/// pressed, or `Some(None)` when "Stop comparing" is.
pub fn show(
    ui: &mut egui::Ui,
    families: &mut PerFamily<bool>,
    comparing: bool,
) -> Option<Option<PerFamily<bool>>> {
    ui.heading("Compare");
    ui.horizontal_wrapped(|ui| {
        for (group, members) in Family::groups() {
            let mut on = members.families().all(|f| families[f]);
            if ui
                .checkbox(&mut on, super::solver::group_label(group))
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
