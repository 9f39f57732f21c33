//! The exercises that come with tetlab, graded: for each, a right answer passes its grade and
//! every check of its lesson, and a wrong one fails, its grade naming the wrong particle and a
//! configuration without giving AD's gradient away.
//!
//! One test, in order: an answer redefines the lesson's family for the whole process.

use std::path::Path;
use tetlab_core::constraint_file::grade::{self, Grade, Verdict};
use tetlab_core::constraint_file::{ConstraintFile, EXAMPLES};
use tetlab_core::teaching::lesson::{BUILTIN, Lesson, LessonRun};

/// An exercise: its lesson, the file the student starts from, and two answers made from it.
struct Exercise {
    lesson: usize,
    file: &'static str,
    right: fn(&str) -> String,
    wrong: fn(&str) -> String,
    /// The particle the wrong answer gets wrong.
    wrong_particle: usize,
}

const GRADIENT: &str = r#"
[gradient]
p1 = "cross(e2, e3) / (6 * rest)"
p2 = "cross(e3, e1) / (6 * rest)"
p3 = "cross(e1, e2) / (6 * rest)"
p0 = "-(cross(e2, e3) + cross(e3, e1) + cross(e1, e2)) / (6 * rest)"
"#;

const EXERCISES: [Exercise; 2] = [
    // "This gradient is wrong: fix it": g3 lost its minus.
    Exercise {
        lesson: 8,
        file: "height-wrong-sign.toml",
        right: |text| text.replace("g3 = (cross", "g3 = -(cross"),
        // A different slip: p2's gradient left at the unit normal's.
        wrong: |text| {
            text.replace("g3 = (cross", "g3 = -(cross")
                .replace("p2 = \"g2\"", "p2 = \"n\"")
        },
        wrong_particle: 2,
    },
    // "Write the gradient": nothing given.
    Exercise {
        lesson: 9,
        file: "relative-volume.toml",
        right: |text| format!("{text}{GRADIENT}"),
        // V0 forgotten at p3: the gradient of V / 6, not of V / V0.
        wrong: |text| {
            format!("{text}{GRADIENT}").replace(
                "p3 = \"cross(e1, e2) / (6 * rest)\"",
                "p3 = \"cross(e1, e2) / 6\"",
            )
        },
        wrong_particle: 3,
    },
];

/// Every step of `lesson` with `answer` handed in; whether every check held (a simulation that
/// diverged holds nothing).
fn every_check_holds(lesson: &Lesson, answer: ConstraintFile) -> bool {
    let mut run = LessonRun::new(lesson);
    run.hand_in(lesson, answer).unwrap();
    lesson.steps.iter().all(|step| {
        match run.run_step(step, |_| std::ops::ControlFlow::Continue(())) {
            Ok(Some(outcome)) => outcome.checks.iter().all(|(_, _, holds)| *holds),
            _ => false,
        }
    })
}

#[test]
fn each_exercise_grades_a_right_and_a_wrong_answer() {
    // The exercises are the built-in lessons with a step that checks a gradient.
    let with_exercises: Vec<usize> = (1..=BUILTIN.len())
        .filter(|&n| {
            let header = BUILTIN[n - 1].header().unwrap();
            header.missing_mesh().is_none()
                && Lesson::builtin(n)
                    .unwrap()
                    .steps
                    .iter()
                    .any(|s| s.exercises().next().is_some())
        })
        .collect();
    assert_eq!(
        with_exercises,
        EXERCISES.iter().map(|e| e.lesson).collect::<Vec<_>>()
    );

    for exercise in &EXERCISES {
        let start = EXAMPLES
            .iter()
            .find(|e| e.file == exercise.file)
            .unwrap()
            .text;
        let lesson = Lesson::builtin(exercise.lesson).unwrap();
        let family = lesson.file_families[0];
        let as_shipped = grade::of_family(&lesson.families, family).unwrap();
        assert!(!as_shipped.passed(), "lesson {}", exercise.lesson);

        // Wrong: not passed; the particle named, with a configuration, and not AD's gradient.
        let wrong = ConstraintFile::parse(Path::new("wrong.toml"), &(exercise.wrong)(start))
            .unwrap_or_else(|e| panic!("{e}"));
        let grade = Grade::of(&wrong);
        assert!(!grade.passed(), "lesson {}: {grade:?}", exercise.lesson);
        let named = grade.shown_wrong.as_ref().map(|w| w.particle);
        assert_eq!(named, Some(exercise.wrong_particle), "{grade:?}");
        assert!(matches!(
            grade.particles[exercise.wrong_particle],
            Verdict::Wrong(e) if e > 1e-3
        ));
        let lines = grade.lines();
        let said = lines
            .iter()
            .map(|(l, _)| l.as_str())
            .collect::<Vec<_>>()
            .join("\n");
        let p = exercise.wrong_particle;
        assert!(said.contains(&format!("p{p}: wrong")), "{said}");
        assert!(
            said.contains(&format!("p{p} is furthest off at p0 = (")),
            "{said}"
        );
        assert!(!said.contains("automatic differentiation gives"), "{said}");
        assert!(
            !every_check_holds(&lesson, wrong),
            "lesson {} with a wrong answer",
            exercise.lesson
        );

        // Right: passed, every particle held, and every check of the lesson holds.
        let lesson = Lesson::builtin(exercise.lesson).unwrap();
        let right = ConstraintFile::parse(Path::new("right.toml"), &(exercise.right)(start))
            .unwrap_or_else(|e| panic!("{e}"));
        let grade = Grade::of(&right);
        assert!(grade.passed(), "lesson {}: {grade:?}", exercise.lesson);
        assert!(
            grade
                .particles
                .iter()
                .all(|v| matches!(v, Verdict::Held(e) if *e < 1e-9))
        );
        assert_eq!(grade.shown_wrong, None);
        assert!(grade.lines()[0].0.starts_with("passed"));
        assert!(
            every_check_holds(&lesson, right),
            "lesson {} with the right answer",
            exercise.lesson
        );
    }
}
