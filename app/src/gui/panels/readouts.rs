//! Live numbers and their plots over time.

use super::{Context, Panel};
use crate::gui::request::Request;
use crate::gui::workbench::Sample;
use eframe::egui;
use egui_plot::{Legend, Line, Plot, PlotPoints};

/// Each plot's height: three fit where two of 110 did, so the display panel below stays in a
/// window 800 pixels high.
const PLOT_HEIGHT: f32 = 75.0;

/// Each plot's height with the fourth, the distance from the exact step, shown: the four take
/// the room of three.
const PLOT_HEIGHT_OF_FOUR: f32 = 0.75 * PLOT_HEIGHT;

/// The readouts: the metrics of the current frame, the engine and timings, and plots of the
/// recent frames.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Readouts;

impl Panel for Readouts {
    fn ui(&mut self, ui: &mut egui::Ui, context: &Context<'_>, requests: &mut Vec<Request>) {
        show(ui, context, requests);
    }
}

fn show(ui: &mut egui::Ui, context: &Context<'_>, requests: &mut Vec<Request>) {
    let (bench, step_time, frame_time) = (context.bench, context.step_time, context.frame_time);
    let plot_height = if bench.exact_step {
        PLOT_HEIGHT_OF_FOUR
    } else {
        PLOT_HEIGHT
    };
    let m = &bench.metrics;
    let taken = bench.simulation.state().taken;
    for warning in [
        &bench.stability_warning,
        &bench.newton_warning,
        &bench.slow_frame,
        &bench.energy_warning,
        &bench.penetration_warning,
    ]
    .into_iter()
    .flatten()
    {
        ui.colored_label(egui::Color32::from_rgb(230, 160, 40), warning);
    }
    egui::Grid::new("readouts").num_columns(2).show(ui, |ui| {
        for (label, value) in [
            (
                "frame",
                format!(
                    "{} (t = {:.2} s)",
                    bench.simulation.frame(),
                    bench.simulation.time()
                ),
            ),
            (
                "inverted tets",
                format!("{} of {}", m.inverted_tets, bench.simulation.tets().len()),
            ),
            ("min V/V0", format!("{:.4}", m.min_volume_ratio)),
            ("volume error", format!("{:.3e}", m.volume_error)),
            ("max edge strain", format!("{:.3e}", m.max_edge_strain)),
            (
                "energy",
                bench
                    .history
                    .back()
                    .map_or_else(String::new, |s| format!("{:.4e} J", s.energy[3])),
            ),
            (
                "kinetic, elastic",
                bench.history.back().map_or_else(String::new, |s| {
                    format!("{:.2e}, {:.2e} J", s.energy[0], s.energy[2])
                }),
            ),
            (
                "to ground, damping",
                format!("{:.2e}, {:.2e} J", taken.ground, taken.damping),
            ),
            (
                "settling an edit",
                if bench.simulation.is_settling() {
                    "yes".to_owned()
                } else {
                    "no".to_owned()
                },
            ),
            ("engine", bench.simulation.describe_engine()),
            (
                "step time",
                format!("{:.2} ms", step_time.as_secs_f64() * 1e3),
            ),
            (
                "frame time",
                if bench.playing {
                    format!(
                        "{:.1} ms, {:.0} fps",
                        frame_time.as_secs_f64() * 1e3,
                        1.0 / frame_time.as_secs_f64().max(1e-6)
                    )
                } else {
                    "paused".to_owned()
                },
            ),
        ] {
            ui.label(label);
            ui.monospace(value);
            ui.end_row();
        }
    });
    // How far XPBD's frame is from the exact one (tetlab_core::measures::exact_step): each frame
    // stepped again by the Newton reference from the same start, so off unless asked.
    ui.horizontal(|ui| {
        let mut on = bench.exact_step;
        let toggle = ui
            .checkbox(&mut on, "distance from the exact step")
            .on_hover_text(
                "Each frame is stepped again by the Newton reference from the same start (every \
             substep's implicit Euler step solved to 1e-10); the largest distance between the \
             two is XPBD's error in that frame. Slow beyond small scenes.",
            );
        if toggle.changed() {
            requests.push(Request::ExactStep(on));
        }
        if let Some(gap) = bench.history.back().and_then(|s| s.exact_step) {
            ui.monospace(format!("{gap:.2e} m"))
                .on_hover_text("the largest over the particles");
        }
    });
    let series = |name: &str, value: fn(&Sample) -> f64| {
        Line::new(
            name.to_owned(),
            PlotPoints::from_iter(bench.history.iter().map(|s| [s.time, value(s)])),
        )
    };
    Plot::new("inverted plot")
        .height(plot_height)
        .legend(Legend::default())
        .allow_scroll(false)
        .show(ui, |plot| {
            plot.line(series("inverted tets", |s| s.metrics.inverted_tets as f64));
        });
    Plot::new("volume plot")
        .height(plot_height)
        .legend(Legend::default())
        .allow_scroll(false)
        .show(ui, |plot| {
            plot.line(series("min V/V0", |s| s.metrics.min_volume_ratio));
            plot.line(series("volume error", |s| s.metrics.volume_error));
        });
    // The energy account: a total that rises, with what the ground and damping took added
    // back and beyond what a violated rigid family releases, is a gain
    // (tetlab_core::measures::energy_account).
    Plot::new("energy plot")
        .height(plot_height)
        // Four series: a small legend, in their order, so that it leaves the plot visible.
        .legend(
            Legend::default()
                .text_style(egui::TextStyle::Small)
                .follow_insertion_order(true),
        )
        .allow_scroll(false)
        .show(ui, |plot| {
            plot.line(series("total energy, J", |s| s.energy[3]));
            plot.line(series("total + taken", |s| s.energy[4]));
            plot.line(series("kinetic", |s| s.energy[0]));
            plot.line(series("elastic", |s| s.energy[2]));
        });
    if bench.exact_step {
        Plot::new("exact step plot")
            .height(plot_height)
            .legend(Legend::default())
            .allow_scroll(false)
            .show(ui, |plot| {
                let gaps = bench
                    .history
                    .iter()
                    .filter_map(|s| s.exact_step.map(|gap| [s.time, gap]));
                plot.line(Line::new(
                    "distance from the exact step, m".to_owned(),
                    PlotPoints::from_iter(gaps),
                ));
            });
    }
}
