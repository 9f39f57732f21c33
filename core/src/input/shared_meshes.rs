//! The reference meshes written by other tools (the bunny, the armadillo, Gmsh balls and a beam),
//! which live beside a clone in `../shared/meshes` and never in the repository. Tests,
//! benchmarks and the bunny lesson read them from there.
//!
//! A clone on its own has no such folder. Tests that need a mesh ask [`for_test`]: without the
//! folder they skip, saying so on stderr; under CI (`CI=true`), where the folder must be present,
//! a skip is a failure, so that every test that reads the meshes really ran.

use std::io::Write;
use std::path::{Path, PathBuf};

/// `../shared/meshes` beside the clone tetlab was built from.
pub fn folder() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/meshes")
}

/// Whether the folder is there.
pub(crate) fn present() -> bool {
    folder().is_dir()
}

/// Whether this is a CI run (`CI=true`), where the shared meshes must be present.
pub(crate) fn in_ci() -> bool {
    std::env::var("CI").is_ok_and(|v| v == "true")
}

/// The path of mesh `name` for a test that needs it, or `None` when the folder is absent: the
/// test then returns early, and this says on stderr (past the test harness's capture) which
/// folder was missing.
///
/// # Panics
/// Under CI (`CI=true`) when the folder is absent.
pub fn for_test(name: &str) -> Option<PathBuf> {
    if present() {
        return Some(folder().join(name));
    }
    let folder = folder();
    assert!(
        !in_ci(),
        "CI=true but {} is absent: the tests that read {name} from it must run under CI",
        folder.display()
    );
    // Straight to the stream, not through eprintln!, which the test harness captures.
    let _ = writeln!(
        std::io::stderr(),
        "skipped: {} is absent (a clone on its own), and this test reads {name} from it",
        folder.display()
    );
    None
}
