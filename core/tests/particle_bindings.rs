//! Constraint files on single particles (`applies_to = "particles"`), chosen by a condition on
//! their rest positions (`where`): `assets/constraints/pin.toml` (C = |p0 − q0|, the rest
//! position in C) and `assets/constraints/hook.toml` (C = |p0 − h| − rest, a world point in
//! C). The condition chooses by place on any mesh; the check agrees with each file's gradient
//! by hand; a mistake in a `where` is named at its place; and on both engines the pinned
//! particles stay where they were at rest and the hooked ones at their distance from the hook,
//! on a beam that sags without them; on all three engines a cube hangs from its pinned top.

use glam::DVec3;
use std::path::Path;
use tetlab_core::constraint_file::ConstraintFile;
use tetlab_core::constraint_file::check::check;
use tetlab_core::constraints::{Families, Family};
use tetlab_core::scene::{Builtin, Scene};
use tetlab_core::simulation::{EngineChoice, Settings, Simulation};

#[path = "support/example_files.rs"]
mod example_files;
use example_files::example;

#[test]
fn where_chooses_particles_by_their_rest_positions_on_any_mesh() {
    let pin = example("pin.toml");
    for n in [2, 4] {
        let cube = Scene::builtin(Builtin::Cube, n).unwrap();
        let chosen = pin.chooses(&cube.mesh.positions);
        // The top layer of a cube of n cells a side: (n + 1)² particles.
        assert_eq!(chosen.len(), (n as usize + 1).pow(2));
        let top = cube
            .mesh
            .positions
            .iter()
            .map(|p| p.y)
            .fold(f64::MIN, f64::max);
        assert!(
            chosen
                .iter()
                .all(|&i| cube.mesh.positions[i as usize].y == top)
        );
    }
    // The hook takes the top edge of the beam's far end: a line of n + 1 particles along z.
    let beam = Scene::builtin(Builtin::Beam, 4).unwrap();
    let chosen = example("hook.toml").chooses(&beam.mesh.positions);
    assert_eq!(chosen.len(), 5);
    for &i in &chosen {
        let p = beam.mesh.positions[i as usize];
        assert_eq!((p.x, p.y), (2.0, 1.5), "{p}");
    }
}

#[test]
fn the_check_agrees_with_each_hand_gradient() {
    for name in ["pin.toml", "hook.toml"] {
        let file = example(name);
        let report = check(&file, 2000, 3);
        assert!(report.agrees(), "{name}: {report:?}");
        // Tied to the world: moving the particle changes C.
        assert!(!report.translation_invariant(), "{name}: {report:?}");
    }
}

/// The error of a file of one constraint on single particles, given `where` and `value`.
fn mistake(applies_to: &str, condition: &str, rest: &str) -> String {
    let text =
        format!("name = \"w\"\napplies_to = \"{applies_to}\"\nwhere = \"{condition}\"\n{rest}");
    ConstraintFile::parse(Path::new("w.toml"), &text)
        .expect_err("a mistake")
        .to_string()
}

#[test]
fn a_mistake_in_where_is_named_at_its_place() {
    let value = "value = \"length(p0 - q0)\"\n";
    // Where the particle is now has no place in a choice made at rest.
    let e = mistake("particles", "p0.y > 1", value);
    assert!(e.starts_with("w.toml:3:10: in where: `p0`"), "{e}");
    assert!(e.contains("q0") && e.contains("rest_min"), "{e}");
    // A value, not a comparison.
    let e = mistake("particles", "q0.y + 1", value);
    assert!(e.starts_with("w.toml:3:"), "{e}");
    assert!(e.contains("comparison"), "{e}");
    // A comparison of vectors.
    let e = mistake("particles", "q0 > rest_min", value);
    assert!(e.starts_with("w.toml:3:10: in where:"), "{e}");
    assert!(e.contains("scalar"), "{e}");
    // Only single particles are chosen.
    let e = mistake("edges", "q0.y > 1", "value = \"length(p0 - p1) - rest\"\n");
    assert!(e.starts_with("w.toml:3:9:"), "{e}");
    assert!(
        e.contains("applies_to = \\\"particles\\\"") || e.contains("\"particles\""),
        "{e}"
    );
    // One particle: a gradient of p1 is not its.
    let e = mistake(
        "particles",
        "q0.y > 1",
        "value = \"length(p0 - q0)\"\n[gradient]\np1 = \"p0\"\n",
    );
    assert!(e.contains("this binding has particle p0 only"), "{e}");
    // Each projection is one particle's: no pair.
    let e = mistake(
        "particles",
        "q0.y > 1",
        "pair = [\"a\", \"b\"]\n[[constraint]]\nname = \"a\"\nvalue = \"p0.x\"\n\
         [[constraint]]\nname = \"b\"\nvalue = \"p0.y\"\n",
    );
    assert!(
        e.starts_with("w.toml:4:8:") && e.contains("each alone"),
        "{e}"
    );
}

/// The beam (its end at x = 0 held by the scene) with soft edges, `file`'s family active or
/// not, after `frames` frames on `engine`; and the family.
fn beam(file: &str, engine: EngineChoice, with_file: bool, frames: usize) -> (Simulation, Family) {
    let mut families = Families::builtin();
    let family = families.register_all(vec![example(file)]).unwrap()[0];
    let mut compliance = Settings::default().compliance;
    compliance[Family::EDGES] = 1e-6;
    let settings = Settings {
        active: families.per_family(|f| {
            f == Family::EDGES || f == Family::VOLUME || (with_file && f == family)
        }),
        compliance,
        engine,
        ..Settings::default()
    };
    let scene = Scene::builtin(Builtin::Beam, 4).unwrap();
    let mut simulation = Simulation::with_families(&scene, settings, families);
    for _ in 0..frames {
        simulation.step();
    }
    (simulation, family)
}

/// How far the far end's top edge (x = 2, y = 1.5) has sunk: the largest drop of its particles.
fn sag(simulation: &Simulation) -> f64 {
    let rest = simulation.rest_positions();
    (0..rest.len())
        .filter(|&i| rest[i].x == 2.0 && rest[i].y == 1.5)
        .map(|i| rest[i].y - simulation.positions()[i].y)
        .fold(0.0, f64::max)
}

#[test]
fn pinned_particles_stay_at_rest_and_hooked_ones_at_their_distance_on_both_engines() {
    // The tolerance of each engine: f64, and f32 with its rounding of a 2 m body.
    for (engine, tolerance) in [(EngineChoice::Reference, 1e-9), (EngineChoice::Fast, 1e-5)] {
        let (free, _) = beam("pin.toml", engine, false, 60);
        assert!(
            sag(&free) > 1e-3,
            "{engine:?}: the free end sags {}",
            sag(&free)
        );

        // Pinned by where they were at rest: the top layer, the free end's top edge with it.
        let (pinned, _) = beam("pin.toml", engine, true, 60);
        let top = example("pin.toml").chooses(pinned.rest_positions());
        let moved = top
            .iter()
            .map(|&i| pinned.positions()[i as usize].distance(pinned.rest_positions()[i as usize]))
            .fold(0.0, f64::max);
        assert!(
            moved < tolerance,
            "{engine:?}: a pinned particle moved {moved}"
        );
        assert!(sag(&pinned) < tolerance, "{engine:?}: {}", sag(&pinned));

        // Hooked: each at its rest distance from the hook at (2, 3, 0).
        let (hooked, _) = beam("hook.toml", engine, true, 60);
        let hook = DVec3::new(2.0, 3.0, 0.0);
        let chosen = example("hook.toml").chooses(hooked.rest_positions());
        assert_eq!(chosen.len(), 5);
        for &i in &chosen {
            let (now, rest) = (
                hooked.positions()[i as usize],
                hooked.rest_positions()[i as usize],
            );
            let stretch = now.distance(hook) - rest.distance(hook);
            assert!(
                stretch.abs() < tolerance,
                "{engine:?}: the rod stretched {stretch}"
            );
        }
        eprintln!(
            "{engine:?}: the free end sags {:.3e} m free, {:.1e} pinned (a pin moved {moved:.1e}), \
             {:.3e} hooked",
            sag(&free),
            sag(&pinned),
            sag(&hooked)
        );
        assert!(
            sag(&hooked) < 0.1 * sag(&free),
            "{engine:?}: hooked {} against free {}",
            sag(&hooked),
            sag(&free)
        );
    }
}

#[test]
fn a_cube_hangs_from_its_pinned_top_on_every_engine() {
    let mut families = Families::builtin();
    let pin = families.register_all(vec![example("pin.toml")]).unwrap()[0];
    let scene = Scene::builtin(Builtin::Cube, 2).unwrap();
    let top = example("pin.toml").chooses(&scene.mesh.positions);
    for (engine, tolerance) in [
        (EngineChoice::Reference, 1e-9),
        (EngineChoice::Fast, 1e-5),
        (EngineChoice::Newton, 1e-6),
    ] {
        // No ground: without the pin the cube falls.
        let fall = |pinned: bool| {
            let settings = Settings {
                active: families.per_family(|f| {
                    f == Family::EDGES || f == Family::VOLUME || (pinned && f == pin)
                }),
                engine,
                ground: false,
                ..Settings::default()
            };
            let mut simulation = Simulation::with_families(&scene, settings, families.clone());
            for _ in 0..10 {
                simulation.step();
            }
            let moved = |i: usize| simulation.positions()[i].distance(scene.mesh.positions[i]);
            let top_moved = top.iter().map(|&i| moved(i as usize)).fold(0.0, f64::max);
            let lowest_moved = (0..scene.mesh.positions.len())
                .map(moved)
                .fold(0.0, f64::max);
            (top_moved, lowest_moved)
        };
        let (free_top, _) = fall(false);
        assert!(
            free_top > 0.1,
            "{engine:?}: the free cube falls ({free_top} m)"
        );
        let (top_moved, any_moved) = fall(true);
        assert!(
            top_moved < tolerance,
            "{engine:?}: the pinned top moved {top_moved}"
        );
        // The rest hangs from it, stretched by what one iteration leaves of the rigid edges
        // and volume (micrometres), where the free cube fell more than 0.1 m.
        eprintln!(
            "{engine:?}: free fall {free_top:.3} m; pinned top {top_moved:.1e} m, any particle {any_moved:.1e} m"
        );
        assert!(any_moved < 1e-3, "{engine:?}: a particle moved {any_moved}");
    }
}
