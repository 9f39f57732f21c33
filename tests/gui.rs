//! The workbench, screenless: egui_kittest drives it like a user (buttons, keys, a mouse drag)
//! and renders it with wgpu on a software adapter. Each test checks the state and the pixels of
//! the 3D view, and compares a snapshot in tests/snapshots/ (refresh with UPDATE_SNAPSHOTS=1).

#[path = "support/gui.rs"]
mod gui_support;

// The constraint editor and an exercise: each workbench owns its table of families, so they run in
// this process with the others.
#[path = "gui/constraint_editor.rs"]
mod constraint_editor;
#[path = "gui/contact.rs"]
mod contact;
#[path = "gui/exercise.rs"]
mod exercise;
#[path = "gui/modes.rs"]
mod modes;

use eframe::egui;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use gui_support::{click_at, open_lesson_file, pixels_like, workbench};
use tetlab::gui::{Preferences, TetlabApp, viewport};
use tetlab_core::constraints::Families;
use tetlab_core::teaching::visual;

#[test]
fn the_initial_scene_shows_the_body_in_the_3d_view() {
    let mut harness = workbench("cube", 3);
    assert_eq!(harness.state().bench.simulation.tets().len(), 162);
    assert!(
        pixels_like(&mut harness, visual::HEALTHY) > 5000,
        "the cube is drawn"
    );
    harness.snapshot("workbench_initial");
}

/// A corner tet of a cube, selected by clicking its particle, inverted with the tool, recovered by
/// playing.
#[test]
fn a_tet_inverted_through_the_ui_turns_red_with_arrows_and_recovers_when_played() {
    let mut harness = workbench("cube", 2);
    // Click the particle at the top front corner (the camera looks from +x, +y, +z).
    let corner = 26;
    let (rect, camera) = (
        harness.state().viewport.rect,
        harness.state().viewport.camera,
    );
    let (at, _) = viewport::project(
        &camera,
        rect,
        harness.state().bench.simulation.positions()[corner],
    )
    .unwrap();
    click_at(&mut harness, at);
    assert_eq!(harness.state().bench.selected_particle, Some(corner));
    harness.get_by_label("Invert selected tet").click();
    harness.run_steps(2);
    assert!(harness.state().bench.metrics.inverted_tets >= 1);
    harness.snapshot("tet_inverted");
    assert!(
        pixels_like(&mut harness, visual::INVERTED) > 1000,
        "the inverted tet is red"
    );
    assert!(
        pixels_like(
            &mut harness,
            visual::family_colour(
                &tetlab_core::constraints::Families::builtin(),
                tetlab_core::constraints::Family::VOLUME,
            )
        ) > 50,
        "volume arrows"
    );

    // One substep: the projections' corrections appear as magenta arrows.
    harness.key_press(egui::Key::U);
    harness.run_steps(2);
    let moved = harness.state().bench.simulation.corrections()[corner].length();
    assert!(moved > 0.05, "the inverted corner is pushed back: {moved}");
    assert!(
        pixels_like(&mut harness, visual::CORRECTION) > 50,
        "correction arrows"
    );
    harness.snapshot("tet_substep_corrections");

    harness.get_by_label("Play").click();
    harness.run_steps(60);
    assert_eq!(harness.state().bench.metrics.inverted_tets, 0);
    harness.snapshot("tet_recovered");
    assert!(
        pixels_like(&mut harness, visual::INVERTED) < 50,
        "no red left"
    );
    assert!(
        pixels_like(&mut harness, visual::HEALTHY) > 5000,
        "the cube is still in view"
    );
}

#[test]
fn keys_drive_the_workbench() {
    let mut harness = workbench("cube", 2);
    harness.key_press(egui::Key::M);
    harness.run_steps(1);
    assert_eq!(
        harness.state().bench.metrics.inverted_tets,
        48,
        "M mirrors every tet"
    );
    harness.key_press(egui::Key::R);
    harness.run_steps(1);
    assert_eq!(harness.state().bench.metrics.inverted_tets, 0, "R resets");

    // Orbit by dragging on empty space, then C brings the first view back.
    let first_view = harness.state().viewport.camera;
    let empty = harness.state().viewport.rect.left_bottom() + egui::vec2(30.0, -30.0);
    harness.event(egui::Event::PointerMoved(empty));
    harness.event(egui::Event::PointerButton {
        pos: empty,
        button: egui::PointerButton::Primary,
        pressed: true,
        modifiers: Default::default(),
    });
    harness.run_steps(1);
    for k in 1..=5 {
        harness.event(egui::Event::PointerMoved(
            empty + egui::vec2(20.0 * k as f32, 0.0),
        ));
        harness.run_steps(1);
    }
    harness.event(egui::Event::PointerButton {
        pos: empty + egui::vec2(100.0, 0.0),
        button: egui::PointerButton::Primary,
        pressed: false,
        modifiers: Default::default(),
    });
    harness.run_steps(1);
    assert_ne!(
        harness.state().viewport.camera,
        first_view,
        "the drag orbits"
    );
    harness.key_press(egui::Key::C);
    harness.run_steps(1);
    assert_eq!(
        harness.state().viewport.camera,
        first_view,
        "C resets the camera"
    );

    // Mirror everything and play: the body recovers where it is, it is not launched.
    harness.key_press(egui::Key::M);
    harness.key_press(egui::Key::Space);
    harness.run_steps(1);
    assert!(harness.state().bench.playing);
    let mut highest = f64::MIN;
    for _ in 0..90 {
        harness.run_steps(1);
        for p in harness.state().bench.simulation.positions() {
            highest = highest.max(p.y);
        }
    }
    assert_eq!(harness.state().bench.metrics.inverted_tets, 0);
    assert!(
        highest < 1.5,
        "the 1 m cube stays near the ground: {highest} m"
    );
}

#[test]
fn dragging_a_particle_while_paused_moves_it() {
    let mut harness = workbench("tet", 1);
    let (rect, camera) = (
        harness.state().viewport.rect,
        harness.state().viewport.camera,
    );
    let apex = 3;
    let before = harness.state().bench.simulation.positions()[apex];
    let (start, _) = viewport::project(&camera, rect, before).expect("in view");
    let end = start + egui::vec2(-80.0, 40.0);
    harness.event(egui::Event::PointerMoved(start));
    harness.run_steps(1);
    harness.event(egui::Event::PointerButton {
        pos: start,
        button: egui::PointerButton::Primary,
        pressed: true,
        modifiers: Default::default(),
    });
    harness.run_steps(1);
    for k in 1..=8 {
        harness.event(egui::Event::PointerMoved(
            start + (end - start) * (k as f32 / 8.0),
        ));
        harness.run_steps(1);
    }
    harness.event(egui::Event::PointerButton {
        pos: end,
        button: egui::PointerButton::Primary,
        pressed: false,
        modifiers: Default::default(),
    });
    harness.run_steps(2);
    let after = harness.state().bench.simulation.positions()[apex];
    assert!(
        after.distance(before) > 0.1,
        "the apex moved from {before} to {after}"
    );
    assert_eq!(harness.state().bench.selected_particle, Some(apex));
    let (landed, _) = viewport::project(&camera, rect, after).unwrap();
    assert!(
        landed.distance(end) < 3.0,
        "it follows the pointer: {landed:?} vs {end:?}"
    );
}

/// The neo-Hookean pair is one checkbox with the material beside it; its arrows have the
/// colours of the table; a mirrored cube recovers under it; a material too stiff for the
/// substeps is named in the readouts.
#[test]
fn the_neo_hookean_family_is_switched_on_with_its_material() {
    use tetlab_core::constraints::Family;
    let mut harness = workbench("cube", 2);
    for label in ["edges", "volume"] {
        harness.get_all_by_label(label).next().unwrap().click();
    }
    harness
        .get_all_by_label("neo-Hookean")
        .next()
        .unwrap()
        .click();
    harness.run_steps(2);
    let settings = *harness.state().bench.simulation.settings();
    assert_eq!(Families::builtin().describe(&settings.active), "neohookean");
    assert!(harness.state().bench.stability_warning.is_none());
    // At rest ∇C_H = √3 ∇C_D: the hydrostatic arrows cover the deviatoric ones.
    let colour = |family| visual::family_colour(&Families::builtin(), family);
    assert!(pixels_like(&mut harness, colour(Family::NEOHOOKEAN_HYDROSTATIC)) > 20);
    harness.key_press(egui::Key::M);
    harness.run_steps(1);
    assert_eq!(harness.state().bench.metrics.inverted_tets, 48);
    // The inspector shows F and J.
    harness.key_press(egui::Key::E);
    harness.run_steps(2);
    harness
        .get_all_by_label_contains("J = det F = -1.0000")
        .next()
        .unwrap();
    harness.key_press(egui::Key::E);
    harness.run_steps(2);
    // Mirrored, cof F = −F: the two point opposite ways, and both show.
    harness.snapshot("neohookean_mirrored");
    for family in [
        Family::NEOHOOKEAN_DEVIATORIC,
        Family::NEOHOOKEAN_HYDROSTATIC,
    ] {
        assert!(
            pixels_like(&mut harness, colour(family)) > 20,
            "{family:?} arrows"
        );
    }
    harness.key_press(egui::Key::Space);
    harness.run_steps(60);
    assert_eq!(harness.state().bench.metrics.inverted_tets, 0, "recovered");
    // Steel in ten substeps: the readouts say how many it needs.
    let mut steel = settings;
    steel.material = tetlab_core::constraints::material::Material {
        young: 2e11,
        poisson: 0.3,
    };
    harness.state_mut().set_settings(steel);
    harness.run_steps(1);
    harness.get_by_label_contains("needs at least");
}

#[test]
fn the_controls_switch_solver_and_families() {
    let mut harness = workbench("cube", 2);
    harness.get_by_label("PBD").click();
    // The solver panel's checkbox; the compare panel below has one of the same name.
    harness.get_all_by_label("heights").next().unwrap().click();
    harness.run_steps(2);
    let settings = *harness.state().bench.simulation.settings();
    assert_eq!(settings.method, tetlab_core::simulation::Method::Pbd);
    assert!(settings.active[tetlab_core::constraints::Family::HEIGHT]);
    harness.snapshot("controls_pbd_heights");
}

#[test]
fn a_bad_mesh_file_shows_an_error_and_keeps_the_scene() {
    let mut harness = workbench("cube", 2);
    let path = std::env::temp_dir().join(format!("tetlab-gui-{}.msh", std::process::id()));
    std::fs::write(&path, "$MeshFormat\n9.9 0 8\n$EndMeshFormat\n").unwrap();
    harness.get_by_label("mesh file").click();
    harness.run_steps(1);
    harness
        .get_by_label("mesh file")
        .type_text(path.to_str().unwrap());
    harness.run_steps(1);
    harness.get_by_label("Open").click();
    harness.run_steps(2);
    let error = harness.state().error.clone().expect("an error is shown");
    assert!(
        error.contains(":2: MSH version 9.9 is not supported"),
        "{error}"
    );
    assert_eq!(
        harness.state().bench.simulation.tets().len(),
        48,
        "the cube stays"
    );
}

/// "Copy link" puts a link to the state on the clipboard (and says so): the scene, the edits and
/// the camera; a second workbench opened on it shows the same body, bit for bit.
#[test]
fn copy_link_gives_a_link_that_opens_the_same_state() {
    let mut harness = workbench("cube", 2);
    harness.key_press(egui::Key::M);
    harness.run_steps(1);
    harness.get_by_label("Copy link").click();
    harness.run_steps(1);
    let copied = harness
        .output()
        .platform_output
        .commands
        .iter()
        .find_map(|command| match command {
            egui::OutputCommand::CopyText(text) => Some(text.clone()),
            _ => None,
        })
        .expect("the link is copied");
    let (page, fragment) = copied.split_once('#').expect("a fragment");
    assert_eq!(page, tetlab::gui::link::page_url());
    assert!(
        fragment.starts_with("scene=cube&resolution=2") && fragment.contains("edits=mirror"),
        "{fragment}"
    );
    harness.run_steps(1);
    harness.get_by_label_contains("link copied");

    let mut student = TetlabApp::with_preferences(Preferences::default());
    student.open_fragment(fragment);
    assert_eq!(student.error, None);
    let teacher = harness.state();
    assert_eq!(
        student.bench.simulation.positions(),
        teacher.bench.simulation.positions()
    );
    assert_eq!(student.viewport.camera, teacher.viewport.camera);
    assert_eq!(student.bench.metrics.inverted_tets, 48);
}

/// The screenshot in the README (`docs/images/workbench.png`): a corner tet of a 3³ cube inverted by
/// hand, red, with the gradient arrows of all three families pointing back.
#[test]
fn readme_screenshot() {
    let mut harness = workbench("cube", 3);
    // The solver panel's checkbox; the compare panel below has one of the same name.
    harness.get_all_by_label("heights").next().unwrap().click();
    harness.run_steps(1);
    let corner = 63;
    let (rect, camera) = (
        harness.state().viewport.rect,
        harness.state().viewport.camera,
    );
    let position = harness.state().bench.simulation.positions()[corner];
    let (at, _) = viewport::project(&camera, rect, position).unwrap();
    click_at(&mut harness, at);
    harness.key_press(egui::Key::I);
    harness.run_steps(2);
    assert!(harness.state().bench.metrics.inverted_tets >= 1);
    assert!(pixels_like(&mut harness, visual::INVERTED) > 1000);
    // The README's picture is this test's snapshot: compared like every other, and rewritten only
    // when asked for (`UPDATE_SNAPSHOTS=1`); a mismatch leaves `workbench.new.png` beside it.
    let images = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/images");
    harness.snapshot_options(
        "workbench",
        &egui_kittest::SnapshotOptions::new().output_path(images),
    );
}

/// Step-by-step mode on a lone inverted tet: J begins a substep, then projects one constraint per
/// press (highlighted in the view with its arrows), then closes the sweep; K finishes a substep.
#[test]
fn step_by_step_projects_one_constraint_per_key_press() {
    use tetlab_core::teaching::stepper::{Advanced, StepByStep};
    let mut harness = workbench("tet", 1);
    harness.key_press(egui::Key::I);
    harness.run_steps(1);
    assert_eq!(harness.state().bench.metrics.inverted_tets, 1);
    let inverted_ratio = harness.state().bench.metrics.min_volume_ratio;
    let mut expected = harness.state().bench.simulation.clone();
    expected.substep();

    harness.key_press(egui::Key::J);
    harness.run_steps(1);
    assert_eq!(
        harness.state().bench.last_advance,
        Some(Advanced::BeganSubstep)
    );
    // Six edges, then the volume: stop before the volume to see it pending.
    for _ in 0..6 {
        harness.key_press(egui::Key::J);
        harness.run_steps(1);
        assert!(matches!(
            harness.state().bench.last_advance,
            Some(Advanced::Projected(_))
        ));
    }
    let pending = harness
        .state()
        .bench
        .stepping
        .unwrap()
        .pending(&harness.state().bench.simulation)
        .expect("the volume is next");
    assert_eq!(pending.family, tetlab_core::constraints::Family::VOLUME);
    harness.get_by_label_contains("next projects volume #0");
    harness.get_by_label_contains("last: projected edges #5");
    assert!(
        pixels_like(&mut harness, tetlab::gui::geometry::PENDING) > 50,
        "the pending constraint is highlighted"
    );
    assert!(
        pixels_like(&mut harness, visual::CORRECTION) > 20,
        "with the Δx it will apply"
    );
    harness.snapshot("step_by_step");

    harness.key_press(egui::Key::K);
    harness.run_steps(1);
    let bench = &harness.state().bench;
    assert_eq!(bench.stepping, Some(StepByStep::BetweenSubsteps));
    assert_eq!(bench.simulation.positions(), expected.positions());
    assert!(
        bench.metrics.min_volume_ratio > inverted_ratio + 0.5,
        "the volume projection pushed the tet back: V/V0 {inverted_ratio} -> {}",
        bench.metrics.min_volume_ratio
    );

    harness.key_press(egui::Key::Space);
    harness.run_steps(1);
    assert!(harness.state().bench.playing && harness.state().bench.stepping.is_none());
}

/// The inspector (E) shows the selected tet's constraints with their formulas and the
/// finite-difference check.
#[test]
fn the_inspector_shows_the_numbers_of_the_selected_tet() {
    let mut harness = workbench("cube", 2);
    // The solver panel's checkbox; the compare panel below has one of the same name.
    harness.get_all_by_label("heights").next().unwrap().click();
    harness.key_press(egui::Key::I);
    harness.key_press(egui::Key::E);
    harness.run_steps(2);
    assert!(harness.state().inspector.open);
    harness.get_by_label_contains("Tet 0: particles");
    harness.get_by_label_contains("Signed volume (1)");
    harness.get_by_label_contains("C = ⅙ e₁ · (e₂ × e₃) − V");
    harness.get_by_label_contains("volume #0   C = ");
    harness.get_by_label_contains("finite-difference relative error");
    harness.snapshot("inspector");
}

/// A lesson opened from its file: the step's text, "do it" with Enter, the expected observation
/// checked live, and a later step that compares two constraint sets side by side.
#[test]
fn a_lesson_page_checks_its_observations_live_and_compares_side_by_side() {
    let mut harness = workbench("cube", 2);
    open_lesson_file(&mut harness, "02-edges-cannot-uninvert.toml");
    assert_eq!(harness.state().bench.scene.name, "tet");
    harness.get_by_label_contains("Why edges alone cannot un-invert a tet");
    harness.get_by_label_contains("[..] expect inverted_tets == 1");
    harness.key_press(egui::Key::Enter);
    harness.run_steps(2);
    assert_eq!(harness.state().bench.metrics.inverted_tets, 1);
    harness.get_by_label_contains("[ok] expect inverted_tets == 1");
    harness.snapshot("lesson_page");

    harness.key_press(egui::Key::ArrowRight);
    harness.key_press(egui::Key::ArrowRight);
    harness.run_steps(1);
    harness.get_by_label_contains("step 3 of 3");
    harness.key_press(egui::Key::Enter);
    harness.run_steps(70);
    let app = harness.state();
    let comparison = app.comparison.as_ref().expect("the step compares");
    assert!(
        !app.bench.playing,
        "the step's 60 frames played, then it paused"
    );
    assert_eq!(
        app.bench.metrics.inverted_tets, 1,
        "edges only: still inverted"
    );
    assert_eq!(
        comparison.bench.metrics.inverted_tets, 0,
        "edges + volume: recovered"
    );
    harness.get_by_label_contains("[ok] expect compare.inverted_tets == 0");
    harness.snapshot("lesson_comparison");
}

/// Classroom mode (F5): larger, the 3D view and the lesson only, driven by the keyboard.
#[test]
fn classroom_mode_shows_the_view_and_the_lesson_only() {
    let mut harness = workbench("cube", 2);
    open_lesson_file(&mut harness, "03-heights.toml");
    harness.key_press(egui::Key::F5);
    harness.run_steps(2);
    assert!(harness.state().classroom);
    assert!(
        harness.query_by_label("Playback").is_none(),
        "no side panels"
    );
    harness.key_press(egui::Key::ArrowRight);
    harness.key_press(egui::Key::Enter);
    harness.run_steps(2);
    harness.get_by_label_contains("step 2 of 4");
    assert_eq!(harness.state().bench.metrics.inverted_tets, 1);
    harness.key_press(egui::Key::V);
    harness.run_steps(2);
    assert!(
        pixels_like(&mut harness, visual::INVERTED) > 1000,
        "the inverted tet is large and red"
    );
    harness.snapshot("classroom");
    harness.key_press(egui::Key::F5);
    harness.run_steps(2);
    assert!(!harness.state().classroom);
    harness.get_by_label("Playback");
}

/// The compare panel: a second view of the same scene with other families, driven by the same
/// keys.
#[test]
fn the_compare_panel_runs_two_constraint_sets_side_by_side() {
    let mut harness = workbench("cube", 2);
    // The compare panel's "edges" checkbox, below the solver panel's; the panel is scrolled
    // down to it first (the side panel is taller than the window).
    harness.get_by_label("Compare side by side").scroll_to_me();
    harness.run();
    harness
        .get_all_by_label("edges")
        .last()
        .expect("two edges checkboxes")
        .click();
    harness.get_by_label("Compare side by side").click();
    harness.run_steps(2);
    let families = |harness: &Harness<'static, TetlabApp>| {
        let comparison = harness.state().comparison.as_ref().expect("comparing");
        Families::builtin().describe(comparison.bench.simulation.active())
    };
    assert_eq!(families(&harness), "height+volume");
    harness.get_by_label("height+volume");
    harness.get_by_label("edges+volume");
    // A solver setting reaches both sides; the families are each side's own.
    harness.get_by_label("PBD").click();
    harness.get_all_by_label("heights").next().unwrap().click();
    harness.run_steps(1);
    let app = harness.state();
    let (left, right) = (
        app.bench.simulation.settings(),
        app.comparison.as_ref().unwrap().bench.simulation.settings(),
    );
    assert_eq!(left.method, tetlab_core::simulation::Method::Pbd);
    assert_eq!(
        right.method,
        tetlab_core::simulation::Method::Pbd,
        "both sides"
    );
    assert_eq!(
        Families::builtin().describe(&left.active),
        "edges+height+volume"
    );
    assert_eq!(families(&harness), "height+volume", "its own families");
    harness.get_by_label("XPBD").click();
    harness.get_all_by_label("heights").next().unwrap().click();
    harness.run_steps(1);
    harness.key_press(egui::Key::M);
    harness.run_steps(1);
    let comparison = harness.state().comparison.as_ref().unwrap();
    assert_eq!(comparison.bench.metrics.inverted_tets, 48, "M mirrors both");
    harness.key_press(egui::Key::Space);
    harness.run_steps(30);
    let app = harness.state();
    let comparison = app.comparison.as_ref().unwrap();
    assert_eq!(
        comparison.bench.simulation.frame(),
        app.bench.simulation.frame()
    );
    assert_eq!(comparison.bench.metrics.inverted_tets, 0);
    harness.get_by_label("Stop comparing").click();
    harness.run_steps(1);
    assert!(harness.state().comparison.is_none());
}

/// "Open mesh file..." (O): a browser inside the workbench, opened in the folder of the last
/// path; a click on a file loads it.
#[test]
fn open_mesh_file_browses_and_loads_a_mesh() {
    let mut harness = workbench("cube", 2);
    harness.state_mut().controls.scene.path = "../assets/meshes/bipyramid.node".into();
    harness.get_by_label("Open mesh file...").click();
    harness.run_steps(4);
    harness.get_by_label_contains("assets/meshes");
    harness.get_by_label("bipyramid.ele");
    harness.get_by_label("bipyramid.node").click();
    harness.run_steps(2);
    assert_eq!(harness.state().bench.scene.name, "bipyramid");
    assert_eq!(harness.state().bench.simulation.tets().len(), 2);
    assert!(
        harness.query_by_label("bipyramid.ele").is_none(),
        "the browser closed"
    );
}

/// A scene file of several bodies opened by path: the bodies are simulated and drawn, the ball
/// launched. The view shows the new scene at once, though the old one was never changed (both
/// at their first revision: the view once kept drawing the old body).
#[test]
fn a_scene_file_of_several_bodies_opens_in_the_view() {
    let mut harness = workbench("cube", 2);
    open_by_path(&mut harness, "../assets/scenes/thrown.toml");
    let bench = &harness.state().bench;
    assert_eq!(bench.scene.name, "thrown");
    let names: Vec<&str> = bench
        .simulation
        .bodies()
        .iter()
        .map(|b| b.name.as_str())
        .collect();
    assert_eq!(names, ["cube", "ball", "beam"]);
    assert!(
        bench.simulation.velocities().iter().any(|v| v.y == 3.0),
        "the ball is thrown"
    );
    harness.snapshot("scene_file_bodies");
}

/// Two cubes stacked, opened as a scene file: with the contact family switched on in the solver
/// panel (which then shows the thickness and friction), the small cube rests on the large one
/// frame after frame, touching it, where without contact it would sink into it; the contacts'
/// normals are drawn where they touch.
#[test]
fn a_stack_rests_on_contact_in_the_workbench() {
    let mut harness = workbench("cube", 2);
    open_by_path(&mut harness, "../assets/scenes/stacked-cubes.toml");
    tick(&mut harness, "contact");
    assert!(
        harness.query_by_label_contains("mu_s").is_some(),
        "the friction is shown"
    );
    for _ in 0..20 {
        harness.get_by_label("Step frame").click();
        harness.run_steps(1);
    }
    let bench = &harness.state().bench;
    assert_eq!(bench.simulation.frame(), 20);
    assert!(bench.metrics.contacts > 0, "the cubes touch");
    let upper = &bench.simulation.bodies()[1];
    let lowest = bench.simulation.positions()[upper.particles.start as usize..]
        .iter()
        .map(|p| p.y)
        .fold(f64::INFINITY, f64::min);
    assert!(
        lowest > 1.0,
        "the small cube rests on the large one: {lowest}"
    );
    harness.snapshot("contact_stack");
}

/// Types `path` into the mesh-file field and presses Open.
fn open_by_path(harness: &mut Harness<'static, TetlabApp>, path: &str) {
    harness.get_by_label("mesh file").click();
    harness.run_steps(1);
    harness.get_by_label("mesh file").type_text(path);
    harness.run_steps(1);
    harness.get_by_label("Open").click();
    harness.run_steps(3);
}

/// Ticks the solver panel's checkbox `label` (the first of that label: the solver panel's is
/// above the compare panel's).
fn tick(harness: &mut Harness<'static, TetlabApp>, label: &str) {
    (harness.get_all_by_label(label).next())
        .unwrap_or_else(|| panic!("the solver panel's {label}"))
        .click();
    harness.run_steps(2);
}

/// A panel and the requests it made, drawn on its own.
struct Alone {
    panel: Box<dyn tetlab::gui::panels::Panel>,
    bench: tetlab::gui::workbench::Workbench,
    requests: Vec<tetlab::gui::request::Request>,
}

/// `panel` on a 2×2×2 cube, drawn on its own in a `width` × `height` harness.
fn alone(
    panel: Box<dyn tetlab::gui::panels::Panel>,
    width: f32,
    height: f32,
) -> Harness<'static, Alone> {
    let settings = tetlab::gui::Preferences::default().settings;
    let bench =
        tetlab::gui::workbench::Workbench::builtin(tetlab_core::scene::Builtin::Cube, 2, settings);
    let mut fonts = false;
    let mut harness = Harness::builder()
        .with_size(egui::vec2(width, height))
        .wgpu()
        .build_ui_state(
            move |ui, alone: &mut Alone| {
                if !fonts {
                    tetlab::gui::install_fonts(ui.ctx());
                    fonts = true;
                }
                let context = tetlab::gui::panels::Context::of(&alone.bench);
                alone.panel.ui(ui, &context, &mut alone.requests);
            },
            Alone {
                panel,
                bench,
                requests: Vec::new(),
            },
        );
    harness.run_steps(3);
    harness
}

/// Every side panel has the one signature of `Panel` and can be drawn, and snapshot, on its own:
/// a change to one panel changes its snapshot only. What a panel asks for comes out as requests.
#[test]
fn each_panel_is_drawn_on_its_own_and_asks_through_requests() {
    use tetlab::gui::panels::{
        compare::ComparePanel, controls::Controls, display::DisplayPanel, lesson::LessonPanel,
        readouts::Readouts, solver::SolverPanel, tools::Tools,
    };
    use tetlab::gui::request::Request;
    use tetlab::gui::shortcuts::Action;
    let panels: [(&str, Box<dyn tetlab::gui::panels::Panel>, f32); 7] = [
        ("panel_controls", Box::new(Controls::default()), 250.0),
        ("panel_solver", Box::new(SolverPanel), 300.0),
        ("panel_tools", Box::new(Tools), 140.0),
        ("panel_compare", Box::new(ComparePanel::default()), 70.0),
        ("panel_readouts", Box::new(Readouts), 450.0),
        ("panel_display", Box::new(DisplayPanel::default()), 240.0),
        ("panel_lesson", Box::new(LessonPanel::default()), 70.0),
    ];
    let mut results = egui_kittest::SnapshotResults::default();
    for (name, panel, height) in panels {
        let mut harness = alone(panel, 330.0, height);
        harness.snapshot(name);
        results.extend_harness(&mut harness);
    }
    results.unwrap();
    let mut harness = alone(Box::new(Tools), 330.0, 140.0);
    harness.get_by_label("Mirror all").click();
    harness.run_steps(1);
    assert!(matches!(
        harness.state().requests.as_slice(),
        [Request::Act(Action::Mirror)]
    ));
    let mut harness = alone(Box::new(SolverPanel), 330.0, 300.0);
    harness.get_by_label("PBD").click();
    harness.run_steps(1);
    let asked = harness.state().requests.iter().find_map(|r| match r {
        Request::Settings(settings) => Some(settings.method),
        _ => None,
    });
    assert_eq!(asked, Some(tetlab_core::simulation::Method::Pbd));
    let mut harness = alone(Box::new(Readouts), 330.0, 450.0);
    harness.get_by_label("distance from the exact step").click();
    harness.run_steps(1);
    assert!(matches!(
        harness.state().requests.as_slice(),
        [Request::ExactStep(true)]
    ));
}
