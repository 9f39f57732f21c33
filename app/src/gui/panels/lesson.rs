//! The lesson: a picker, the current step's text, what it expects (checked live against the
//! metrics) and the buttons to do it and move on. The same contents serve the lesson window and
//! classroom mode (larger).

use super::{Context, Panel};
use crate::gui::request::{LessonRequest, Request};
use crate::gui::workbench::Workbench;
use eframe::egui;
use tetlab_core::constraints::{Families, Family};
use tetlab_core::measures::metrics::Metrics;
use tetlab_core::teaching::lesson::{BUILTIN, Lesson, Step};

/// A lesson in progress in the workbench.
pub struct LessonState {
    /// The lesson.
    pub lesson: Lesson,
    /// The step shown, from 0.
    pub step: usize,
    /// Frames the step still plays after "do it".
    pub frames_left: u64,
}

impl LessonState {
    /// The step shown.
    pub fn current(&self) -> &Step {
        &self.lesson.steps[self.step]
    }
}

/// The lesson panel: a picker, and the current step of the lesson in progress. It owns the
/// typed path of a lesson file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LessonPanel {
    /// The path typed in the "lesson file" field.
    pub path: String,
    /// Per built-in lesson, the note that its mesh is not here (read once).
    missing: Option<Vec<Option<String>>>,
}

/// What the lesson panel says of a lesson whose mesh file is not here (in a browser, or a clone
/// without `../shared/meshes`), or `None` when it can be opened.
pub fn missing_mesh_note(
    number: usize,
    header: &tetlab_core::teaching::lesson::LessonHeader,
) -> Option<String> {
    let mesh = header.missing_mesh()?;
    let name = std::path::Path::new(mesh)
        .file_name()
        .map_or(mesh.into(), |n| n.to_string_lossy());
    Some(format!(
        "Lesson {number} needs the mesh {name}, which is not here: scripts/web.sh puts it beside the page (in meshes/) from ../shared/meshes, when that folder is beside the repository."
    ))
}

impl Panel for LessonPanel {
    fn ui(&mut self, ui: &mut egui::Ui, context: &Context<'_>, requests: &mut Vec<Request>) {
        let comparison = context.comparison.map(|c| c.metrics);
        // In a browser a lesson on a mesh file cannot be opened (the page has no file system):
        // say so before it is clicked. On the desktop, opening it says what is missing.
        let missing = self.missing.get_or_insert_with(|| {
            BUILTIN
                .iter()
                .enumerate()
                .map(|(k, lesson)| {
                    let header = lesson.header().ok()?;
                    cfg!(target_arch = "wasm32")
                        .then(|| missing_mesh_note(k + 1, &header))
                        .flatten()
                })
                .collect()
        });
        let request = show(
            ui,
            context.lesson,
            missing,
            &mut self.path,
            context.classroom,
            context.bench,
            comparison.as_ref(),
        );
        requests.extend(request.map(Request::Lesson));
    }
}

/// Shows the lesson picker and, when a lesson is open, its current step. `large` is classroom
/// mode. `bench` is the workbench shown and `comparison` the metrics of the second simulation.
fn show(
    ui: &mut egui::Ui,
    state: Option<&LessonState>,
    missing: &[Option<String>],
    path: &mut String,
    large: bool,
    bench: &Workbench,
    comparison: Option<&Metrics>,
) -> Option<LessonRequest> {
    let families = bench.simulation.families();
    let mut request = None;
    let size = if large { 22.0 } else { 14.0 };
    if !large || state.is_none() {
        ui.horizontal_wrapped(|ui| {
            ui.label("Lesson:");
            for k in 1..=BUILTIN.len() {
                let chosen = state.is_some_and(|s| {
                    s.lesson.source.file_name().and_then(|n| n.to_str())
                        == Some(BUILTIN[k - 1].file)
                });
                let note = missing.get(k - 1).and_then(Option::as_deref);
                if ui
                    .add_enabled(
                        note.is_none(),
                        egui::Button::selectable(chosen, k.to_string()),
                    )
                    .on_hover_text(BUILTIN[k - 1].file)
                    .on_disabled_hover_text(note.unwrap_or_default())
                    .clicked()
                {
                    request = Some(LessonRequest::Builtin(k));
                }
            }
        });
        for note in missing.iter().flatten() {
            ui.small(note);
        }
        ui.horizontal(|ui| {
            ui.add(
                egui::TextEdit::singleline(path)
                    .hint_text("your-lesson.toml")
                    .desired_width(200.0),
            )
            .labelled_by(ui.label("lesson file").id);
            if ui
                .add_enabled(!path.trim().is_empty(), egui::Button::new("Open lesson"))
                .clicked()
            {
                request = Some(LessonRequest::File(path.trim().to_owned()));
            }
        });
    }
    let Some(state) = state else {
        ui.label("Pick a lesson, or drop a lesson file (.toml) on the window.");
        return request;
    };
    let step = state.current();
    ui.label(
        egui::RichText::new(&state.lesson.title)
            .size(size * 1.3)
            .strong(),
    );
    ui.label(
        egui::RichText::new(format!(
            "step {} of {}",
            state.step + 1,
            state.lesson.steps.len()
        ))
        .size(size * 0.8),
    );
    ui.add_space(size * 0.4);
    ui.label(egui::RichText::new(&step.text).size(size));
    ui.add_space(size * 0.4);
    for expectation in &step.expect {
        let (mark, colour, measured) = match expectation.check(bench.measured(comparison)) {
            Some((value, true)) => ("[ok]", egui::Color32::from_rgb(60, 180, 90), value),
            Some((value, false)) => ("[..]", egui::Color32::from_rgb(220, 160, 40), value),
            None => ("[..]", egui::Color32::GRAY, f64::NAN),
        };
        let now = if measured.is_nan() {
            "no comparison shown".to_owned()
        } else {
            format!("now {measured:.4}")
        };
        ui.label(
            egui::RichText::new(format!("{mark} expect {expectation}   ({now})"))
                .size(size * 0.9)
                .color(colour)
                .monospace(),
        );
    }
    for family in step.exercises() {
        show_grade(ui, families, family, size);
    }
    ui.add_space(size * 0.4);
    ui.horizontal(|ui| {
        let text = |t: &str| egui::RichText::new(t).size(size);
        if ui
            .add_enabled(state.step > 0, egui::Button::new(text("< Previous")))
            .on_hover_text("Left arrow")
            .clicked()
        {
            request = Some(LessonRequest::Previous);
        }
        let what = describe(step);
        if ui
            .add_enabled(!what.is_empty(), egui::Button::new(text("Do it")))
            .on_hover_text(format!("Enter: {what}"))
            .clicked()
        {
            request = Some(LessonRequest::Do);
        }
        if ui
            .add_enabled(
                state.step + 1 < state.lesson.steps.len(),
                egui::Button::new(text("Next >")),
            )
            .on_hover_text("Right arrow")
            .clicked()
        {
            request = Some(LessonRequest::Next);
        }
    });
    if state.frames_left > 0 {
        ui.label(
            egui::RichText::new(format!("playing: {} frames to go", state.frames_left))
                .size(size * 0.8),
        );
    }
    request
}

/// The grade of the student's gradient for an exercise step: which particles held against
/// automatic differentiation, and for a wrong one where it is furthest off (never AD's answer).
/// Worked out again whenever the family is redefined (as the student types in the editor).
/// The constraint editor shows it too, beside the text being typed.
pub fn show_grade(ui: &mut egui::Ui, families: &Families, family: Family, size: f32) {
    let Some(grade) = tetlab_core::constraint_file::grade::of_family(families, family) else {
        return;
    };
    ui.add_space(size * 0.3);
    ui.label(
        egui::RichText::new(format!(
            "Your gradient of {}, graded:",
            families.name(family)
        ))
        .size(size * 0.9)
        .strong(),
    );
    for (line, good) in grade.lines() {
        let colour = if good {
            egui::Color32::from_rgb(60, 180, 90)
        } else {
            egui::Color32::from_rgb(220, 90, 60)
        };
        ui.label(egui::RichText::new(line).size(size * 0.85).color(colour));
    }
}

/// "mirror, then 60 frames", or empty when the step does nothing by itself.
fn describe(step: &Step) -> String {
    let mut parts: Vec<String> = step.actions.iter().map(|a| format!("{a:?}")).collect();
    if step.frames > 0 {
        parts.push(format!("{} frames", step.frames));
    }
    parts.join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;
    use tetlab_core::teaching::lesson::LessonHeader;

    /// A lesson whose mesh is not here is named in the panel, by the mesh's file name; one on a
    /// built-in scene is not.
    #[test]
    fn a_lesson_whose_mesh_is_missing_is_named() {
        let text = "title = \"t\"\nscene = \"../nowhere/bunny.node\"\n[[step]]\ntext = \"x\"\n";
        let header = LessonHeader::parse(std::path::Path::new("lessons/x.toml"), text).unwrap();
        let note = missing_mesh_note(6, &header).expect("the mesh is missing");
        assert!(
            note.starts_with("Lesson 6 needs the mesh bunny.node"),
            "{note}"
        );
        let cube = "title = \"c\"\nscene = \"cube\"\n";
        let header = LessonHeader::parse(std::path::Path::new("x.toml"), cube).unwrap();
        assert_eq!(missing_mesh_note(1, &header), None);
    }
}
