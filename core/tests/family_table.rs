//! The table of families is a value: defining a family makes a new table and the old one goes
//! with its last holder, so 10⁴ definitions (the workbench's editor defines one per keystroke
//! that compiles) leave live memory where it was; tables are independent of each other.

use std::path::Path;
use tetlab_core::constraint_file::ConstraintFile;
use tetlab_core::constraints::{Families, Family};
use tetlab_core::scene::{Builtin, Scene};
use tetlab_core::simulation::{Settings, Simulation};

// The counting allocator needs `unsafe impl GlobalAlloc`; it only forwards to `System`.
#[allow(unsafe_code)]
#[path = "support/live_bytes.rs"]
mod live_bytes;

use live_bytes::live;

/// The `k`-th text a student types: the same family, a new definition each time.
fn typed(k: usize) -> ConstraintFile {
    let text = format!(
        "name = \"typed\"\napplies_to = \"edges\"\nvalue = \"length(p0 - p1) * {} - rest\"\n",
        1 + k % 10
    );
    ConstraintFile::parse(Path::new("typed.toml"), &text).unwrap()
}

#[test]
fn ten_thousand_definitions_leave_live_memory_flat() {
    let scene = Scene::builtin(Builtin::Tet, 1).unwrap();
    let mut families = Families::builtin();
    let family = families.define(typed(0)).unwrap();
    let mut settings = Settings::default();
    settings.active[family] = true;
    let mut simulation = Simulation::with_families(&scene, settings, families.clone());
    simulation.step();
    // Warm up: every text the loop types, once.
    for k in 0..10 {
        families.define(typed(k)).unwrap();
        simulation.set_families(families.clone());
    }
    let before = live();
    for k in 0..10_000 {
        assert_eq!(families.define(typed(k)).unwrap(), family, "the same place");
        simulation.set_families(families.clone());
    }
    simulation.step();
    let grown = live() - before;
    // One definition is about a kilobyte (its row, its text, its tapes): a leak of one per
    // definition would be ten megabytes.
    assert!(
        grown.abs() < 64 * 1024,
        "{grown} bytes more after 10⁴ definitions"
    );
    assert_eq!(simulation.constraint_count(family), 6);
}

#[test]
fn a_table_is_its_holders_alone() {
    let mut one = Families::builtin();
    let family = one.define(typed(0)).unwrap();
    let other = Families::builtin();
    assert!(
        other.parse("typed").is_err(),
        "another table does not have it"
    );
    let copy = one.clone();
    one.define(typed(1)).unwrap();
    assert!(
        !one.same_definition(&copy, family),
        "redefined in one table"
    );
    assert!(copy.same_definition(&copy.clone(), family));
    assert_eq!(copy.name(family), "typed");
    assert!(Family::builtins().all(|f| one.same_definition(&other, f)));
}
