//! The inspector: for the selected tet (and, in step-by-step mode, for the constraint about to be
//! projected) every active constraint's numbers as the solver sees them, its gradient checked
//! against central differences, and its formula.

use super::{Context, Panel};
use crate::gui::request::Request;
use crate::gui::workbench::Workbench;
use eframe::egui;
use glam::DVec3;
use tetlab_core::constraints::{Binding, Formula};
use tetlab_core::simulation::{Method, Simulation};
use tetlab_core::teaching::inspector::{Inspection, inspect, inspect_tet, state_lines};

/// The inspector window.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Inspector {
    /// Whether it is shown.
    pub open: bool,
}

impl Panel for Inspector {
    fn ui(&mut self, ui: &mut egui::Ui, context: &Context<'_>, _: &mut Vec<Request>) {
        show(ui.ctx(), &mut self.open, context.bench);
    }
}

/// Shows the inspector as a window while `open` is true.
fn show(ctx: &egui::Context, open: &mut bool, bench: &Workbench) {
    egui::Window::new("Inspector")
        .open(open)
        .default_pos([320.0, 60.0])
        .default_width(560.0)
        .vscroll(true)
        .show(ctx, |ui| contents(ui, bench));
}

/// The inspector's contents, for any container.
pub fn contents(ui: &mut egui::Ui, bench: &Workbench) {
    let simulation = &bench.simulation;
    let method = simulation.settings().method;
    if let Some(projection) = bench.stepping.and_then(|s| s.pending(simulation)) {
        ui.heading("Next projection");
        let inspection = inspect(simulation, projection.family, projection.constraint);
        formula(ui, &simulation.families().row(projection.family).formula);
        // One id for whichever constraint is next, so the table keeps its column widths.
        constraint(ui, simulation, &inspection, method, "next projection");
        ui.separator();
    }
    contacts(ui, bench);
    let Some(tet) = bench.selected_tet else {
        ui.label("Select a tet (click a particle) to inspect its constraints.");
        return;
    };
    ui.heading(format!("Tet {tet}: particles {:?}", simulation.tets()[tet]));
    let mut inspections = Vec::new();
    inspect_tet(simulation, tet, &mut inspections);
    if inspections.is_empty() {
        ui.label("No constraint family is active.");
    }
    let families = simulation.families();
    for family in families.all() {
        let of_family: Vec<&Inspection> = inspections
            .iter()
            .filter(|i| i.projection.family == family)
            .collect();
        if of_family.is_empty() {
            continue;
        }
        let row = families.row(family);
        egui::CollapsingHeader::new(format!("{} ({})", row.title, of_family.len()))
            .id_salt(families.name(family))
            // Open where the tet has one constraint of the family (volume, neo-Hookean).
            .default_open(of_family.len() == 1)
            .show(ui, |ui| {
                formula(ui, &row.formula);
                for inspection in of_family {
                    ui.separator();
                    let p = &inspection.projection;
                    let id = (families.name(p.family), p.constraint);
                    constraint(ui, simulation, inspection, method, id);
                }
            });
    }
}

/// The contacts of the selected particle, each family that binds to contacts on each pair:
/// the pair's numbers as the contact pass sees them (its ∇C is drawn in the view).
fn contacts(ui: &mut egui::Ui, bench: &Workbench) {
    let simulation = &bench.simulation;
    let Some(particle) = bench.selected_particle else {
        return;
    };
    let families = simulation.families();
    let contact: Vec<_> =
        tetlab_core::simulation::contact::contact_families(families, simulation.active()).collect();
    if contact.is_empty() {
        return;
    }
    let pairs = simulation.contacts_of(particle);
    let method = simulation.settings().method;
    egui::CollapsingHeader::new(format!("Contacts of particle {particle} ({})", pairs.len()))
        .id_salt("contacts of the selected particle")
        .default_open(true)
        .show(ui, |ui| {
            if pairs.is_empty() {
                ui.label(
                    "None this frame: the broad phase found no triangle this particle may reach \
                 within the frame.",
                );
                return;
            }
            for &family in &contact {
                formula(ui, &families.row(family).formula);
                for &c in pairs.iter().take(MAX_CONTACTS_SHOWN) {
                    ui.separator();
                    let inspection = inspect(simulation, family, c);
                    constraint(ui, simulation, &inspection, method, ("contact", family, c));
                }
            }
            if pairs.len() > MAX_CONTACTS_SHOWN {
                ui.label(format!(
                    "and {} more, farther or not over their triangles",
                    pairs.len() - MAX_CONTACTS_SHOWN
                ));
            }
        });
    ui.separator();
}

/// How many of the selected particle's contact pairs the inspector lists.
const MAX_CONTACTS_SHOWN: usize = 4;

/// The family's constraint and gradients, one line of math each.
fn formula(ui: &mut egui::Ui, formula: &Formula) {
    egui::Frame::group(ui.style()).show(ui, |ui| {
        for line in formula.lines() {
            ui.label(egui::RichText::new(line).monospace().size(14.0));
        }
    });
}

/// One constraint's numbers: C, rest value, λ and the next Δλ; per particle w, ∇C and its
/// central-difference check.
fn constraint(
    ui: &mut egui::Ui,
    simulation: &Simulation,
    inspection: &Inspection,
    method: Method,
    id: impl std::hash::Hash + std::fmt::Debug,
) {
    let p = &inspection.projection;
    let families = simulation.families();
    let rest_name = families.row(p.family).rest_symbol;
    let step = match (p.delta_lambda, method) {
        (Some(d), Method::Xpbd) => format!("next Δλ = {d:+.4e}"),
        (Some(d), Method::Pbd) => format!("next k′s = {d:+.4e}"),
        (None, _) if p.degenerate => "skipped: ∇C undefined (degenerate)".to_owned(),
        (None, _) if families.binding(p.family) == Binding::Contacts => {
            "not projected now (see below)".to_owned()
        }
        (None, _) => "skipped: every particle fixed".to_owned(),
    };
    ui.label(
        egui::RichText::new(format!(
            "{} #{}   C = {:+.4e}   {rest_name} = {:+.4e}   λ = {:+.4e}   {step}",
            families.name(p.family),
            p.constraint,
            p.value,
            p.rest,
            p.lambda,
        ))
        .monospace(),
    );
    for line in state_lines(simulation, p) {
        ui.monospace(line);
    }
    egui::Grid::new(("inspection", id))
        .striped(true)
        .show(ui, |ui| {
            let file = inspection.file_gradients;
            let gradient_headers: &[&str] = match file {
                Some(_) => &["∇C by AD", "∇C yours"],
                None => &["∇C"],
            };
            let headers = ["", "particle", "w"]
                .iter()
                .chain(gradient_headers)
                .chain(&["∇C by finite differences", "Δx if projected now"]);
            for header in headers {
                ui.label(egui::RichText::new(*header).strong());
            }
            ui.end_row();
            for k in 0..p.len {
                ui.monospace(format!("p{}", subscript(k)));
                ui.monospace(p.particles[k].to_string());
                ui.monospace(format!("{:.3e}", p.inverse_masses[k]));
                match file {
                    Some(file) => {
                        ui.monospace(vector(file.automatic[k]));
                        match file.yours[k] {
                            Some(yours) => {
                                let scale = file.automatic[..p.len]
                                    .iter()
                                    .map(|g| g.length())
                                    .fold(0.0, f64::max);
                                let differs = (yours - file.automatic[k]).length()
                                    > tetlab_core::teaching::visual::DISAGREEMENT * scale;
                                let text = egui::RichText::new(vector(yours)).monospace();
                                ui.label(if differs {
                                    text.color(egui::Color32::from_rgb(220, 60, 60))
                                } else {
                                    text
                                });
                            }
                            None => {
                                ui.monospace("not given");
                            }
                        }
                    }
                    None => {
                        ui.monospace(vector(p.gradients[k]));
                    }
                }
                ui.monospace(vector(inspection.numeric_gradients[k]));
                ui.monospace(vector(p.delta_x[k]));
                ui.end_row();
            }
        });
    if let Some(file) = families.file(p.family) {
        let used = if file.use_gradient {
            "the solver projects with your gradient (use_gradient = true)"
        } else {
            "the solver projects with AD's gradient"
        };
        ui.label(format!("{used}; yours in red where it differs from AD's"));
    }
    ui.monospace(format!(
        "Σ|∇C|² = {:.4e}   Σ w|∇C|² = {:.4e}   finite-difference relative error {:.1e}",
        inspection.gradient_norm_squared(),
        p.weighted_norm,
        inspection.relative_error
    ));
}

fn subscript(k: usize) -> char {
    ['₀', '₁', '₂', '₃'][k.min(3)]
}

fn vector(v: DVec3) -> String {
    format!("({:+.4}, {:+.4}, {:+.4})", v.x, v.y, v.z)
}
