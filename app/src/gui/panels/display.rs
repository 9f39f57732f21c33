//! What the 3D view shows.

use crate::gui::geometry::{ARROWS_ON_ALL_UP_TO, ViewOptions};
use eframe::egui;

/// Shows the display options; returns true if "frame the body" was pressed.
pub fn show(ui: &mut egui::Ui, options: &mut ViewOptions, tets: usize) -> bool {
    ui.heading("Display");
    ui.checkbox(&mut options.see_through, "See-through (all faces)");
    ui.checkbox(&mut options.colour_by_volume, "Colour by V/V0");
    ui.horizontal(|ui| {
        ui.checkbox(&mut options.particles, "Particles");
        ui.checkbox(&mut options.edges, "Edges");
    });
    ui.checkbox(&mut options.arrows, "Gradient arrows (grad C)");
    ui.add_enabled(
        tets <= ARROWS_ON_ALL_UP_TO,
        egui::Checkbox::new(
            &mut options.arrows_on_all_tets,
            format!("Arrows on all tets (up to {ARROWS_ON_ALL_UP_TO})"),
        ),
    );
    ui.add(
        egui::Slider::new(&mut options.arrow_scale, 0.1..=4.0)
            .logarithmic(true)
            .text("arrow length"),
    );
    ui.button("Frame the body").on_hover_text("V").clicked()
}
