//! Every built-in lesson reads, and what each step says should be observed is observed when it
//! runs headless.

use std::path::Path;
use tetlab_core::lesson::{BUILTIN, Lesson, LessonRun};
use tetlab_core::shared_meshes;

#[test]
fn there_are_at_least_six_lessons_in_order() {
    assert!(BUILTIN.len() >= 6);
    let files: Vec<&str> = BUILTIN.iter().map(|b| b.file).collect();
    let mut sorted = files.clone();
    sorted.sort();
    assert_eq!(files, sorted);
    assert!(Lesson::builtin(0).is_err() && Lesson::builtin(BUILTIN.len() + 1).is_err());
}

/// Every built-in lesson, run headless. A lesson whose mesh is one of `../shared/meshes` skips
/// when that folder is absent (and fails under CI, see `shared_meshes::for_test`).
#[test]
fn every_lesson_observes_what_it_says() {
    for (number, builtin) in (1..).zip(BUILTIN) {
        let header = builtin.header().unwrap_or_else(|e| panic!("{e}"));
        if let Some(mesh) = header.missing_mesh() {
            let name = Path::new(mesh).file_name().unwrap().to_string_lossy();
            if shared_meshes::for_test(&name).is_none() {
                continue;
            }
        }
        let lesson = Lesson::builtin(number).unwrap_or_else(|e| panic!("{e}"));
        let mut run = LessonRun::new(&lesson);
        for (k, step) in lesson.steps.iter().enumerate() {
            assert!(!step.text.is_empty());
            let outcome = run
                .run_step(step, |_| std::ops::ControlFlow::Continue(()))
                .unwrap_or_else(|e| panic!("lesson {number}: {e}"))
                .expect("nothing stops it");
            for (expectation, value, holds) in &outcome.checks {
                assert!(
                    holds,
                    "lesson {number} ({}), step {}: expected {expectation}, measured {value:?}",
                    lesson.title,
                    k + 1
                );
            }
        }
    }
}
