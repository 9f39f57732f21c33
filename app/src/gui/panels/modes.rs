//! The modes window: for the selected tet, the energy of the active families on it (E = Σ ½ C²/α,
//! [`tetlab_core::energy`]), the twelve eigenvalues of its Hessian as a bar chart coloured by
//! sign, each mode's class and frequency, and one mode picked, which the view draws: arrows of the
//! eigenvector at the corners and the tet moved along it, still or animated. Only drawn: the
//! simulation is untouched. It follows the tet as it is dragged.

use super::{Context, Panel};
use crate::gui::request::Request;
use crate::gui::workbench::{ModeShown, Workbench};
use eframe::egui;
use egui_plot::{Bar, BarChart, Legend, Plot};
use glam::DVec3;
use tetlab_core::energy::element::{Compliance, ElementEnergy};
use tetlab_core::energy::hessian::{asymmetry, coordinates, energy};
use tetlab_core::energy::modes::{Modes, ZERO};
use tetlab_core::teaching::visual::{self, Rgba};

/// How long one swing of an animated mode takes, in seconds.
const PERIOD: f64 = 1.6;

/// The modes window and what is picked in it.
#[derive(Clone, Debug, PartialEq)]
pub struct ModesPanel {
    /// Whether it is shown.
    pub open: bool,
    /// The mode drawn in the view, by its place lowest first (it keeps its place as the tet
    /// moves: the lowest stays the lowest).
    pub picked: Option<usize>,
    /// Whether the tet swings along the mode, or stands moved by the amplitude.
    pub animate: bool,
    /// How far the tet is moved along the mode, in tet sizes.
    pub amplitude: f64,
    /// Whether the chart also shows the projected eigenvalues, max(λ, 0).
    pub projected: bool,
    /// The eigenvector last drawn: the next is turned to point the same way (an eigenvector's
    /// sign is arbitrary, and would flip from frame to frame as the tet is dragged).
    last_vector: Option<[DVec3; 4]>,
}

impl Default for ModesPanel {
    fn default() -> Self {
        ModesPanel {
            open: false,
            picked: None,
            animate: true,
            amplitude: 0.3,
            projected: false,
            last_vector: None,
        }
    }
}

impl Panel for ModesPanel {
    fn ui(&mut self, ui: &mut egui::Ui, context: &Context<'_>, requests: &mut Vec<Request>) {
        let mut open = self.open;
        let mut shown = None;
        egui::Window::new("Modes")
            .open(&mut open)
            // Over the readouts, beside the view: the tet and its mode stay in sight.
            .default_pos([900.0, 30.0])
            .default_width(370.0)
            .vscroll(true)
            .show(ui.ctx(), |ui| shown = self.contents(ui, context.bench));
        self.open = open;
        if shown.is_none() {
            self.last_vector = None;
        }
        if shown != context.bench.mode_shown {
            requests.push(Request::ShowMode(shown));
        }
    }
}

/// Negative eigenvalues: red, as inverted tets.
const NEGATIVE: Rgba = visual::INVERTED;
/// Zero eigenvalues: grey.
const ZERO_COLOUR: Rgba = [150, 150, 150, 255];
/// Positive eigenvalues: the mode colour.
const POSITIVE: Rgba = visual::MODE;

fn colour(rgba: Rgba) -> egui::Color32 {
    egui::Color32::from_rgba_unmultiplied(rgba[0], rgba[1], rgba[2], rgba[3])
}

impl ModesPanel {
    /// The window's contents; the mode to draw, if one is picked.
    pub fn contents(&mut self, ui: &mut egui::Ui, bench: &Workbench) -> Option<ModeShown> {
        let Some(tet) = bench.selected_tet else {
            ui.label("Select a tet (click a particle) to see the modes of its energy.");
            return None;
        };
        let simulation = &bench.simulation;
        let (element, x) = match ElementEnergy::of_tet(simulation, tet) {
            Ok(found) => found,
            Err(why) => {
                ui.label(why);
                return None;
            }
        };
        let modes = Modes::of(&element, &x);
        let families = simulation.families();
        ui.heading(format!(
            "Tet {tet}: E = {:.4e}",
            energy(&element, &coordinates(&x))
        ));
        for &(family, compliance) in &element.compliances {
            let name = families.name(family);
            ui.label(match compliance {
                Compliance::Given(alpha) => format!("{name}: ½ C²/α with α = {alpha:.3e}"),
                Compliance::Rigid => format!(
                    "{name}: rigid (α = 0), taken with α = 1: compare its eigenvalues' signs \
                     and shapes, not their sizes"
                ),
            });
        }
        ui.label(format!(
            "{} zero and {} negative of 12 (zero: |λ| ≤ {ZERO:.0e} × max |λ| = {:.3e}); \
             Hessian symmetric to {:.1e}",
            modes.zero_count(),
            modes.negative_count(),
            modes.largest(),
            asymmetry(&modes.hessian),
        ));
        self.chart(ui, &modes);
        ui.horizontal(|ui| {
            ui.checkbox(&mut self.projected, "projected, max(λ, 0)")
                .on_hover_text(
                    "What projected Newton uses: the same eigenvectors, the 12 × 12 eigenvalues \
                     clamped at zero (not the F-space clamp of `tetlab modes`)",
                );
            ui.checkbox(&mut self.animate, "animate");
            ui.add(
                egui::Slider::new(&mut self.amplitude, 0.05..=1.0).text("amplitude (tet sizes)"),
            );
        });
        self.list(ui, &modes);
        ui.small(format!(
            "Mass-weighted: H v = ω² M v with the tet's lumped mass, m = {:.3e} kg at each \
             corner, so the modes are H's and ω² = λ / m. A negative λ does not oscillate: it \
             grows.",
            modes.mass
        ));
        let k = self.picked.filter(|&k| k < modes.modes().len())?;
        let mut vector = modes.modes()[k].vector;
        if let Some(last) = self.last_vector {
            let along: f64 = (0..4).map(|c| last[c].dot(vector[c])).sum();
            if along < 0.0 {
                vector = vector.map(|v| -v);
            }
        }
        self.last_vector = Some(vector);
        let swing = if self.animate {
            ui.ctx().request_repaint();
            let time = ui.input(|i| i.time);
            (std::f64::consts::TAU * time / PERIOD).sin()
        } else {
            1.0
        };
        Some(ModeShown {
            tet,
            vector,
            offset: self.amplitude * swing,
        })
    }

    /// The eigenvalues as bars, lowest first, each divided by the largest |λ| (they span many
    /// orders of magnitude; the list gives each), coloured by sign.
    fn chart(&self, ui: &mut egui::Ui, modes: &Modes) {
        let largest = modes.largest().max(f64::MIN_POSITIVE);
        // Side by side when the projected ones are shown too.
        let shift = if self.projected { 0.2 } else { 0.0 };
        let bar = |at: f64, k: usize, value: f64, zero: bool| {
            let fill = match (zero, value < 0.0) {
                (true, _) => ZERO_COLOUR,
                (false, true) => NEGATIVE,
                (false, false) => POSITIVE,
            };
            Bar::new(at, value / largest)
                .width(0.4)
                .fill(colour(fill))
                .name(format!("mode {k}: λ = {value:.4e}"))
        };
        let raw: Vec<Bar> = (0..modes.modes().len())
            .map(|k| {
                bar(
                    k as f64 - shift,
                    k,
                    modes.modes()[k].value,
                    modes.is_zero(k),
                )
            })
            .collect();
        let projected: Vec<Bar> = modes
            .projected_values()
            .into_iter()
            .enumerate()
            .map(|(k, v)| bar(k as f64 + shift, k, v, modes.is_zero(k) || v == 0.0))
            .collect();
        let picked = self.picked;
        Plot::new("mode eigenvalues")
            .height(150.0)
            .legend(Legend::default())
            .allow_drag(false)
            .allow_zoom(false)
            .allow_scroll(false)
            .include_y(-1.0)
            .include_y(1.0)
            .x_axis_label("mode, lowest first")
            .y_axis_label("λ / max |λ|")
            .show(ui, |plot| {
                plot.bar_chart(BarChart::new("λ", raw).element_formatter(Box::new(
                    move |bar: &Bar, _: &BarChart| {
                        let k = bar.argument.round() as usize;
                        let mark = if picked == Some(k) { " (picked)" } else { "" };
                        format!("{}{mark}", bar.name)
                    },
                )));
                if self.projected {
                    plot.bar_chart(BarChart::new("max(λ, 0)", projected));
                }
            });
    }

    /// One line per mode: pick it, its λ, ω and class (its shares of every class when hovered).
    fn list(&mut self, ui: &mut egui::Ui, modes: &Modes) {
        egui::Grid::new("modes list").striped(true).show(ui, |ui| {
            for header in ["mode", "λ", "ω (1/s)", "class"] {
                ui.label(egui::RichText::new(header).strong());
            }
            ui.end_row();
            if ui.radio(self.picked.is_none(), "none").clicked() {
                self.picked = None;
            }
            ui.end_row();
            for (k, mode) in modes.modes().iter().enumerate() {
                if ui.radio(self.picked == Some(k), format!("#{k}")).clicked() {
                    self.picked = Some(k);
                }
                let text = egui::RichText::new(format!("{:+.4e}", mode.value)).monospace();
                ui.label(match (modes.is_zero(k), mode.value < 0.0) {
                    (true, _) => text.color(colour(ZERO_COLOUR)),
                    (false, true) => text.color(colour(NEGATIVE)),
                    (false, false) => text,
                });
                let omega_squared = modes.omega_squared(k);
                ui.monospace(if modes.is_zero(k) {
                    "0".to_owned()
                } else if omega_squared < 0.0 {
                    format!("grows, {:.3e}", (-omega_squared).sqrt())
                } else {
                    format!("{:.3e}", omega_squared.sqrt())
                });
                let shares: Vec<String> = (mode.shares.iter())
                    .zip(tetlab_core::energy::modes::Class::ALL)
                    .map(|(share, class)| format!("{}: {share:.2}", class.name()))
                    .collect();
                ui.monospace(mode.class.name())
                    .on_hover_text(format!("shares of the mode: {}", shares.join(", ")));
                ui.end_row();
            }
        });
    }
}
