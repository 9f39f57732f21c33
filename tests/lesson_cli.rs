//! `tetlab lesson`: the built-in lessons run headless and observe what they say; a teacher's own
//! lesson file runs too, and its mistakes are reported with file and line; `--record` writes
//! what the lesson shows.

mod support;

use serde_json::Value;
use std::path::PathBuf;
use support::{assert_usage_error, asset, stderr, stdout, tetlab};

fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tetlab-lesson-{}-{test}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn the_built_in_lessons_are_listed_and_observe_what_they_say() {
    let list = tetlab(&["lesson", "--list"]);
    assert!(list.status.success());
    let text = stdout(&list);
    assert_eq!(text.lines().count(), 14, "{text}");
    assert!(text.contains("02-edges-cannot-uninvert.toml"));

    let output = tetlab(&["lesson", "2"]);
    let text = stdout(&output);
    assert!(output.status.success(), "{text}{}", stderr(&output));
    assert!(text.starts_with("# 2. Why edges alone cannot un-invert a tet"));
    assert_eq!(text.matches("observed: ").count(), 6, "{text}");
    assert!(!text.contains("NOT OBSERVED"));
}

/// Lesson 8 ends in an exercise: as shipped, its last check (the gradient agrees with AD) is not
/// observed and the run fails; handed a mended copy of the file with `--constraint-file`, it
/// passes. A file of another name joins the lesson's families instead.
#[test]
fn the_gradient_exercise_fails_until_the_student_mends_the_file() {
    let output = tetlab(&["lesson", "8"]);
    assert_eq!(output.status.code(), Some(1), "{}", stderr(&output));
    let text = stdout(&output);
    assert!(
        text.contains("observed: gradient_error.height-wrong-sign > 0.1"),
        "{text}"
    );
    assert!(
        text.contains("NOT OBSERVED: gradient_error.height-wrong-sign < 1e-6"),
        "{text}"
    );
    let unobserved: Vec<&str> = text
        .lines()
        .filter(|l| l.starts_with("NOT OBSERVED"))
        .collect();
    assert_eq!(unobserved.len(), 2, "the exercise's two checks: {text}");
    assert!(
        unobserved[1].starts_with("NOT OBSERVED: max_edge_strain < 1e-6"),
        "{text}"
    );
    // Each step that runs frames prints its energy account; the wrong gradient pumps energy in,
    // and the account says so, in the three steps that project along it.
    let accounts = text.lines().filter(|l| l.starts_with("energy: ")).count();
    let gains = text
        .lines()
        .filter(|l| l.starts_with("warning: the energy grew by"))
        .count();
    assert_eq!((accounts, gains), (3, 3), "{text}");

    let dir = scratch("exercise");
    let wrong = std::fs::read_to_string(asset("constraints/height-wrong-sign.toml")).unwrap();
    let fix = dir.join("my-fix.toml");
    std::fs::write(&fix, wrong.replace("g3 = (cross", "g3 = -(cross")).unwrap();
    let output = tetlab(&["lesson", "8", "--constraint-file", fix.to_str().unwrap()]);
    let text = stdout(&output);
    assert!(output.status.success(), "{text}{}", stderr(&output));
    assert!(
        text.contains("observed: gradient_error.height-wrong-sign < 1e-6"),
        "{text}"
    );
    let gains = text
        .lines()
        .filter(|l| l.starts_with("warning: the energy grew by"))
        .count();
    assert_eq!(gains, 2, "mended, the last step gains no energy: {text}");

    let broken = dir.join("broken.toml");
    std::fs::write(&broken, wrong.replace("g3 = (cross", "g3 = (crosss")).unwrap();
    let output = tetlab(&["lesson", "8", "--constraint-file", broken.to_str().unwrap()]);
    let line = assert_usage_error(&output, "broken.toml:");
    assert!(line.contains("unknown function `crosss`"), "{line}");
}

/// Lesson 9's exercise starts with no gradient at all: as shipped, its grade says so particle by
/// particle and the run fails; a wrong answer is named at its particle with a configuration; a
/// right one passes.
#[test]
fn the_write_a_gradient_exercise_is_graded() {
    let output = tetlab(&["lesson", "9", "--quiet"]);
    assert_eq!(output.status.code(), Some(1), "{}", stderr(&output));
    let text = stdout(&output);
    assert!(text.contains("grade: p0: not written yet"), "{text}");

    let dir = scratch("write");
    let start = std::fs::read_to_string(asset("constraints/relative-volume.toml")).unwrap();
    let gradient = "\n[gradient]\n\
        p1 = \"cross(e2, e3) / (6 * rest)\"\n\
        p2 = \"cross(e3, e1) / (6 * rest)\"\n\
        p3 = \"cross(e1, e2) / (6 * rest)\"\n\
        p0 = \"-(cross(e2, e3) + cross(e3, e1) + cross(e1, e2)) / (6 * rest)\"\n";
    // Hands `text` in as the answer to lesson 9.
    let hand_in = |text: String| {
        let answer = dir.join("my-answer.toml");
        std::fs::write(&answer, text).unwrap();
        let answer = answer.to_str().unwrap();
        tetlab(&["lesson", "9", "--quiet", "--constraint-file", answer])
    };
    let output = hand_in(format!("{start}{gradient}"));
    let text = stdout(&output);
    assert!(output.status.success(), "{text}{}", stderr(&output));
    assert!(text.contains("grade: passed"), "{text}");

    // p2's gradient with its sign lost.
    let output = hand_in(
        format!("{start}{gradient}").replace("p2 = \"cross(e3, e1)", "p2 = \"cross(e1, e3)"),
    );
    let text = stdout(&output);
    assert_eq!(output.status.code(), Some(1), "{text}{}", stderr(&output));
    assert!(text.contains("grade: p2: wrong"), "{text}");
    assert!(
        text.contains("grade: p2 is furthest off at p0 = ("),
        "{text}"
    );
    assert!(text.contains("grade: p1: held"), "{text}");
}

#[test]
fn a_teachers_lesson_runs_and_a_wrong_expectation_fails_the_run() {
    let dir = scratch("teacher");
    let path = dir.join("mine.toml");
    std::fs::write(
        &path,
        "title = \"Mine\"\nscene = \"cube\"\nresolution = 2\n\n[[step]]\ntext = \"Mirror.\"\n\
         actions = [\"mirror\"]\nexpect = [\"inverted_tets == 48\", \"inverted_tets == 0\"]\n",
    )
    .unwrap();
    let output = tetlab(&["lesson", path.to_str().unwrap()]);
    assert_eq!(output.status.code(), Some(1), "{}", stderr(&output));
    let text = stdout(&output);
    assert!(
        text.contains("observed: inverted_tets == 48 (measured 48)"),
        "{text}"
    );
    assert!(
        text.contains("NOT OBSERVED: inverted_tets == 0 (measured 48)"),
        "{text}"
    );
}

#[test]
fn mistakes_in_a_lesson_file_name_the_file_and_line() {
    let dir = scratch("mistakes");
    let path = dir.join("typo.toml");
    std::fs::write(
        &path,
        "title = \"Typo\"\nscene = \"tet\"\n[[step]]\ntext = \"x\"\nactions = [\"mirorr\"]\n",
    )
    .unwrap();
    let line = assert_usage_error(&tetlab(&["lesson", path.to_str().unwrap()]), "typo.toml:5:");
    assert!(line.contains("'mirorr' is not an action"), "{line}");
    assert_usage_error(&tetlab(&["lesson", "99"]), "no such lesson");
    assert_usage_error(
        &tetlab(&["lesson", "/nonexistent.toml"]),
        "/nonexistent.toml",
    );
    assert_usage_error(&tetlab(&["lesson"]), "<N|FILE>");
}

#[test]
fn a_recorded_lesson_holds_its_frames_its_text_and_the_comparison() {
    let dir = scratch("record");
    let path = dir.join("lesson2.rrd");
    let output = tetlab(&["lesson", "2", "--record", path.to_str().unwrap(), "--quiet"]);
    assert!(output.status.success(), "{}", stderr(&output));
    let output = tetlab(&["inspect", path.to_str().unwrap(), "--json"]);
    assert!(output.status.success(), "{}", stderr(&output));
    let summary: Value = serde_json::from_str(&stdout(&output)).unwrap();
    // 120 + 60 frames after the first; the clock runs on through the third step's reset.
    assert_eq!(summary["frames"], serde_json::json!([0, 180]));
    let entities = summary["entities"].as_object().unwrap();
    assert_eq!(entities["lesson"]["frame_rows"], 3, "one text per step");
    assert_eq!(entities["world/particles"]["frame_rows"], 181);
    assert_eq!(
        entities["compare/world/particles"]["frame_rows"], 60,
        "the third step compares"
    );
    assert_eq!(entities["compare/metrics/inverted_tets"]["frame_rows"], 60);
}

/// A lesson's material is checked like `--material`, and named by file and line.
#[test]
fn a_bad_material_in_a_lesson_names_the_line() {
    let dir = std::env::temp_dir().join(format!("tetlab-material-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("material.toml");
    std::fs::write(
        &path,
        "title = \"m\"\nscene = \"tet\"\n\n[settings]\nconstraints = \"neohookean\"\nmaterial = \"E=1e6,nu=0.7\"\n\n[[step]]\ntext = \"x\"\n",
    )
    .unwrap();
    let output = tetlab(&["lesson", path.to_str().unwrap()]);
    assert_eq!(output.status.code(), Some(2));
    let message = stderr(&output);
    assert!(
        message.contains("material.toml:6") && message.contains("nu 0.7 is out of range"),
        "{message}"
    );
    std::fs::write(
        &path,
        "title = \"m\"\nscene = \"tet\"\n\n[settings]\ncompliance = { neohookean-deviatoric = 1.0 }\n\n[[step]]\ntext = \"x\"\n",
    )
    .unwrap();
    let output = tetlab(&["lesson", path.to_str().unwrap()]);
    assert_eq!(output.status.code(), Some(2));
    assert!(
        stderr(&output).contains("material.toml:5"),
        "{}",
        stderr(&output)
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// `tetlab lesson --material` replaces the lesson's material: the neo-Hookean lesson's cube of
/// 1 MPa sags under 5 %; one of 10 kPa does not.
#[test]
fn a_lesson_runs_with_another_material() {
    let output = tetlab(&["lesson", "7", "--quiet"]);
    assert!(output.status.success(), "{}", stdout(&output));
    let soft = tetlab(&["lesson", "7", "--quiet", "--material", "E=1e4,nu=0.3"]);
    assert_eq!(soft.status.code(), Some(1), "{}", stdout(&soft));
    assert!(
        stdout(&soft).contains("NOT OBSERVED: max_edge_strain < 0.05"),
        "{}",
        stdout(&soft)
    );
    assert_usage_error(
        &tetlab(&["lesson", "7", "--material", "E=1e4"]),
        "--material",
    );
}
