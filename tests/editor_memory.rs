//! The workbench's editor defines a family on every keystroke that compiles: 100 definitions
//! through the path the editor's text takes ([`TetlabApp::define_constraint`], with a comparison
//! shown too) leave the app's live memory where it was.

use std::path::Path;
use tetlab::gui::{Preferences, TetlabApp};
use tetlab_core::constraint_file::ConstraintFile;

// The counting allocator needs `unsafe impl GlobalAlloc`; it only forwards to `System`.
#[allow(unsafe_code)]
#[path = "../core/tests/support/live_bytes.rs"]
mod live_bytes;

use live_bytes::live;

/// The `k`-th text typed in the editor.
fn typed(k: usize) -> ConstraintFile {
    let text = format!(
        "name = \"typed\"\napplies_to = \"tets\"\nvalue = \"det(p1 - p0, p2 - p0, p3 - p0) / {} - rest\"\n",
        6 + k % 10
    );
    ConstraintFile::parse(Path::new("typed.toml"), &text).unwrap()
}

#[test]
fn a_hundred_definitions_in_the_editor_leave_live_memory_flat() {
    let mut preferences = Preferences::default();
    preferences.scene.builtin = "cube".into();
    preferences.scene.resolution = 2;
    let mut app = TetlabApp::with_preferences(preferences);
    app.compare(Some(*app.bench.simulation.active()));
    for k in 0..10 {
        app.define_constraint(typed(k));
        app.bench.step_frame();
    }
    let before = live();
    for k in 0..100 {
        app.define_constraint(typed(k));
        app.bench.step_frame();
    }
    let grown = live() - before;
    let family = app.editor.family.expect("defined");
    assert!(app.bench.simulation.active()[family]);
    // One definition holds about a kilobyte; a leak of one per definition would be 100 kB.
    assert!(
        grown.abs() < 16 * 1024,
        "{grown} bytes more after 100 definitions"
    );
}
