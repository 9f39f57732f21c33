//! What the 3D view shows.

use super::{Context, Panel};
use crate::gui::geometry::{ARROWS_ON_ALL_UP_TO, ViewOptions};
use crate::gui::request::Request;
use crate::gui::shortcuts::Action;
use eframe::egui;

/// The display panel; it owns the options the 3D views draw with.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DisplayPanel {
    /// What the views draw.
    pub options: ViewOptions,
}

impl Panel for DisplayPanel {
    fn ui(&mut self, ui: &mut egui::Ui, context: &Context<'_>, requests: &mut Vec<Request>) {
        let tets = context.bench.simulation.tets().len();
        if let Some(action) = show(ui, &mut self.options, tets) {
            requests.push(Request::Act(action));
        }
    }
}

/// The display options; the camera action asked for, if any.
fn show(ui: &mut egui::Ui, options: &mut ViewOptions, tets: usize) -> Option<Action> {
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
    ui.checkbox(&mut options.corrections, "Corrections dp (last substep)")
        .on_hover_text("The displacement the last substep's projections gave each particle");
    ui.add_enabled(
        options.corrections,
        egui::Slider::new(&mut options.correction_gain, 1.0..=1000.0)
            .logarithmic(true)
            .text("dp drawn x"),
    );
    let mut action = None;
    ui.horizontal(|ui| {
        if ui.button("Frame the body").on_hover_text("V").clicked() {
            action = Some(Action::FrameView);
        }
        if ui.button("Reset camera").on_hover_text("C").clicked() {
            action = Some(Action::ResetCamera);
        }
    });
    // Its own row: the panel does not grow wider for it.
    if ui
        .button("Copy link")
        .on_hover_text(
            "a link to this state (scene, settings, lesson, camera, edits) for the web page",
        )
        .clicked()
    {
        action = Some(Action::CopyLink);
    }
    action
}
