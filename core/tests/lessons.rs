//! Every built-in lesson reads, and what each step says should be observed is observed when it
//! runs headless.

use tetlab_core::lesson::{BUILTIN, Lesson, LessonRun};

#[test]
fn there_are_at_least_six_lessons_in_order() {
    assert!(BUILTIN.len() >= 6);
    let files: Vec<&str> = BUILTIN.iter().map(|b| b.file).collect();
    let mut sorted = files.clone();
    sorted.sort();
    assert_eq!(files, sorted);
    assert!(Lesson::builtin(0).is_err() && Lesson::builtin(BUILTIN.len() + 1).is_err());
}

#[test]
fn every_lesson_observes_what_it_says() {
    for number in 1..=BUILTIN.len() {
        let lesson = Lesson::builtin(number).unwrap_or_else(|e| panic!("{e}"));
        let mut run = LessonRun::new(&lesson);
        for (k, step) in lesson.steps.iter().enumerate() {
            assert!(!step.text.is_empty());
            let outcome = run
                .run_step(step, |_| std::ops::ControlFlow::Continue(()))
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
