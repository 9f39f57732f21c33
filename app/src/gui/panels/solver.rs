//! The solver settings: method, families with their compliance or stiffness, substeps and the
//! rest. The panel edits a copy; the app applies a change to every simulation shown.

use super::{Context, Panel};
use crate::gui::request::Request;
use crate::gui::shortcuts::Action;
use eframe::egui;
use tetlab_core::constraints::material::{MAX_POISSON, YOUNG};
use tetlab_core::constraints::{Families, PerFamily};
use tetlab_core::simulation::{EngineChoice, Method, Settings};

/// The solver panel: it edits a copy of the simulation's settings and asks for the copy when
/// the user changed it. "Write a constraint" asks for the constraint editor, whose family joins
/// the list.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SolverPanel;

impl Panel for SolverPanel {
    fn ui(&mut self, ui: &mut egui::Ui, context: &Context<'_>, requests: &mut Vec<Request>) {
        let current = context.bench.simulation.settings();
        ui.horizontal(|ui| {
            ui.heading("Solver");
            if ui
                .button("Write a constraint (G)")
                .on_hover_text("The constraint editor: C as an expression, checked and simulated")
                .clicked()
            {
                requests.push(Request::Act(Action::ConstraintEditor));
            }
        });
        if let Some(settings) = edit(ui, context.bench.simulation.families(), current) {
            requests.push(Request::Settings(Box::new(settings)));
        }
        // What a scene file gave a body of its own, which the settings above do not change.
        for body in context.bench.simulation.bodies() {
            if let Some(made_of) = body.made_of() {
                ui.label(format!("body {}: {made_of}", body.name))
                    .on_hover_text(
                        "Its own, from the scene file: the material above is the other bodies'; a \
                     family runs on it where it is listed there and switched on here",
                    );
            }
        }
    }
}

/// The settings' widgets, on a copy of `current`; the copy when the user changed it.
fn edit(ui: &mut egui::Ui, families: &Families, current: &Settings) -> Option<Settings> {
    let mut settings = *current;
    ui.horizontal(|ui| {
        ui.radio_value(&mut settings.method, Method::Xpbd, "XPBD");
        ui.radio_value(&mut settings.method, Method::Pbd, "PBD");
    });
    let contact = tetlab_core::simulation::contact::contact_families(families, &current.active)
        .next()
        .is_some();
    // Wrapped: five choices are wider than the panel.
    ui.horizontal_wrapped(|ui| {
        ui.label("engine");
        for engine in EngineChoice::ALL {
            // The Newton reference solves a substep without contact; the GPU engine needs an
            // adapter (the first ask for one waits for it, once).
            let without = contact && engine == EngineChoice::Newton;
            let why = match engine.available() {
                Err(why) => format!("No GPU engine here: {why}"),
                Ok(()) if without => "The Newton reference solves a substep without contact: \
                                      switch contact off to use it"
                    .to_owned(),
                Ok(()) => String::new(),
            };
            let radio = egui::RadioButton::new(settings.engine == engine, engine.name());
            let response = ui
                .add_enabled(why.is_empty(), radio)
                .on_hover_text(engine.summary())
                .on_disabled_hover_text(why);
            if response.clicked() {
                settings.engine = engine;
            }
        }
    });
    if contact && settings.engine == EngineChoice::Newton {
        settings.engine = EngineChoice::Auto;
    }
    for (group, members) in families.groups() {
        let family = members.families().next().expect("a group has a family");
        // The material gives the compliance of the neo-Hookean pair and of a file's constraints
        // with a `stiffness`.
        if families.row(family).compliance_from_material.is_some() {
            material_group(ui, families, &mut settings, group, members);
            continue;
        }
        // A file of several constraints is one group: switched and set together.
        let label = if members.families().count() > 1 {
            group
        } else {
            &*families.row(family).label
        };
        ui.horizontal(|ui| {
            let mut on = members.families().all(|f| settings.active[f]);
            if ui.checkbox(&mut on, label).changed() {
                for f in members.families() {
                    settings.active[f] = on;
                }
            }
            let (mut compliance, mut stiffness) =
                (settings.compliance[family], settings.stiffness[family]);
            match settings.method {
                Method::Xpbd => {
                    ui.add(
                        egui::DragValue::new(&mut compliance)
                            .range(0.0..=10.0)
                            .speed(1e-4)
                            .prefix("alpha "),
                    )
                    .on_hover_text("XPBD compliance: 0 is rigid, larger is softer");
                }
                Method::Pbd => {
                    ui.add(egui::Slider::new(&mut stiffness, 0.0..=1.0).text("k"));
                }
            }
            let changed = (
                compliance != settings.compliance[family],
                stiffness != settings.stiffness[family],
            );
            for f in members.families() {
                if changed.0 {
                    settings.compliance[f] = compliance;
                }
                if changed.1 {
                    settings.stiffness[f] = stiffness;
                }
            }
        });
    }
    let active = settings.active;
    if tetlab_core::simulation::contact::contact_families(families, &active)
        .next()
        .is_some()
    {
        contact_row(ui, &mut settings.contact);
    }
    ui.add(
        egui::Slider::new(&mut settings.substeps, 1..=400)
            .logarithmic(true)
            .text("substeps"),
    )
    .on_hover_text("Rigid constraints converge as the substeps get shorter");
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

/// Contact's thickness and friction, under the families when a family on contacts is active.
fn contact_row(ui: &mut egui::Ui, contact: &mut tetlab_core::simulation::contact::ContactSettings) {
    use tetlab_core::input::limits::{FRICTION, THICKNESS};
    ui.horizontal(|ui| {
        ui.add(
            egui::DragValue::new(&mut contact.thickness)
                .range(THICKNESS.min..=THICKNESS.max)
                .speed(1e-3)
                .prefix("d ")
                .suffix(" m"),
        )
        .on_hover_text(
            "Contact's thickness: the least height it keeps a particle above a triangle",
        );
        for (value, name, what) in [
            (
                &mut contact.static_friction,
                "mu_s ",
                "Static friction: sticks while the slide is under mu_s times the push",
            ),
            (
                &mut contact.kinetic_friction,
                "mu_k ",
                "Kinetic friction: a slide is slowed by mu_k times the push",
            ),
        ] {
            ui.add(
                egui::DragValue::new(value)
                    .range(FRICTION.min..=FRICTION.max)
                    .speed(0.01)
                    .prefix(name),
            )
            .on_hover_text(what);
        }
    });
}

/// The families a material describes (the neo-Hookean pair): on or off together, with the
/// material's E and ν (which give their compliances, under XPBD and PBD alike).
fn material_group(
    ui: &mut egui::Ui,
    families: &Families,
    settings: &mut Settings,
    group: &str,
    members: PerFamily<bool>,
) {
    let mut on = members.families().all(|f| settings.active[f]);
    let mut material = settings.material;
    let speed = material.young * 0.01;
    ui.horizontal(|ui| {
        if ui.checkbox(&mut on, group_label(families, group)).changed() {
            for family in members.families() {
                settings.active[family] = on;
            }
        }
        ui.add(
            egui::DragValue::new(&mut material.young)
                .range(YOUNG.min..=YOUNG.max)
                .speed(speed)
                .custom_formatter(|e, _| format!("{e:.2e}"))
                .prefix("E ")
                .suffix(" Pa"),
        )
        .on_hover_text("Young's modulus: a larger E is stiffer");
        ui.add(
            egui::DragValue::new(&mut material.poisson)
                .range(0.0..=MAX_POISSON)
                .speed(0.005)
                .max_decimals(3)
                .prefix("nu "),
        )
        .on_hover_text("Poisson's ratio: towards 0.5 the volume barely changes");
    });
    if material != settings.material && material.check().is_ok() {
        settings.material = material;
    }
}

/// "neo-Hookean" for `neohookean`: the table's label of a group's first family, up to its
/// first space.
pub fn group_label<'a>(families: &'a Families, group: &str) -> &'a str {
    let family = families
        .all()
        .find(|&f| families.row(f).group == group)
        .expect("a group of the table");
    let row = families.row(family);
    if families.file(family).is_some() {
        // A file's group is named by the file's `name`.
        return &row.group;
    }
    let label: &str = &row.label;
    label.split(' ').next().unwrap_or(label)
}
