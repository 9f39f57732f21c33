//! The as-rigid-as-possible (corotated) constraint written as a file, twice: with the polar
//! rotation (`assets/constraints/arap.toml`, C = √V₀ ‖F − R‖) and with the signed singular values
//! (`arap-singular-values.toml`, C = √V₀ ‖σ − 1‖). The check agrees with both hand gradients;
//! the two files are one C, to rounding; and the mirrored cube, every tet inverted, recovers
//! under either on both engines in every projection order tried, and on the Newton reference
//! (whose Hessians run the file's gradient tape on dual numbers, through R's exact derivative).

use glam::DVec3;
use std::path::Path;
use tetlab_core::constraint_file::ConstraintFile;
use tetlab_core::constraint_file::check::{Reflection, check};
use tetlab_core::constraints::Families;
use tetlab_core::constraints::material::Material;
use tetlab_core::measures::metrics::Metrics;
use tetlab_core::measures::outcome::Outcome;
use tetlab_core::numbers::random::SplitMix64;
use tetlab_core::scene::{Builtin, Perturbation, Scene};
use tetlab_core::simulation::{EngineChoice, Settings, Simulation};

fn load(name: &str) -> ConstraintFile {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../assets/constraints")
        .join(name);
    ConstraintFile::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn the_check_agrees_with_both_hand_gradients() {
    for (seed, name) in [(1, "arap.toml"), (2, "arap-singular-values.toml")] {
        let report = check(&load(name), 2000, seed);
        assert!(report.agrees(), "{name}: {report:?}");
        assert!(
            report.translation_invariant() && report.rotation_invariant(),
            "{name}: {report:?}"
        );
        // A mirror image is not a rotation of the rest shape: C changes.
        assert_eq!(report.reflection, Reflection::Changed, "{name}");
        assert!(report.automatic_vs_finite_difference < 1e-5, "{report:?}");
    }
}

#[test]
fn the_polar_and_the_singular_value_files_are_one_constraint() {
    let (polar, sigma) = (load("arap.toml"), load("arap-singular-values.toml"));
    let material = Material::default();
    let mut random = SplitMix64::new(5);
    let mut worst: f64 = 0.0;
    for _ in 0..500 {
        let shape: Vec<DVec3> = (0..4).map(|_| random.in_cube(1.0)).collect();
        // Deformed, a third of them inverted (p1 mirrored through the others' plane).
        let mut points: Vec<DVec3> = shape.iter().map(|q| *q + random.in_cube(0.4)).collect();
        if random.next_f64() < 0.35 {
            let normal = (points[2] - points[0])
                .cross(points[3] - points[0])
                .normalize();
            let height = normal.dot(points[1] - points[0]);
            points[1] -= 2.0 * height * normal;
        }
        let (a, b) = (
            polar.store(&shape, &material),
            sigma.store(&shape, &material),
        );
        let (ca, cb) = (polar.value(&points, 0.0, &a), sigma.value(&points, 0.0, &b));
        worst = worst.max((ca - cb).abs() / ca.abs().max(1e-3));
        // AD's gradients (through the polar rotation's derivative rule and through the
        // singular values') and the hand-written ones.
        for own in [false, true] {
            let ga = polar.gradients_of(&points, 0.0, &a, own);
            let gb = sigma.gradients_of(&points, 0.0, &b, own);
            for (x, y) in ga.iter().zip(&gb) {
                worst = worst.max((*x - *y).length() / x.length().max(1e-3));
            }
        }
    }
    println!("polar against singular values: {worst:.1e} relative");
    assert!(worst < 1e-10, "{worst:e}");
}

#[test]
fn the_mirrored_cube_recovers_on_both_engines_in_every_order() {
    let scene = Scene::builtin(Builtin::Cube, 4).unwrap();
    // The second file is the first's C (the test above): one order each, to keep the time down.
    let seeds = [vec![None, Some(1), Some(2), Some(3)], vec![None]];
    for (name, seeds) in ["arap.toml", "arap-singular-values.toml"].iter().zip(seeds) {
        let mut table = Families::builtin();
        let family = table.register_all(vec![load(name)]).unwrap()[0];
        for engine in [EngineChoice::Reference, EngineChoice::Fast] {
            for &order_seed in &seeds {
                let settings = Settings {
                    active: table.per_family(|f| f == family),
                    engine,
                    order_seed,
                    settle_edits: true,
                    ..Settings::default()
                };
                let mut simulation = Simulation::with_families(&scene, settings, table.clone());
                simulation.perturb(Perturbation::Mirror);
                let start = Metrics::measure(&simulation);
                assert_eq!(start.inverted_tets, 384);
                let mut outcome = Outcome::start(&simulation, &start);
                for _ in 0..60 {
                    simulation.step();
                    let metrics = Metrics::measure_sound(&simulation).unwrap();
                    outcome.observe(&simulation, &metrics);
                }
                println!(
                    "{name} {engine:?} seed {order_seed:?}: last inverted at frame {:?}, \
                     min V/V0 {:.3}, thrown {}",
                    outcome.last_inverted_frame,
                    outcome.last.min_volume_ratio,
                    outcome.thrown()
                );
                assert!(
                    outcome.recovered() && !outcome.thrown(),
                    "{name} {engine:?}"
                );
            }
        }
    }
}

/// The Newton reference solves each substep's implicit step with the Hessian of the file's
/// constraint (its gradient tape run on dual numbers, through the polar rotation's exact
/// derivative): on a small mirrored cube it recovers too.
#[test]
fn the_newton_reference_recovers_a_small_mirrored_cube() {
    let scene = Scene::builtin(Builtin::Cube, 2).unwrap();
    let mut table = Families::builtin();
    let family = table.register_all(vec![load("arap.toml")]).unwrap()[0];
    let settings = Settings {
        active: table.per_family(|f| f == family),
        engine: EngineChoice::Newton,
        settle_edits: true,
        ..Settings::default()
    };
    let mut simulation = Simulation::with_families(&scene, settings, table);
    simulation.perturb(Perturbation::Mirror);
    let start = Metrics::measure(&simulation);
    assert_eq!(start.inverted_tets, 48);
    let mut outcome = Outcome::start(&simulation, &start);
    // No tet inverted after frame 10; twice that is run.
    for _ in 0..20 {
        simulation.step();
        outcome.observe(&simulation, &Metrics::measure_sound(&simulation).unwrap());
    }
    println!(
        "Newton: last inverted at frame {:?}, min V/V0 {:.3}",
        outcome.last_inverted_frame, outcome.last.min_volume_ratio
    );
    assert!(outcome.recovered() && !outcome.thrown());
}
