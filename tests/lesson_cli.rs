//! `tetlab lesson`: the built-in lessons run headless and observe what they say; a teacher's own
//! lesson file runs too, and its mistakes are reported with file and line; `--record` writes
//! what the lesson shows.

mod support;

use serde_json::Value;
use std::path::PathBuf;
use support::{assert_usage_error, stderr, stdout, tetlab};

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
    assert_eq!(text.lines().count(), 7, "{text}");
    assert!(text.contains("02-edges-cannot-uninvert.toml"));

    let output = tetlab(&["lesson", "2"]);
    let text = stdout(&output);
    assert!(output.status.success(), "{text}{}", stderr(&output));
    assert!(text.starts_with("# 2. Why edges alone cannot un-invert a tet"));
    assert_eq!(text.matches("observed: ").count(), 6, "{text}");
    assert!(!text.contains("NOT OBSERVED"));
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
    assert_usage_error(&tetlab(&["lesson", "8"]), "no such lesson");
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
