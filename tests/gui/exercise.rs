//! An exercise in the workbench, screenless (egui_kittest on wgpu, like tests/gui.rs): lesson 9
//! asks for the gradient of the relative volume; the student types it in the constraint editor,
//! and the lesson panel grades it as they type: a wrong p3 is named with a configuration, the
//! mended one passes, and the step's checks then hold.
//!
//! The lesson brings its own table of families, so this runs beside the other GUI tests.

use crate::gui_support::{open_lesson_file, workbench};
use eframe::egui;
use egui_kittest::kittest::Queryable;

#[test]
fn an_exercise_is_graded_in_the_lesson_panel_as_the_student_types() {
    let mut harness = workbench("cube", 2);
    open_lesson_file(&mut harness, "09-write-a-gradient.toml");
    harness.key_press(egui::Key::ArrowRight);
    harness.run_steps(2);
    harness.get_by_label_contains("step 2 of 2");
    harness.get_by_label_contains("not yet: your gradient of relative-volume");
    harness.get_by_label_contains("p0: not written yet");

    // The gradient typed at the end of the file, V0 forgotten at p3.
    harness.key_press(egui::Key::G);
    harness.run_steps(2);
    let editor = harness.get_by_label("Constraint file");
    editor.focus();
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::End);
    let typed = "\n[gradient]\n\
        p1 = \"cross(e2, e3) / (6 * rest)\"\n\
        p2 = \"cross(e3, e1) / (6 * rest)\"\n\
        p0 = \"-(cross(e2, e3) + cross(e3, e1) + cross(e1, e2)) / (6 * rest)\"\n\
        p3 = \"cross(e1, e2) / 6\"";
    harness.get_by_label("Constraint file").type_text(typed);
    harness.run_steps(2);
    assert_eq!(harness.state().editor.error, None);
    // In the lesson panel and beside the editor.
    for line in ["p0: held", "p3: wrong", "p3 is furthest off at p0 = ("] {
        assert_eq!(harness.get_all_by_label_contains(line).count(), 2, "{line}");
    }
    harness.snapshot("lesson_exercise_wrong");

    // Mended: "/ 6\"" becomes "/ (6 * rest)\"".
    for _ in 0..2 {
        harness.key_press(egui::Key::Backspace);
    }
    harness
        .get_by_label("Constraint file")
        .type_text("(6 * rest)\"");
    harness.run_steps(2);
    assert_eq!(
        harness
            .get_all_by_label_contains("passed: your gradient of relative-volume agrees")
            .count(),
        2
    );
    harness.get_by_label_contains("[ok] expect gradient_error.relative-volume < 1e-6");
    harness.snapshot("lesson_exercise_passed");

    // Done: mirrored, and back along the student's gradient.
    harness.get_by_label("Do it").click();
    harness.run_steps(70);
    let app = harness.state();
    assert_eq!(app.bench.metrics.inverted_tets, 0);
    assert!(!app.bench.playing, "the step's 60 frames played");
    harness.get_by_label_contains("[ok] expect inverted_tets == 0");
}
