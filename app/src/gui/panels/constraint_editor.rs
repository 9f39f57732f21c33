//! The constraint editor: a constraint file typed (or opened, or dropped) in a panel beside the
//! 3D view, compiled as you type. While the text compiles, its family is defined in the table and simulated, drawn
//! and inspected like the built-in ones, and its arrows follow every keystroke; while it does
//! not, the mistake is shown at its line and column, and the last good definition stays.
//! "Check my gradient" runs the check of `tetlab check-gradients --constraint-file` on it.

use super::{Context, Panel};
use crate::gui::request::Request;
use eframe::egui;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use tetlab_core::constraint_file::check::{self, Report};
use tetlab_core::constraint_file::{ConstraintFile, EXAMPLES};
use tetlab_core::constraints::{Families, Family};

/// The name the editor's text has in errors until it comes from a file.
pub const UNSAVED: &str = "editor.toml";

/// Configurations "Check my gradient" compares on.
pub const CHECK_CONFIGS: usize = 2000;

/// The editor's state.
pub struct ConstraintEditor {
    /// Whether the window is open.
    pub open: bool,
    /// The text being edited.
    pub text: String,
    /// What errors call the text: the file it came from, or [`UNSAVED`].
    pub path: PathBuf,
    /// The family the text defines now (the last text that compiled; of a file of several
    /// constraints, the first, which the check and the grade are of).
    pub family: Option<Family>,
    /// Every family the text defines now (one, or one per `[[constraint]]`).
    pub families: Vec<Family>,
    /// Why the text does not define a family now (`FILE:LINE:COLUMN: …`), if it does not.
    pub error: Option<String>,
    /// Where that mistake is, line and column from 1, to mark it.
    pub error_at: Option<(usize, usize)>,
    /// The last "Check my gradient", for the family it checked.
    pub report: Option<(Family, Arc<ConstraintFile>, Report)>,
}

impl Default for ConstraintEditor {
    fn default() -> Self {
        ConstraintEditor {
            open: false,
            text: String::new(),
            path: PathBuf::from(UNSAVED),
            family: None,
            families: Vec::new(),
            error: None,
            error_at: None,
            report: None,
        }
    }
}

impl ConstraintEditor {
    /// Puts `text`, from `path`, in the editor and compiles it: its constraints (one, or one
    /// per `[[constraint]]`), or `None` and the mistake.
    pub fn set_text(&mut self, path: &Path, text: &str) -> Option<Vec<ConstraintFile>> {
        self.text = text.to_owned();
        self.path = path.to_owned();
        self.compile()
    }

    /// Compiles the text: the file, or the mistake (kept in [`ConstraintEditor::error`]).
    pub fn compile(&mut self) -> Option<Vec<ConstraintFile>> {
        match ConstraintFile::parse_all(&self.path, &self.text) {
            Ok(files) => {
                self.error = None;
                self.error_at = None;
                Some(files)
            }
            Err(e) => {
                self.error_at = e.at;
                self.error = Some(e.to_string());
                None
            }
        }
    }

    /// Shows the editor in a panel below the 3D view (so that the arrows can be watched while
    /// typing) while it is open: the text on the left, what it defines and the gradient check on
    /// the right. Returns a newly compiled file when the text changed and compiles (the app
    /// defines its family).
    fn show(
        &mut self,
        ui: &mut egui::Ui,
        families: &Families,
        exercise: bool,
    ) -> Option<Vec<ConstraintFile>> {
        if !self.open {
            return None;
        }
        let mut compiled = None;
        egui::Panel::bottom("constraint editor")
            .resizable(true)
            .default_size(330.0)
            .min_size(160.0)
            .show(ui, |ui| {
                ui.horizontal(|ui| {
                    ui.heading("Constraint editor");
                    if ui.button("Close (G)").clicked() {
                        self.open = false;
                    }
                });
                compiled = self.contents(ui, families, exercise);
            });
        compiled
    }

    /// The editor's contents, for any container: the text on the left; what the text defines (or
    /// its mistake), the gradient check and the examples to start from on the right.
    /// `exercise`: the text's family is what the open lesson step asks the student to write or
    /// mend; its grade is shown with the status.
    pub fn contents(
        &mut self,
        ui: &mut egui::Ui,
        families: &Families,
        exercise: bool,
    ) -> Option<Vec<ConstraintFile>> {
        let mut compiled = None;
        let width = ui.available_width();
        let height = ui.available_height();
        ui.horizontal_top(|ui| {
            ui.vertical(|ui| {
                ui.set_width(0.6 * width);
                egui::ScrollArea::vertical()
                    .id_salt("constraint text")
                    .max_height(height)
                    .show(ui, |ui| compiled = self.text(ui));
            });
            ui.separator();
            ui.vertical(|ui| {
                egui::ScrollArea::vertical()
                    .id_salt("constraint status")
                    .max_height(height)
                    .show(ui, |ui| {
                        // What the text defines and its grade first, where they stay in view
                        // however many examples there are.
                        self.status(ui, families);
                        if let Some(family) = self.family.filter(|_| exercise) {
                            super::lesson::show_grade(ui, families, family, 14.0);
                        }
                        ui.separator();
                        if let Some(file) = self.examples(ui) {
                            compiled = Some(file);
                        }
                    });
            });
        });
        compiled
    }

    /// The examples of `assets/constraints` as buttons; the one pressed replaces the text.
    fn examples(&mut self, ui: &mut egui::Ui) -> Option<Vec<ConstraintFile>> {
        let mut compiled = None;
        ui.horizontal_wrapped(|ui| {
            ui.label("Start from:");
            for example in EXAMPLES {
                let name = example.file.trim_end_matches(".toml");
                if ui
                    .small_button(name)
                    .on_hover_text(example.shown().display().to_string())
                    .clicked()
                {
                    compiled = self.set_text(&example.shown(), example.text);
                }
            }
        });
        compiled
    }

    /// The text, its mistake's line marked; the file when an edit made it compile.
    fn text(&mut self, ui: &mut egui::Ui) -> Option<Vec<ConstraintFile>> {
        let label = ui
            .horizontal(|ui| {
                let label = ui.label("Constraint file");
                ui.label(
                    egui::RichText::new(format!("{}", self.path.display()))
                        .small()
                        .weak(),
                );
                label.id
            })
            .inner;
        let marked = self.error_at.map(|(line, _)| line);
        let mut layouter = |ui: &egui::Ui, text: &dyn egui::TextBuffer, wrap: f32| {
            let mut job = egui::text::LayoutJob::default();
            let font = egui::TextStyle::Monospace.resolve(ui.style());
            let colour = ui.visuals().text_color();
            for (k, line) in text.as_str().split_inclusive('\n').enumerate() {
                let mut format = egui::TextFormat::simple(font.clone(), colour);
                if marked == Some(k + 1) {
                    format.background = egui::Color32::from_rgba_unmultiplied(220, 60, 60, 70);
                }
                job.append(line, 0.0, format);
            }
            job.wrap.max_width = wrap;
            ui.fonts_mut(|fonts| fonts.layout_job(job))
        };
        let response = ui
            .add(
                egui::TextEdit::multiline(&mut self.text)
                    .code_editor()
                    .desired_rows(14)
                    .desired_width(f32::INFINITY)
                    .layouter(&mut layouter),
            )
            .labelled_by(label);
        if response.changed() {
            return self.compile();
        }
        None
    }

    /// What the text defines now, or its mistake; then the gradient check.
    fn status(&mut self, ui: &mut egui::Ui, families: &Families) {
        // A family of another table (a lesson opened since) is not this text's any more.
        self.families.retain(|&f| families.has(f));
        if self.family.is_some_and(|f| !families.has(f)) {
            self.family = None;
        }
        match (&self.error, self.family) {
            (Some(error), _) => {
                ui.colored_label(egui::Color32::from_rgb(220, 60, 60), error);
                if let Some(family) = self.family {
                    ui.label(format!(
                        "the view still shows the last text that compiled ({})",
                        families.name(family)
                    ));
                }
            }
            (None, Some(family)) => {
                let used = match families.file(family) {
                    Some(file) if file.use_gradient => "your gradient",
                    _ => "the gradient by automatic differentiation",
                };
                ui.label(format!(
                    "family {}: on in the solver panel, projected with {used}",
                    families.name(family)
                ));
            }
            (None, None) => {
                ui.label("Type a constraint, or start from an example.");
            }
        }
        if let Some(family) = self.family {
            self.check(ui, families, family);
        }
    }

    /// "Check my gradient" and what it found.
    fn check(&mut self, ui: &mut egui::Ui, families: &Families, family: Family) {
        let Some(file) = families.file(family) else {
            return;
        };
        let gives = (0..file.arity()).any(|k| file.gives_gradient(k));
        ui.separator();
        if ui
            .add_enabled(gives, egui::Button::new("Check my gradient"))
            .on_hover_text(format!(
                "against automatic differentiation on {CHECK_CONFIGS} random configurations, as \
                 tetlab check-gradients --constraint-file does"
            ))
            .on_disabled_hover_text("give [gradient] entries p0 = \"…\" to check them")
            .clicked()
        {
            let report = check::check(file, CHECK_CONFIGS, 1);
            self.report = Some((family, Arc::clone(file), report));
        }
        let Some((checked, definition, report)) = &self.report else {
            return;
        };
        if *checked != family || !Arc::ptr_eq(definition, file) {
            ui.label("(the text changed since the last check)");
            return;
        }
        for line in report_lines(report) {
            let (text, good) = line;
            let colour = if good {
                egui::Color32::from_rgb(40, 150, 60)
            } else {
                egui::Color32::from_rgb(220, 60, 60)
            };
            ui.colored_label(colour, text);
        }
    }
}

impl Panel for ConstraintEditor {
    /// Below the 3D view while it is open; a text that compiled is asked to be defined.
    fn ui(&mut self, ui: &mut egui::Ui, context: &Context<'_>, requests: &mut Vec<Request>) {
        let exercise = context.lesson.is_some_and(|state| {
            state
                .current()
                .exercises()
                .any(|family| Some(family) == self.family)
        });
        if let Some(files) = self.show(ui, context.bench.simulation.families(), exercise) {
            requests.push(Request::Constraint(files));
        }
    }
}

/// A gradient check as lines to show, each with whether it is good news.
pub fn report_lines(report: &Report) -> Vec<(String, bool)> {
    let mut lines = Vec::new();
    let agrees = report.agrees();
    lines.push((
        if agrees {
            format!(
                "your gradient agrees with AD on {} configurations",
                report.compared
            )
        } else {
            "your gradient does NOT agree with AD".to_owned()
        },
        agrees,
    ));
    for (k, error) in report.max_relative_error.iter().enumerate() {
        if let Some(error) = error {
            let good = *error <= check::AGREEMENT;
            lines.push((format!("p{k}: largest relative error {error:.1e}"), good));
        }
    }
    if let Some(worst) = report.worst.as_ref().filter(|_| !agrees) {
        let points: Vec<String> = worst
            .points
            .iter()
            .map(|p| format!("({:.3}, {:.3}, {:.3})", p.x, p.y, p.z))
            .collect();
        lines.push((
            format!(
                "worst at p{}: points {} (rest {:.3})",
                worst.particle,
                points.join(" "),
                worst.rest
            ),
            false,
        ));
    }
    lines.push((
        format!(
            "translation invariant (sum of grad C = 0): {}",
            yes(report.translation_invariant())
        ),
        true,
    ));
    // About its own place, one particle cannot turn: Σ p × ∇C is 0 whatever C is.
    let rotation = match report.max_relative_error.len() {
        1 => "rotation invariant: not asked of one particle (it turns about itself)".to_owned(),
        _ => format!(
            "rotation invariant (sum of p x grad C = 0): {}",
            yes(report.rotation_invariant())
        ),
    };
    lines.push((rotation, true));
    lines
}

fn yes(b: bool) -> &'static str {
    if b { "yes" } else { "no" }
}
