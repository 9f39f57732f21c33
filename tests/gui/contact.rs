//! Contact in the workbench: a particle of the upper cube's underside clicked (the inspector
//! lists its contact pairs with C, ∇C beside central differences, and where the particle stands
//! over its triangle), bodies of their own stuff, and the warning where contact let a particle
//! under a surface.

use super::gui_support::{click_at, workbench};
use eframe::egui;
use egui_kittest::kittest::Queryable;
use tetlab::gui::viewport;

#[test]
fn the_inspector_shows_the_contacts_of_the_clicked_particle() {
    let mut harness = workbench("cube", 2);
    super::open_by_path(&mut harness, "../assets/scenes/stacked-cubes.toml");
    super::tick(&mut harness, "contact");
    for _ in 0..10 {
        harness.get_by_label("Step frame").click();
        harness.run_steps(1);
    }
    // The particle of the upper cube's underside nearest the camera (which looks from +x, +y,
    // +z): a corner the user sees resting on the lower cube.
    let (particle, at) = {
        let state = harness.state();
        let simulation = &state.bench.simulation;
        let upper = simulation.bodies()[1].particles.clone();
        let positions = simulation.positions();
        let lowest = (upper.clone())
            .map(|i| positions[i as usize].y)
            .fold(f64::INFINITY, f64::min);
        let particle = (upper.map(|i| i as usize))
            .filter(|&i| positions[i].y < lowest + 0.01)
            .max_by(|&a, &b| {
                let near = |i: usize| positions[i].x + positions[i].z;
                near(a).total_cmp(&near(b))
            })
            .unwrap();
        let camera = state.viewport.camera;
        let (at, _) = viewport::project(&camera, state.viewport.rect, positions[particle]).unwrap();
        (particle, at)
    };
    click_at(&mut harness, at);
    assert_eq!(harness.state().bench.selected_particle, Some(particle));
    let pairs = harness.state().bench.simulation.contacts_of(particle);
    assert!(!pairs.is_empty(), "the corner rests on the lower cube");
    // The view draws ∇C at the four particles of its nearest pair (as for a pending projection).
    harness.run_steps(2);
    harness.snapshot("contact_selected");
    harness.key_press(egui::Key::E);
    harness.run_steps(2);
    assert!(harness.state().inspector.open);
    harness.get_by_label_contains(&format!(
        "Contacts of particle {particle} ({})",
        pairs.len()
    ));
    harness.get_by_label_contains(&format!("contact #{}   C = ", pairs[0]));
    let over = "p₀ is over the triangle: its foot at b = (";
    assert!(harness.query_all_by_label_contains(over).next().is_some());
    harness.get_by_label_contains("C = e₀ · n − d ≥ 0");
    harness.snapshot("contact_inspector");
}

/// A scene of bodies of their own stuff (`assets/scenes/soft-on-stiff.toml`): the solver panel
/// says what each is made of, and with the neo-Hookean pair and contact switched on the soft
/// cube sags onto the rigid block and rests there (snapshot `soft_on_stiff.png`).
#[test]
fn bodies_of_their_own_stuff_play_in_the_workbench() {
    let mut harness = workbench("cube", 2);
    super::open_by_path(&mut harness, "../assets/scenes/soft-on-stiff.toml");
    harness.get_by_label("body block: 2000 kg/m³, constraints edges+volume");
    harness.get_by_label("body soft: 500 kg/m³, material E=1e5,nu=0.3, constraints neohookean");
    for family in ["neo-Hookean", "contact"] {
        super::tick(&mut harness, family);
    }
    let top = |harness: &egui_kittest::Harness<'_, tetlab::gui::TetlabApp>, b: usize| {
        let simulation = &harness.state().bench.simulation;
        let range = simulation.bodies()[b].particles.clone();
        let positions = &simulation.positions()[range.start as usize..range.end as usize];
        positions.iter().map(|p| p.y).fold(f64::MIN, f64::max)
    };
    // Undamped, the soft cube swings about its sag (its top between 1.5 mm above where it
    // started and 12 mm below, core/tests/contact.rs): the deepest its top came is what shows.
    let start = (top(&harness, 0), top(&harness, 1));
    let (mut block, mut soft): (f64, f64) = (0.0, 0.0);
    for _ in 0..30 {
        harness.get_by_label("Step frame").click();
        harness.run_steps(1);
        block = block.max((start.0 - top(&harness, 0)).abs());
        soft = soft.max(start.1 - top(&harness, 1));
    }
    let simulation = &harness.state().bench.simulation;
    let metrics = tetlab_core::measures::metrics::Metrics::measure_bodies(simulation);
    assert!(metrics[1].1.contacts > 0, "the soft cube touches the block");
    assert!(
        soft > 5e-3,
        "the soft cube's top came down {soft} m at most"
    );
    assert!(block < 1e-4, "the block's top moved {block} m");
    harness.run_steps(2);
    harness.snapshot("soft_on_stiff");
}

/// The readouts warn where contact let a particle under a surface, as `tetlab run` does: a cube
/// thrown down at 8 m/s onto another (`assets/scenes/dropped-cube.toml`) with one substep a
/// frame goes into it; a reset forgets the warning.
#[test]
fn a_particle_under_a_surface_is_warned_about_in_the_readouts() {
    let mut harness = workbench("cube", 2);
    super::open_by_path(&mut harness, "../assets/scenes/dropped-cube.toml");
    super::tick(&mut harness, "contact");
    let bench = &mut harness.state_mut().bench;
    let settings = *bench.simulation.settings();
    bench.set_settings(tetlab_core::simulation::Settings {
        substeps: 1,
        ..settings
    });
    for _ in 0..12 {
        harness.get_by_label("Step frame").click();
        harness.run_steps(1);
    }
    harness.get_by_label_contains("warning: contact let a particle");
    harness.get_by_label("Reset").click();
    harness.run_steps(1);
    assert_eq!(harness.state().bench.penetration_warning, None);
}
