//! The solver settings: method, families with their compliance or stiffness, substeps and the
//! rest. The panel edits a copy; the app applies a change to every simulation shown.

use eframe::egui;
use tetlab_core::constraints::Family;
use tetlab_core::solver::{Method, Settings};

/// Shows `current`; returns the settings the user changed them to, if they did.
pub fn show(ui: &mut egui::Ui, current: &Settings) -> Option<Settings> {
    ui.heading("Solver");
    let mut settings = *current;
    ui.horizontal(|ui| {
        ui.radio_value(&mut settings.method, Method::Xpbd, "XPBD");
        ui.radio_value(&mut settings.method, Method::Pbd, "PBD");
    });
    for family in Family::all() {
        ui.horizontal(|ui| {
            ui.checkbox(&mut settings.active[family], family.row().label);
            match settings.method {
                Method::Xpbd => {
                    ui.add(
                        egui::DragValue::new(&mut settings.compliance[family])
                            .range(0.0..=10.0)
                            .speed(1e-4)
                            .prefix("alpha "),
                    )
                    .on_hover_text("XPBD compliance: 0 is rigid, larger is softer");
                }
                Method::Pbd => {
                    ui.add(egui::Slider::new(&mut settings.stiffness[family], 0.0..=1.0).text("k"));
                }
            }
        });
    }
    ui.add(egui::Slider::new(&mut settings.substeps, 1..=50).text("substeps"));
    ui.add(egui::Slider::new(&mut settings.iterations, 1..=20).text("iterations"));
    ui.add(egui::Slider::new(&mut settings.gravity, 0.0..=20.0).text("gravity"));
    ui.checkbox(&mut settings.ground, "ground (y = 0)");
    ui.add(egui::Slider::new(&mut settings.damping, 0.0..=10.0).text("damping"));
    ui.checkbox(&mut settings.settle_edits, "settle edits")
        .on_hover_text(
            "After an invert, mirror, flatten or drag, corrections may move particles but not \
         speed them up until the edit is undone",
        );
    (settings != *current).then_some(settings)
}
