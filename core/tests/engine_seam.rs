//! The seam every engine plugs into: a simulation owns its state and settings, an engine steps
//! the state a frame at a time and hears of an edit only by the revision it is handed. A third
//! engine written in this test (`support/reversed_engine.rs`) steps, is edited, inspected,
//! measured and walked step by step through the same calls as tetlab's own, and the settings a
//! simulation reports are the ones it was given.

#[path = "support/reversed_engine.rs"]
mod reversed_engine;

use glam::DVec3;
use reversed_engine::Reversed;
use tetlab_core::constraints::{Family, PerFamily};
use tetlab_core::measures::metrics::Metrics;
use tetlab_core::scene::{Builtin, Perturbation, Scene};
use tetlab_core::simulation::fast::FastSimulation;
use tetlab_core::simulation::{EngineChoice, Revision, Settings, Simulation};
use tetlab_core::teaching::stepper::StepByStep;

fn cube(engine: EngineChoice) -> Simulation {
    let scene = Scene::builtin(Builtin::Cube, 2).unwrap();
    let settings = Settings {
        active: PerFamily::builtin_list("edges,height,volume").unwrap(),
        substeps: 10,
        engine,
        ..Settings::default()
    };
    Simulation::new(&scene, settings)
}

/// Something done to a simulation.
type Edit = fn(&mut Simulation);

/// The revisions the test's engine saw at its last frame.
fn seen(simulation: &mut Simulation) -> (u64, u64) {
    let engine = simulation
        .engine_as::<Reversed>()
        .expect("the test's engine");
    *engine.seen.last().expect("a frame was stepped")
}

#[test]
fn every_edit_reaches_an_engine_by_the_revision_alone() {
    let mut simulation = cube(EngineChoice::Reference);
    simulation.use_engine(Reversed::build, "reversed");
    simulation.step();
    let edits: [(&str, Edit); 9] = [
        ("perturb", |s| s.perturb(Perturbation::Mirror)),
        ("place", |s| s.place(3, DVec3::new(0.1, 2.0, 0.0))),
        ("pin", |s| s.set_pinned(0, true)),
        ("grab", |s| s.grab(5, DVec3::new(0.0, 1.5, 0.0))),
        ("release", |s| s.release()),
        ("set_positions", |s| {
            let rest = s.rest_positions().to_vec();
            s.set_positions(&rest)
        }),
        ("a projection", |s| {
            let mut stepper = StepByStep::default();
            stepper.advance(s);
            stepper.advance(s);
        }),
        ("reset", |s| s.reset()),
        ("begin_substep", |s| s.begin_substep()),
    ];
    for (name, edit) in edits {
        let (body, state) = seen(&mut simulation);
        edit(&mut simulation);
        simulation.step();
        let (body_after, state_after) = seen(&mut simulation);
        assert_eq!(body_after, body, "{name}: the body is as it was");
        assert!(state_after > state, "{name}: the state's revision moved");
    }
    // Moving a held target is an input of each frame, not an edit.
    simulation.grab(5, DVec3::new(0.0, 1.5, 0.0));
    simulation.step();
    let before = seen(&mut simulation);
    simulation.move_grab(DVec3::new(0.2, 1.6, 0.0));
    simulation.step();
    assert_eq!(seen(&mut simulation), before);
    // Forces and plane strain are edits of the body.
    for (name, edit) in [
        (
            "forces",
            (|s| s.set_forces(vec![DVec3::X; 27])) as fn(&mut Simulation),
        ),
        ("plane strain", |s| s.set_plane_strain(true)),
    ] {
        let (body, _) = seen(&mut simulation);
        edit(&mut simulation);
        simulation.step();
        assert!(
            seen(&mut simulation).0 > body,
            "{name}: the body's revision moved"
        );
    }
}

#[test]
fn a_third_engine_is_edited_inspected_measured_and_stepped_like_the_others() {
    let mut simulation = cube(EngineChoice::Reference);
    simulation.use_engine(Reversed::build, "reversed");
    assert_eq!(
        simulation.describe_engine(),
        "reversed",
        "before it is built"
    );
    simulation.perturb(Perturbation::Mirror);
    for _ in 0..200 {
        simulation.step();
    }
    assert_eq!(simulation.describe_engine(), "reversed (f64, a test's)");
    let metrics = Metrics::measure_sound(&simulation).unwrap();
    assert_eq!(
        metrics.inverted_tets, 0,
        "recovers as the reference engine does"
    );
    // The inspector describes a projection on the simulation's own state.
    let projection = simulation.projection(Family::VOLUME, 0);
    assert!(projection.value.is_finite() && projection.weighted_norm > 0.0);
    // A copy keeps the engine it was given (built again on its first frame).
    let mut copy = simulation.clone();
    copy.step();
    assert_eq!(copy.describe_engine(), "reversed (f64, a test's)");
    // It walks backwards: one frame from the same state differs from the reference engine's.
    let mut reference = cube(EngineChoice::Reference);
    let mut reversed = cube(EngineChoice::Reference);
    reversed.use_engine(Reversed::build, "reversed");
    for simulation in [&mut reference, &mut reversed] {
        simulation.perturb(Perturbation::Scramble(3));
        simulation.step();
    }
    assert_ne!(reference.positions(), reversed.positions());
}

#[test]
fn the_fast_engine_takes_up_an_edit_and_is_built_again_only_for_its_body() {
    let mut simulation = cube(EngineChoice::Fast);
    let frames = |s: &mut Simulation| s.engine_as::<FastSimulation>().unwrap().frame();
    simulation.step();
    simulation.step();
    assert_eq!(frames(&mut simulation), 2);
    // An edit of the state: the same engine takes it up, and the positions it writes back start
    // from the edited ones (the body moved 5 m along x, which strains nothing).
    let moved: Vec<DVec3> = simulation
        .positions()
        .iter()
        .map(|p| *p + DVec3::X * 5.0)
        .collect();
    simulation.set_positions(&moved);
    simulation.step();
    assert_eq!(frames(&mut simulation), 3, "not built again");
    let centre = simulation.centre_of_mass(simulation.positions());
    assert!((centre.x - 5.0).abs() < 1e-3, "{centre}");
    // A change of the settings it was not built for: the same engine.
    let mut settings = *simulation.settings();
    settings.gravity = 1.0;
    settings.compliance[Family::EDGES] = 1e-6;
    simulation.set_settings(settings);
    simulation.step();
    assert_eq!(frames(&mut simulation), 4);
    // An edit of the body, or another set of families: built again.
    simulation.set_plane_strain(true);
    simulation.step();
    assert_eq!(frames(&mut simulation), 1, "built again for the body");
    settings.active[Family::HEIGHT] = false;
    simulation.set_settings(settings);
    simulation.step();
    assert_eq!(frames(&mut simulation), 1, "built again for the families");
}

#[test]
fn settings_are_what_was_set_and_what_follows_is_resolved() {
    let mut simulation = cube(EngineChoice::Reference);
    let mut settings = Settings {
        active: PerFamily::splat(true),
        ..Settings::default()
    };
    settings.compliance[Family::NEOHOOKEAN_DEVIATORIC] = 123.0;
    simulation.set_settings(settings);
    assert_eq!(simulation.settings(), &settings, "what was set");
    let resolved = simulation.resolved();
    let mu = settings.material.mu();
    assert_eq!(resolved.compliance[Family::NEOHOOKEAN_DEVIATORIC], 1.0 / mu);
    let families = simulation.families();
    assert_eq!(
        families.describe(simulation.active()),
        "edges+height+volume+neohookean+contact"
    );
    assert_eq!(simulation.active().families().count(), families.len());
    assert_eq!(
        simulation.revision(),
        Revision::default(),
        "settings edit no body or state"
    );
}
