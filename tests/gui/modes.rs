//! The modes window in the workbench, screenless (egui_kittest on wgpu, like tests/gui.rs): the
//! selected tet's eigenvalues as the energy of the active families gives them, their count of
//! zeros and negatives as the tet is inverted, a picked mode drawn in the view (arrows and the tet
//! moved along it) while the simulation stays where it was, and a family typed in the editor.

use crate::gui_support::{pixels_like, workbench};
use eframe::egui;
use egui_kittest::kittest::Queryable;
use tetlab_core::energy::modes::Modes;
use tetlab_core::teaching::visual;

/// D opens the window on the selected tet: at rest under edges and volume (the defaults), the
/// Hessian is Σ ∇C ∇Cᵀ, whose rank is that of the gradients: the six edges' span every
/// deformation, the volume's among them, so 12 − 6 = 6 eigenvalues are zero and none negative.
/// Inverted, only the translations stay null (the volume's C ≠ 0 gives the rotations stress);
/// the volume's energy alone has negative modes there. Picking the lowest draws it in the mode
/// colour, and moves nothing.
#[test]
fn the_modes_window_shows_the_selected_tets_eigenvalues_and_draws_a_mode() {
    let mut harness = workbench("tet", 1);
    harness.key_press(egui::Key::D);
    harness.run_steps(2);
    assert!(harness.state().modes.open);
    assert_eq!(
        harness
            .state()
            .bench
            .simulation
            .families()
            .describe(harness.state().bench.simulation.active()),
        "edges+volume"
    );
    harness.get_by_label_contains("Tet 0: E = ");
    harness.get_by_label_contains("volume: rigid (α = 0), taken with α = 1");
    harness.get_by_label_contains("6 zero and 0 negative of 12");

    // Inverted, the edges are content (a mirror image keeps every length) and their ∇C ∇Cᵀ
    // outweighs the volume's C ∇²C: still no negative mode. Without the edges, there are.
    harness.key_press(egui::Key::I);
    harness.run_steps(2);
    harness.get_by_label_contains("3 zero and 0 negative of 12");
    harness.get_all_by_label("edges").next().unwrap().click();
    harness.run_steps(2);
    let simulation = harness.state().bench.simulation.clone();
    assert_eq!(
        simulation.families().describe(simulation.active()),
        "volume"
    );
    let modes = Modes::of_tet(&simulation, 0).unwrap();
    assert!(modes.negative_count() > 0, "{:?}", modes.values());
    harness.get_by_label_contains(&format!(
        "{} zero and {} negative of 12",
        modes.zero_count(),
        modes.negative_count()
    ));

    // The window's bars have the mode colour too: count the view's before a mode is picked.
    let before = pixels_like(&mut harness, visual::MODE);
    harness.state_mut().modes.animate = false;
    harness.get_by_label("#0").click();
    harness.run_steps(3);
    let shown = harness.state().bench.mode_shown.expect("mode 0 is drawn");
    assert_eq!(shown.tet, 0);
    for (a, b) in shown.vector.iter().zip(&modes.modes()[0].vector) {
        assert!((a.abs() - b.abs()).max_element() < 1e-9, "mode 0's vector");
    }
    harness.snapshot("modes");
    let after = pixels_like(&mut harness, visual::MODE);
    assert!(
        after > before + 300,
        "its arrows and the tet moved along it are drawn: {before} then {after} pixels"
    );
    assert_eq!(
        harness.state().bench.simulation.positions(),
        simulation.positions(),
        "only drawn: the simulation has not moved"
    );

    // Closed, the view draws no mode.
    harness.key_press(egui::Key::D);
    harness.run_steps(2);
    assert!(harness.state().bench.mode_shown.is_none());
}

/// A family typed in the constraint editor is among the energies, and the window follows the tet
/// as it moves: the volume file's energy alone at rest has 11 zero eigenvalues, inverted 3.
#[test]
fn the_modes_window_counts_a_family_typed_in_the_editor() {
    let mut harness = workbench("tet", 1);
    let example = tetlab_core::constraint_file::EXAMPLES
        .iter()
        .find(|e| e.file == "volume.toml")
        .unwrap();
    let file = tetlab_core::constraint_file::ConstraintFile::parse(&example.shown(), example.text)
        .unwrap();
    harness.state_mut().define_constraint(file);
    let mut settings = *harness.state().bench.simulation.settings();
    let families = harness.state().bench.simulation.families().clone();
    settings.active = families.parse_list("my-volume").unwrap();
    harness.state_mut().set_settings(settings);
    harness.key_press(egui::Key::D);
    harness.run_steps(2);
    harness.get_by_label_contains("my-volume: rigid (α = 0), taken with α = 1");
    harness.get_by_label_contains("11 zero and 0 negative of 12");
    harness.key_press(egui::Key::I);
    harness.run_steps(2);
    harness.get_by_label_contains("3 zero and 5 negative of 12");
}
