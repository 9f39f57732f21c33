//! Helpers for the workspace-level tests: running the `tetlab` binary as a user would.

#![allow(dead_code)] // each test file uses a different part of this module

use std::process::{Command, Output};

/// Runs `tetlab ARGS…` (the binary cargo built for these tests) and returns its status and output.
pub fn tetlab(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_tetlab"))
        .args(args)
        .output()
        .expect("tetlab runs")
}

/// Stdout as UTF-8 text.
pub fn stdout(output: &Output) -> String {
    String::from_utf8(output.stdout.clone()).expect("stdout is UTF-8")
}

/// Stderr as UTF-8 text.
pub fn stderr(output: &Output) -> String {
    String::from_utf8(output.stderr.clone()).expect("stderr is UTF-8")
}

/// Asserts that a run failed as a usage error: exit status 2, nothing on stdout, and exactly
/// one line on stderr that mentions `names`. Returns that line.
#[track_caller]
pub fn assert_usage_error(output: &Output, names: &str) -> String {
    let err = stderr(output);
    assert_eq!(output.status.code(), Some(2), "exit status; stderr: {err}");
    assert!(
        output.stdout.is_empty(),
        "stdout not empty: {}",
        stdout(output)
    );
    assert_eq!(err.lines().count(), 1, "one line on stderr, got: {err}");
    assert!(err.starts_with("error: "), "{err}");
    assert!(err.contains(names), "stderr should name {names}: {err}");
    err
}

/// The path of `relative` under the repository's `assets/` folder (the tests run in `app/`).
pub fn asset(relative: &str) -> String {
    format!("{}/../assets/{relative}", env!("CARGO_MANIFEST_DIR"))
}
