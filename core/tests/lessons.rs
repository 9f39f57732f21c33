//! Every built-in lesson reads, and what each step says should be observed is observed when it
//! runs headless.

use std::path::Path;
use tetlab_core::constraint_file::ConstraintFile;
use tetlab_core::input::shared_meshes;
use tetlab_core::simulation::EngineChoice;
use tetlab_core::teaching::lesson::{BUILTIN, Expectation, Lesson, LessonRun};

/// The built-in lessons are the files of `assets/lessons`, every one, in file-name order and as
/// they are on disk (the library is rebuilt when the folder changes); lesson k opens the k-th
/// file (or names the mesh it lacks), and 0 and N + 1 are refused, naming the range.
#[test]
fn the_built_in_lessons_are_the_files_of_assets_lessons_in_order() {
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/lessons");
    let mut files: Vec<(String, String)> = std::fs::read_dir(&folder)
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .filter(|path| path.extension().is_some_and(|e| e == "toml"))
        .map(|path| {
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            (name, std::fs::read_to_string(&path).unwrap())
        })
        .collect();
    files.sort();
    let builtin: Vec<(String, String)> = BUILTIN
        .iter()
        .map(|b| (b.file.to_owned(), b.text.to_owned()))
        .collect();
    assert_eq!(builtin, files);
    for (number, lesson) in (1..).zip(BUILTIN) {
        let header = lesson.header().unwrap();
        match Lesson::builtin(number) {
            Ok(opened) => assert_eq!(opened.title, header.title),
            Err(e) => assert!(header.missing_mesh().is_some(), "lesson {number}: {e}"),
        }
    }
    let range = format!("1..={}", BUILTIN.len());
    for number in [0, BUILTIN.len() + 1] {
        let error = Lesson::builtin(number).unwrap_err().to_string();
        assert!(error.contains(&range), "{error}");
    }
}

/// Every built-in lesson, run headless. A lesson whose mesh is one of `../shared/meshes` skips
/// when that folder is absent (and fails under CI, see `shared_meshes::for_test`).
///
/// A lesson may end in an exercise: a step with a check of a constraint file's gradient
/// (`gradient_error.NAME < …`) that holds once the student has mended the file. Lesson 8 is one:
/// as shipped, its exercise's checks (and only those) are not observed; with the sign put back,
/// handed in as a student would (`tetlab lesson 8 --constraint-file my-fix.toml`), everything is.
/// One test does both, in order, since the answer redefines the lesson's family for the process.
///
/// On both engines: a lesson that does not name one (`engine` in its settings) is run on the
/// reference engine and on the fast one, and observes the same on each.
///
/// No step gains energy (the energy account over the step's frames, from the state its actions
/// left), but those of [`GAINS`], which show a setup that does, and there the account says so.
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
        let mut lesson = Lesson::builtin(number).unwrap_or_else(|e| panic!("{e}"));
        let engines = match lesson.settings.engine {
            EngineChoice::Auto => vec![EngineChoice::Reference, EngineChoice::Fast],
            named => vec![named],
        };
        for engine in engines {
            lesson.settings.engine = engine;
            let (pending, gains) = unobserved(number, &lesson, None);
            let expected: Vec<usize> = (GAINS.iter())
                .filter(|(n, _, _)| *n == number)
                .map(|(_, step, _)| *step)
                .collect();
            assert_eq!(
                gains, expected,
                "lesson {number} on the {engine:?} engine: the steps that gained energy"
            );
            // What an exercise expects holds once it is done: only the checks of a step whose
            // gradient check is pending may be.
            let exercise = |step: usize| {
                pending
                    .iter()
                    .any(|(s, e)| *s == step && e.gradient_of.is_some())
            };
            for (step, expectation) in &pending {
                assert!(
                    exercise(*step),
                    "lesson {number} ({}) on the {engine:?} engine, step {step}: expected \
                 {expectation}",
                    lesson.title
                );
            }
            if number == 8 {
                assert!(exercise(4), "the exercise is pending: {pending:?}");
            }
        }
    }
    // Lesson 8, with the student's answer: g3 gets its minus back.
    let wrong = tetlab_core::constraint_file::EXAMPLES
        .iter()
        .find(|e| e.file == "height-wrong-sign.toml")
        .unwrap();
    let mended = wrong.text.replace("g3 = (cross", "g3 = -(cross");
    assert_ne!(mended, wrong.text);
    let answer = ConstraintFile::parse(Path::new("my-fix.toml"), &mended).unwrap();
    let lesson = Lesson::builtin(8).unwrap();
    let (pending, gains) = unobserved(8, &lesson, Some(answer));
    assert_eq!(pending, [], "answered, every check of lesson 8 holds");
    assert_eq!(
        gains,
        [1, 3],
        "answered, the mended gradient gains no energy"
    );
}

/// The lesson steps (lesson, step, why) whose frames gain energy, the account says, on either
/// engine: each shows a setup that does.
const GAINS: &[(usize, usize, &str)] = &[
    (
        4,
        1,
        "the volume alone: XPBD's step on slivers, whose ∇C nearly vanishes, gives energy; the \
         Newton reference on the same problem loses it",
    ),
    (
        5,
        1,
        "5 substeps, one sweep each: XPBD's step is far from the exact one, and the beam's \
         elastic energy overshoots as it falls; the Newton reference on the same problem, and \
         XPBD at 20 substeps or 10 sweeps (steps 2 and 3), lose energy",
    ),
    (
        8,
        1,
        "a wrong gradient, projected along: it pumps energy in",
    ),
    (8, 3, "the same wrong gradient, beside the right one"),
    (8, 4, "the wrong gradient, until the student mends it"),
];

/// Runs every step of `lesson` headless, with `answer` handed in; the expectations that did not
/// hold, with their step, and the steps whose frames gained energy.
fn unobserved(
    number: usize,
    lesson: &Lesson,
    answer: Option<ConstraintFile>,
) -> (Vec<(usize, Expectation)>, Vec<usize>) {
    let mut run = LessonRun::new(lesson);
    if let Some(answer) = answer {
        run.hand_in(lesson, answer).unwrap();
    }
    let mut pending = Vec::new();
    let mut gains = Vec::new();
    for (k, step) in lesson.steps.iter().enumerate() {
        assert!(!step.text.is_empty());
        let outcome = run
            .run_step(step, |_| std::ops::ControlFlow::Continue(()))
            .unwrap_or_else(|e| panic!("lesson {number}: {e}"))
            .expect("nothing stops it");
        for (expectation, _, holds) in outcome.checks {
            if !holds {
                pending.push((k + 1, expectation));
            }
        }
        if run.energy().gain.is_some() {
            gains.push(k + 1);
        }
    }
    (pending, gains)
}
