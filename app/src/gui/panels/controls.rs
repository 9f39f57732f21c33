//! Playback, step-by-step mode and the scene.

use super::{Context, Panel};
use crate::gui::request::{Request, SceneRequest};
use crate::gui::shortcuts::Action;
use crate::gui::workbench::Workbench;
use eframe::egui;
use tetlab_core::scene::{Builtin, ShippedScene};
use tetlab_core::teaching::stepper::{Advanced, Next};

/// The largest resolution the scene panel offers (a cube of 196 608 tets).
const MAX_RESOLUTION: u32 = 32;

/// What the scene section edits between frames.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct SceneChoice {
    /// The built-in scene's name.
    pub builtin: String,
    /// Its resolution.
    pub resolution: u32,
    /// The path typed in the "mesh file" field.
    pub path: String,
    /// The shipped scene file chosen (`stacked-cubes.toml`, [`ShippedScene`]).
    pub shipped: String,
}

impl Default for SceneChoice {
    fn default() -> Self {
        Self {
            builtin: "cube".into(),
            resolution: 3,
            path: String::new(),
            shipped: "stacked-cubes.toml".into(),
        }
    }
}

/// The playback and scene panel; it owns the scene section's choices.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Controls {
    /// The built-in scene, its resolution and the typed mesh path.
    pub scene: SceneChoice,
}

/// The step-by-step buttons and where the substep stands.
fn step_by_step(ui: &mut egui::Ui, bench: &Workbench, requests: &mut Vec<Request>) {
    ui.horizontal(|ui| {
        if ui
            .button("Next projection")
            .on_hover_text("J: one constraint at a time")
            .clicked()
        {
            requests.push(Request::Act(Action::StepProjection));
        }
        if ui
            .add_enabled(
                bench.stepping.is_some(),
                egui::Button::new("Finish substep"),
            )
            .on_hover_text("K")
            .clicked()
        {
            requests.push(Request::Act(Action::FinishSubstep));
        }
    });
    let Some(stepper) = bench.stepping else {
        return;
    };
    let simulation = &bench.simulation;
    let (done, total) = stepper.progress(simulation);
    let status = match (stepper.next(simulation), stepper.iteration(simulation)) {
        (Next::BeginSubstep, _) => {
            "next: begin a substep (predict x from v and gravity)".to_owned()
        }
        (Next::Project(family, c), Some((i, n))) => format!(
            "sweep {}/{n}, {}/{total}: next projects {} #{c}",
            i + 1,
            done + 1,
            simulation.families().name(family)
        ),
        (Next::EndSweep { last }, Some((i, n))) => format!(
            "sweep {}/{n} done: next {}",
            i + 1,
            if last {
                "ground, then velocities v = (x - x_prev)/h"
            } else {
                "ground, then the next sweep"
            }
        ),
        (_, None) => String::new(),
    };
    let last = match bench.last_advance {
        Some(Advanced::BeganSubstep) => "last: predicted x += v h (gravity)".to_owned(),
        Some(Advanced::Projected(p)) => format!(
            "last: projected {} #{}, C was {:+.3e}",
            simulation.families().name(p.family),
            p.constraint,
            p.value
        ),
        Some(Advanced::EndedSweep { ended_substep }) => {
            if ended_substep {
                "last: ground and velocities; substep done".to_owned()
            } else {
                "last: ground; sweep done".to_owned()
            }
        }
        None => String::new(),
    };
    ui.label(egui::RichText::new(status).monospace());
    if !last.is_empty() {
        ui.label(egui::RichText::new(last).monospace());
    }
}

impl Panel for Controls {
    fn ui(&mut self, ui: &mut egui::Ui, context: &Context<'_>, requests: &mut Vec<Request>) {
        let bench = context.bench;
        let choice = &mut self.scene;
        ui.heading("Playback");
        ui.horizontal(|ui| {
            let label = if bench.playing { "Pause" } else { "Play" };
            for (label, key, action) in [
                (label, "Space", Action::PlayPause),
                ("Step frame", "N", Action::StepFrame),
                ("Step substep", "U", Action::StepSubstep),
            ] {
                if ui.button(label).on_hover_text(key).clicked() {
                    requests.push(Request::Act(action));
                }
            }
        });
        step_by_step(ui, bench, requests);

        ui.separator();
        ui.heading("Scene");
        ui.horizontal(|ui| {
            egui::ComboBox::from_label("built-in")
                .selected_text(choice.builtin.clone())
                .show_ui(ui, |ui| {
                    for builtin in Builtin::ALL {
                        ui.selectable_value(
                            &mut choice.builtin,
                            builtin.name().to_owned(),
                            builtin.name(),
                        );
                    }
                });
        });
        // Up to a 196 608-tet cube: big meshes are drawn as a body and run on the fast engine.
        ui.add(
            egui::Slider::new(&mut choice.resolution, 1..=MAX_RESOLUTION)
                .logarithmic(true)
                .text("resolution"),
        )
        .on_hover_text("cells along a side: a cube of resolution n has 6n³ tets (15: 20 250)");
        ui.horizontal(|ui| {
            let builtin = Builtin::from_name(&choice.builtin).unwrap_or(Builtin::Cube);
            if ui.button("Load built-in scene").clicked() {
                requests.push(Request::Scene(SceneRequest::Builtin(
                    builtin,
                    choice.resolution,
                )));
            }
            if ui
                .button("Add a body")
                .on_hover_text("adds the built-in above to the scene shown, dropped onto it")
                .clicked()
            {
                requests.push(Request::Scene(SceneRequest::AddBody(
                    builtin,
                    choice.resolution,
                )));
            }
        });
        // The scene files that come with tetlab, several bodies each, on the desktop and in a
        // page alike (those of the reference meshes need ../shared/meshes beside tetlab).
        ui.horizontal(|ui| {
            egui::ComboBox::from_label("scene file")
                .selected_text(choice.shipped.clone())
                .show_ui(ui, |ui| {
                    for file in ShippedScene::names() {
                        ui.selectable_value(&mut choice.shipped, file.to_owned(), file);
                    }
                });
            let clicked = ui.button("Load").clicked();
            if let Some(shipped) = ShippedScene::named(&choice.shipped).filter(|_| clicked) {
                requests.push(Request::Scene(SceneRequest::Shipped(shipped.file)));
            }
        });
        if cfg!(target_arch = "wasm32") {
            // A page cannot open files by path: meshes and lessons are dropped on it.
            ui.label("drop a .msh mesh, a lesson or a constraint .toml on the page to open it");
        } else {
            ui.horizontal(|ui| {
                ui.add(
                    egui::TextEdit::singleline(&mut choice.path)
                        .hint_text(".msh, .node or .ele path")
                        .desired_width(170.0),
                )
                .labelled_by(ui.label("mesh file").id);
                if ui
                    .add_enabled(!choice.path.trim().is_empty(), egui::Button::new("Open"))
                    .clicked()
                {
                    let path = choice.path.trim().to_owned();
                    requests.push(Request::Scene(SceneRequest::File(path)));
                }
            });
        }
        if !cfg!(target_arch = "wasm32")
            && ui
                .button("Open mesh file...")
                .on_hover_text("O: browse for a .node, .ele, .msh, lesson or constraint file")
                .clicked()
        {
            requests.push(Request::Act(Action::OpenFile));
        }
        ui.label(format!(
            "{}: {} particles, {} tets",
            bench.scene.name,
            bench.simulation.positions().len(),
            bench.simulation.tets().len()
        ));
        for note in &bench.scene.notes {
            ui.small(note);
        }
    }
}
