//! `tetlab validate` as a user runs it: the quick subset passes on both engines, writes its
//! JSON, records on request, runs one case by name, and refuses a case that does not exist.

mod support;

use serde_json::Value;
use std::path::PathBuf;
use support::{assert_usage_error, stderr, stdout, tetlab};

/// A fresh folder for one test's files.
fn folder(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tetlab-validate-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn the_quick_subset_passes_on_both_engines_and_writes_json() {
    let json = folder("quick").join("validation.json");
    let output = tetlab(&["validate", "--json", json.to_str().unwrap()]);
    let table = stdout(&output);
    assert!(output.status.success(), "{table}\n{}", stderr(&output));
    assert!(!table.contains("FAIL"), "{table}");
    let document: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(document["suite"], "quick");
    assert_eq!(document["passed"], true);
    let checks = document["checks"].as_array().unwrap();
    for case in tetlab_core::measures::validation::CASES
        .iter()
        .filter(|c| c.quick)
    {
        for engine in ["reference", "fast"] {
            let of = |c: &&Value| c["case"] == case.name && c["engine"] == engine;
            let passed = checks
                .iter()
                .filter(of)
                .filter(|c| c["passed"] == true)
                .count();
            assert!(
                passed >= 2,
                "{} on {engine}: {passed} checks passed",
                case.name
            );
            assert!(
                table.contains(&format!("| {} | {engine} |", case.name)),
                "{} on {engine} in the table",
                case.name
            );
        }
    }
    // Every static case says whose error it is: a row on the solver's error (against the exact
    // solution of the same discrete problem) or with that solution beside the measured value.
    for case in ["patch", "hanging-bar", "cantilever", "stretch"] {
        for engine in ["reference", "fast"] {
            let judged = checks.iter().any(|c| {
                c["case"] == case
                    && c["engine"] == engine
                    && (c["judged"] == "Solver" || c["discrete"].is_number())
            });
            assert!(
                judged,
                "{case} on {engine}: no row compares with the exact solution"
            );
        }
    }
    // Nothing is written as NaN: a row that only reports has null where it has no number.
    assert!(!std::fs::read_to_string(&json).unwrap().contains("NaN"));
}

#[test]
fn one_case_by_name_on_one_engine_and_recorded() {
    let rrd = folder("twist").join("twist.rrd");
    let output = tetlab(&[
        "validate",
        "twist",
        "--engine",
        "fast",
        "--record",
        rrd.to_str().unwrap(),
    ]);
    let table = stdout(&output);
    assert!(output.status.success(), "{table}\n{}", stderr(&output));
    assert!(table.contains("| twist | fast |") && !table.contains("| twist | reference |"));
    assert!(!table.contains("| patch |"), "only the case asked for");
    let inspected = tetlab(&["inspect", rrd.to_str().unwrap()]);
    assert!(inspected.status.success(), "{}", stderr(&inspected));
    assert!(
        stdout(&inspected).contains("twist/fast/twisted-360/world/particles"),
        "{}",
        stdout(&inspected)
    );
}

#[test]
fn a_case_that_does_not_exist_is_refused_with_the_list() {
    let output = tetlab(&["validate", "cantilevr"]);
    assert_usage_error(&output, "'cantilevr' is not a validation case");
    assert!(stderr(&output).contains("patch, hanging-bar, cantilever"));
    let output = tetlab(&["validate", "--engine", "auto"]);
    assert_usage_error(&output, "--engine");
    let output = tetlab(&["validate", "--threads", "100000"]);
    assert_usage_error(&output, "--threads");
}
