//! The example constraint files shipped in `assets/constraints`, for the tests that run every one
//! or load one by name.

use std::path::{Path, PathBuf};
use tetlab_core::constraint_file::ConstraintFile;

/// The example `assets/constraints/NAME`, compiled.
#[allow(dead_code)] // Not every test that runs the examples loads one by name.
pub fn example(name: &str) -> ConstraintFile {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../assets/constraints")
        .join(name);
    ConstraintFile::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// Every `.toml` file of `assets/constraints`, sorted by path (the same order on every machine).
#[allow(dead_code)] // Not every test that loads an example runs them all.
pub fn example_files() -> Vec<PathBuf> {
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/constraints");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&folder)
        .unwrap_or_else(|e| panic!("{}: {e}", folder.display()))
        .map(|entry| entry.unwrap().path())
        .filter(|path| path.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    files
}
