//! One simulation, two engines: the source note's claims hold on both, and everything a user
//! does to a simulation (perturb, place, pin, grab, settle, step one projection at a time)
//! works on the fast engine too, its state carried between the engines.

use glam::DVec3;
use tetlab_core::constraints::{Family, PerFamily};
use tetlab_core::measures::metrics::Metrics;
use tetlab_core::scene::{Builtin, Perturbation, Scene};
use tetlab_core::simulation::{EngineChoice, Settings, Simulation};
use tetlab_core::teaching::stepper::StepByStep;

fn simulation(
    builtin: Builtin,
    resolution: u32,
    families: &str,
    engine: EngineChoice,
) -> Simulation {
    let scene = Scene::builtin(builtin, resolution).unwrap();
    let settings = Settings {
        active: PerFamily::builtin_list(families).unwrap(),
        engine,
        substeps: 10,
        gravity: 0.0,
        ground: false,
        ..Settings::default()
    };
    let simulation = Simulation::new(&scene, settings);
    assert_eq!(simulation.engine(), engine);
    simulation
}

fn run(simulation: &mut Simulation, frames: usize) -> Metrics {
    for _ in 0..frames {
        simulation.step();
    }
    Metrics::measure_sound(simulation).expect("sound")
}

/// The source note's claims, on each engine: a mirrored cube stays inverted under edges alone,
/// and recovers under edges + heights and under edges + volume; heights alone un-invert a tet.
#[test]
fn the_source_notes_claims_hold_on_both_engines() {
    for engine in [EngineChoice::Reference, EngineChoice::Fast] {
        for (families, inverted_at_the_end) in [
            ("edges", 162),
            ("edges,height", 0),
            ("edges,volume", 0),
            ("edges,height,volume", 0),
        ] {
            let mut cube = simulation(Builtin::Cube, 3, families, engine);
            cube.perturb(Perturbation::Mirror);
            let metrics = run(&mut cube, 120);
            assert_eq!(
                metrics.inverted_tets, inverted_at_the_end,
                "{engine:?}, {families}"
            );
        }
        let mut tet = simulation(Builtin::Tet, 1, "height", engine);
        tet.perturb(Perturbation::Invert);
        let metrics = run(&mut tet, 60);
        assert_eq!(metrics.inverted_tets, 0, "{engine:?}: heights alone");
        assert!(metrics.max_edge_strain < 1e-3, "{engine:?}: {metrics:?}");
    }
}

/// Pins, a particle placed by hand and a rigid grab, on the fast engine: a pinned particle stays
/// where it is, a placed one starts from where it was put, a grabbed one follows its target and
/// keeps the target's speed when let go.
#[test]
fn edits_reach_the_fast_engine() {
    let mut cube = simulation(Builtin::Cube, 2, "edges,volume", EngineChoice::Fast);
    let mut settings = *cube.settings();
    settings.gravity = 9.81;
    settings.ground = true;
    cube.set_settings(settings);
    // Lift the cube, pin one corner: it hangs from it.
    let lifted: Vec<DVec3> = cube.positions().iter().map(|p| *p + DVec3::Y).collect();
    cube.set_positions(&lifted);
    let pinned = 26;
    cube.set_pinned(pinned, true);
    let at = cube.positions()[pinned];
    run(&mut cube, 30);
    assert_eq!(cube.positions()[pinned], at, "pinned");
    assert!(cube.positions()[0].y < lifted[0].y - 0.05, "the rest falls");

    // Placed by hand while paused: the next frame starts from there.
    let placed = cube.positions()[0] + DVec3::new(0.0, 0.0, 0.2);
    cube.place(0, placed);
    cube.step();
    assert!(
        cube.positions()[0].distance(placed) < 0.2,
        "starts from where it was put"
    );

    // Held rigidly: it is at the target after every frame, and keeps the target's speed.
    let grabbed = 3;
    let start = cube.positions()[grabbed];
    cube.grab(grabbed, start);
    for k in 1..=10 {
        let target = start + DVec3::new(0.01 * k as f64, 0.0, 0.0);
        cube.move_grab(target);
        cube.step();
        assert_eq!(
            cube.positions()[grabbed].as_vec3(),
            target.as_vec3(),
            "frame {k}"
        );
    }
    cube.release();
    let speed = cube.velocities()[grabbed].x;
    assert!(
        (speed - 0.6).abs() < 1e-6,
        "thrown at 0.01 m per frame: {speed}"
    );
    cube.step();
    assert!(cube.is_sound());
    assert_ne!(
        cube.corrections()[grabbed],
        DVec3::ZERO,
        "Δp is written back"
    );
}

/// A mirrored cube with edits settling is undone where it lies on the fast engine too, not
/// launched; without settling it is launched. (A cube of an odd resolution, mirrored on the
/// ground, can end with a tet stuck inverted on the fast engine: docs/performance.md.)
#[test]
fn edits_settle_on_the_fast_engine() {
    let highest = |settle: bool| {
        let mut cube = simulation(Builtin::Cube, 4, "edges,volume", EngineChoice::Fast);
        let mut settings = *cube.settings();
        settings.settle_edits = settle;
        settings.substeps = 100;
        settings.set_gravity(9.81);
        cube.set_settings(settings);
        cube.perturb(Perturbation::Mirror);
        let mut highest = f64::MIN;
        for _ in 0..90 {
            cube.step();
            for p in cube.positions() {
                highest = highest.max(p.y);
            }
        }
        assert_eq!(Metrics::measure(&cube).inverted_tets, 0, "settle {settle}");
        highest
    };
    let (settled, launched) = (highest(true), highest(false));
    assert!(
        settled < 1.5,
        "the 1 m cube stays near the ground: {settled} m"
    );
    assert!(
        launched > 10.0,
        "without settling it is launched: {launched} m"
    );
}

/// Step-by-step mode works on the fast engine's state and hands it back: the projections it
/// makes are the reference solver's, and the fast frames go on from where it left off.
#[test]
fn step_by_step_carries_the_state_across_the_engines() {
    let mut cube = simulation(Builtin::Cube, 2, "edges,volume", EngineChoice::Fast);
    cube.perturb(Perturbation::Mirror);
    run(&mut cube, 2);
    let before = cube.positions().to_vec();
    let mut stepper = StepByStep::default();
    stepper.advance(&mut cube); // begin a substep: predict
    for _ in 0..20 {
        stepper.advance(&mut cube);
    }
    let moved = cube
        .positions()
        .iter()
        .zip(&before)
        .filter(|(a, b)| a != b)
        .count();
    assert!(moved > 0, "the projections moved particles");
    stepper.finish(&mut cube);
    let stepped = cube.positions().to_vec();
    cube.step();
    let after: f64 = cube
        .positions()
        .iter()
        .zip(&stepped)
        .map(|(a, b)| a.distance(*b))
        .fold(0.0, f64::max);
    assert!(
        after < 0.5,
        "the fast frame goes on from the stepped state: {after}"
    );
    assert_eq!(run(&mut cube, 60).inverted_tets, 0);
}

/// Switching engines between frames carries the state: a run that switches halfway ends like
/// one that does not (the same qualitative result), and the settings reach the fast engine.
#[test]
fn switching_engines_between_frames_keeps_the_state() {
    let mut cube = simulation(
        Builtin::Cube,
        3,
        "edges,height,volume",
        EngineChoice::Reference,
    );
    cube.perturb(Perturbation::Mirror);
    run(&mut cube, 3);
    let inverted = Metrics::measure(&cube).inverted_tets;
    let mut settings = *cube.settings();
    settings.engine = EngineChoice::Fast;
    cube.set_settings(settings);
    assert_eq!(cube.engine(), EngineChoice::Fast);
    assert_eq!(
        Metrics::measure(&cube).inverted_tets,
        inverted,
        "nothing moved yet"
    );
    // A family switched off reaches the fast engine (it is rebuilt for the families in use).
    settings.active[Family::HEIGHT] = false;
    cube.set_settings(settings);
    assert_eq!(run(&mut cube, 120).inverted_tets, 0);
    settings.engine = EngineChoice::Reference;
    cube.set_settings(settings);
    assert_eq!(run(&mut cube, 10).inverted_tets, 0);
}

/// [`EngineChoice::Auto`] puts big scenes on the fast engine and the teaching scenes on the
/// reference one; every front end says which.
#[test]
fn auto_picks_by_size_and_says_which() {
    let small = Simulation::new(
        &Scene::builtin(Builtin::Cube, 3).unwrap(),
        Settings::default(),
    );
    assert_eq!(small.engine(), EngineChoice::Reference);
    assert_eq!(small.describe_engine(), "reference (f64)");
    let mut big = Simulation::new(
        &Scene::builtin(Builtin::Cube, 6).unwrap(),
        Settings::default(),
    );
    assert_eq!(
        big.engine(),
        EngineChoice::Fast,
        "{} tets",
        big.tets().len()
    );
    big.set_threads(2);
    let expected = if cfg!(feature = "parallel") {
        "fast (f32, 2 threads)"
    } else {
        "fast (f32, 1 thread)"
    };
    assert_eq!(big.describe_engine(), expected);
}
