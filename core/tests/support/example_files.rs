//! The example constraint files shipped in `assets/constraints`, for the tests that run every one.

use std::path::{Path, PathBuf};

/// Every `.toml` file of `assets/constraints`, sorted by path (the same order on every machine).
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
