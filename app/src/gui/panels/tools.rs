//! Tools that deform the body or change the selection.

use crate::gui::workbench::Workbench;
use eframe::egui;
use tetlab_core::scene::Perturbation;

/// Shows the tools; "Inspect" opens the inspector.
pub fn show(ui: &mut egui::Ui, bench: &mut Workbench, inspector_open: &mut bool) {
    ui.heading("Tools");
    ui.horizontal_wrapped(|ui| {
        let has_selection = bench.selected_tet.is_some() && bench.selected_particle.is_some();
        if ui
            .add_enabled(has_selection, egui::Button::new("Invert selected tet"))
            .on_hover_text("I: reflect the selected particle through the opposite face")
            .clicked()
        {
            bench.invert_selected();
        }
        if ui.button("Mirror all").on_hover_text("M").clicked() {
            bench.perturb(Perturbation::Mirror);
        }
        if ui.button("Flatten all").on_hover_text("F").clicked() {
            bench.perturb(Perturbation::Flatten);
        }
        if ui.button("Scramble").on_hover_text("S").clicked() {
            bench.scramble();
        }
        if ui
            .button("Reset")
            .on_hover_text("R: back to the rest shape")
            .clicked()
        {
            bench.reset();
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
                if ui
                    .button(if pinned { "Unpin" } else { "Pin" })
                    .on_hover_text("P")
                    .clicked()
                {
                    bench.toggle_pin();
                }
                if ui
                    .button("Next tet")
                    .on_hover_text("T: the next tet of this particle")
                    .clicked()
                {
                    bench.next_tet_of_selected();
                }
                if ui
                    .button("Inspect")
                    .on_hover_text("E: C, grad C, w, lambda of this tet's constraints")
                    .clicked()
                {
                    *inspector_open = !*inspector_open;
                }
            });
        }
        (None, _) => {
            ui.label("click a particle to select it");
        }
    }
}
