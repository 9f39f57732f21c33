//! The constraint editor in the workbench, screenless (egui_kittest on wgpu, like tests/gui.rs):
//! a constraint typed in the editor is simulated, drawn in its own colour and inspected; a
//! mistake is shown at its line and column while the last good definition stays; a wrong
//! gradient is named by the check and drawn pale beside AD's; a dropped file opens in the editor.
//!
//! Each test's workbench owns its table of families: the examples are added to it, in the same
//! order, before anything is drawn, so that the snapshots do not depend on which test ran first.

use crate::gui_support::{pixels_like, workbench};
use eframe::egui;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use std::path::Path;
use tetlab::gui::TetlabApp;
use tetlab_core::constraint_file::ConstraintFile;
use tetlab_core::constraints::{Families, Family};
use tetlab_core::teaching::visual::{self, Quantity};

/// The example families these tests use, added to `harness`'s workbench in this order before
/// anything is drawn: the solver panel lists every family of its table.
fn with_examples(harness: &mut Harness<'static, TetlabApp>) {
    let mut families = Families::builtin();
    for name in ["height.toml", "height-wrong-sign.toml", "volume.toml"] {
        let example = tetlab_core::constraint_file::EXAMPLES
            .iter()
            .find(|e| e.file == name)
            .unwrap();
        let file = ConstraintFile::parse(&example.shown(), example.text).unwrap();
        families.register(file).unwrap();
    }
    harness.state_mut().bench.set_families(families);
}

/// The workbench's table of families.
fn families(harness: &Harness<'static, TetlabApp>) -> Families {
    harness.state().bench.simulation.families().clone()
}

/// G opens the editor on the source note's height; it is defined, switched on, drawn in its own
/// colour on an inverted tet, inspected beside AD, and recovers the tet when played. A mistake
/// typed in the editor is reported at its line and column, and the family stays as it was.
#[test]
fn a_constraint_typed_in_the_editor_is_simulated_and_its_mistakes_are_shown() {
    let mut harness = workbench("tet", 1);
    with_examples(&mut harness);
    harness.key_press(egui::Key::G);
    harness.run_steps(2);
    let family = harness.state().editor.family.expect("the example compiles");
    assert_eq!(families(&harness).name(family), "my-height");
    let settings = *harness.state().bench.simulation.settings();
    assert!(settings.active[family], "switched on");
    assert_eq!(
        families(&harness).describe(&settings.active),
        "edges+volume+my-height"
    );
    harness.get_by_label_contains("family my-height: on in the solver panel");

    harness.key_press(egui::Key::I);
    harness.run_steps(2);
    assert_eq!(harness.state().bench.metrics.inverted_tets, 1);
    harness.snapshot("constraint_editor");
    let colour = Quantity::Gradient(family).colour(&families(&harness));
    assert!(
        pixels_like(&mut harness, colour) > 50,
        "the file's arrows, in its own colour"
    );

    // The inspector shows AD's gradient and yours (the note's) side by side.
    harness.key_press(egui::Key::E);
    harness.run_steps(2);
    harness.get_by_label_contains("my-height (").click();
    harness.run_steps(2);
    harness.get_all_by_label("∇C yours").next().unwrap();
    harness.get_all_by_label("∇C by AD").next().unwrap();
    harness.key_press(egui::Key::E);

    // A mistake at the end, in the [gradient] table: a particle a tet-vertex binding does not
    // have, on line 22 (the file's 20 lines, then a blank one).
    let typed = "\np4 = \"n\"";
    let editor = harness.get_by_label("Constraint file");
    editor.focus();
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::End);
    harness.get_by_label("Constraint file").type_text(typed);
    harness.run_steps(2);
    let error = harness
        .state()
        .editor
        .error
        .clone()
        .expect("the mistake is shown");
    assert!(error.contains("height.toml:22:1:"), "{error}");
    assert!(
        error.contains("`p4`: this binding has particles p0…p3 only"),
        "{error}"
    );
    harness.get_by_label_contains("`p4`: this binding has particles p0…p3 only");
    harness.snapshot("constraint_editor_mistake");
    assert_eq!(
        harness.state().editor.family,
        Some(family),
        "the last good one stays"
    );
    for _ in 0..typed.len() {
        harness.key_press(egui::Key::Backspace);
    }
    harness.run_steps(2);
    assert_eq!(harness.state().editor.error, None, "mended");

    // Keys go to the editor while it has the focus; the Play button plays.
    harness.get_by_label("Play").click();
    harness.run_steps(60);
    assert_eq!(harness.state().editor.error, None, "nothing was typed");
    assert_eq!(harness.state().bench.metrics.inverted_tets, 0, "recovered");
}

/// The wrong height (one sign lost in g3), picked in the editor: the check names p3, its arrows
/// are drawn pale beside AD's, and the inspector marks yours.
#[test]
fn a_wrong_gradient_is_named_by_the_check_and_drawn_beside_ads() {
    let mut harness = workbench("tet", 1);
    with_examples(&mut harness);
    harness.key_press(egui::Key::G);
    harness.run_steps(2);
    // The editor's example button (the solver panel has a checkbox of the same name).
    harness
        .get_by_role_and_label(egui::accesskit::Role::Button, "height-wrong-sign")
        .click();
    harness.run_steps(2);
    let family = harness.state().editor.family.unwrap();
    assert_eq!(families(&harness).name(family), "height-wrong-sign");
    let active = *harness.state().bench.simulation.active();
    assert!(active[family] && !active[families(&harness).parse("my-height").unwrap()]);
    harness.get_by_label("Check my gradient").click();
    harness.run_steps(2);
    harness.get_by_label("your gradient does NOT agree with AD");
    harness.get_by_label_contains("worst at p3");
    harness.key_press(egui::Key::I);
    harness.run_steps(2);
    // It is simulated with its own gradient (use_gradient): AD's is the one drawn pale (the
    // legend says "grad C: height-wrong-sign, AD, where it differs").
    let pale = Quantity::Disagreeing(family).colour(&families(&harness));
    assert!(pixels_like(&mut harness, pale) > 30, "the other gradient");
    harness.snapshot("constraint_editor_wrong_gradient");
}

/// A constraint file dropped on the window opens in the editor; one with a mistake opens too,
/// with the mistake shown where it can be mended.
#[test]
fn a_dropped_constraint_file_opens_in_the_editor() {
    #[derive(Debug)]
    struct Dropped(std::path::PathBuf);
    impl egui::DroppedFile for Dropped {
        fn path(&self) -> &Path {
            &self.0
        }
        fn bytes(&self) -> Result<Vec<u8>, String> {
            std::fs::read(&self.0).map_err(|e| e.to_string())
        }
    }
    let mut harness = workbench("cube", 2);
    with_examples(&mut harness);
    let volume = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/constraints/volume.toml");
    harness
        .input_mut()
        .dropped_files
        .push(std::sync::Arc::new(Dropped(volume)));
    harness.run_steps(3);
    let family = harness.state().editor.family.expect("dropped and defined");
    assert_eq!(families(&harness).name(family), "my-volume");
    assert!(harness.state().editor.open);
    assert!(harness.state().bench.simulation.active()[family]);

    let dir = std::env::temp_dir().join(format!("tetlab-editor-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let broken = dir.join("broken.toml");
    std::fs::write(
        &broken,
        "name = \"broken\"\napplies_to = \"edges\"\nvalue = \"length(p0 - p2) - rest\"\n",
    )
    .unwrap();
    harness
        .input_mut()
        .dropped_files
        .push(std::sync::Arc::new(Dropped(broken)));
    harness.run_steps(3);
    let error = harness.state().editor.error.clone().expect("the mistake");
    assert!(
        error.contains("broken.toml:3:") && error.contains("p2"),
        "{error}"
    );
    assert!(
        harness.state().editor.text.contains("p0 - p2"),
        "the text to mend"
    );
    let table = families(&harness);
    assert!(visual::family_colour(&table, family) != visual::family_colour(&table, Family::VOLUME));
}

/// The neo-Hookean example holds two constraints: pressed in the editor, both are defined and
/// switched on, projected as a pair, and the editor's previous family is switched off.
#[test]
fn a_file_of_two_constraints_defines_both_from_the_editor() {
    let mut harness = workbench("cube", 2);
    with_examples(&mut harness);
    harness.key_press(egui::Key::G);
    harness.run_steps(2);
    harness
        .get_by_role_and_label(egui::accesskit::Role::Button, "neohookean")
        .click();
    harness.run_steps(2);
    let table = families(&harness);
    let deviatoric = table.parse("my-neohookean-deviatoric").unwrap();
    let hydrostatic = table.parse("my-neohookean-hydrostatic").unwrap();
    let active = *harness.state().bench.simulation.active();
    assert!(active[deviatoric] && active[hydrostatic]);
    assert!(!active[table.parse("my-height").unwrap()]);
    assert_eq!(
        table.unit_of(deviatoric, &active).partner,
        Some(hydrostatic)
    );
    assert_eq!(harness.state().editor.family, Some(deviatoric));
    // The solver panel shows the pair as one group, with the material's E and ν (its stiffness
    // is μ and λ): switched off and on together.
    // The solver panel's (the compare panel below has one of the same name).
    harness
        .get_all_by_role_and_label(egui::accesskit::Role::CheckBox, "my-neohookean")
        .next()
        .expect("the solver panel's checkbox")
        .click();
    harness.run_steps(2);
    let active = *harness.state().bench.simulation.active();
    assert!(!active[deviatoric] && !active[hydrostatic]);
    // The solver panel's (the compare panel below has one of the same name).
    harness
        .get_all_by_role_and_label(egui::accesskit::Role::CheckBox, "my-neohookean")
        .next()
        .expect("the solver panel's checkbox")
        .click();
    harness.run_steps(2);
    let active = *harness.state().bench.simulation.active();
    assert!(active[deviatoric] && active[hydrostatic]);
    // Played from a mirror, the pair brings the cube back, as the built-in does.
    harness.key_press(egui::Key::M);
    harness.run_steps(2);
    assert!(harness.state().bench.metrics.inverted_tets > 0, "mirrored");
    for _ in 0..90 {
        harness.state_mut().bench.step_frame();
    }
    assert_eq!(harness.state().bench.metrics.inverted_tets, 0);
}
