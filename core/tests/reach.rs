//! How far one projection may move a particle (`Settings::reach`, 100 rest edges of its element
//! by default): a step beyond it is skipped and counted, on both engines, and it leaves the
//! built-in families alone.

use glam::DVec3;
use std::path::Path;
use tetlab_core::constraint_file::ConstraintFile;
use tetlab_core::constraints::{Families, Family, PerFamily};
use tetlab_core::measures::metrics::Metrics;
use tetlab_core::scene::{Builtin, Perturbation, Scene};
use tetlab_core::simulation::projection::SkipCounts;
use tetlab_core::simulation::{EngineChoice, Settings, Simulation};

/// A tet squeezed to 10⁻⁴ of its size under its volume constraint alone: ∇V (its face areas)
/// all but vanishes while V − V₀ does not, so a projection would move its corners by about
/// V₀ / |∇V|. Without the reach one frame flings them 4 × 10⁵ m (the reference engine) and
/// 2 × 10⁸ m (the fast one); with it every such projection is skipped, counted, and the tet
/// stays where it is.
#[test]
fn a_step_beyond_the_reach_is_skipped_and_counted_on_both_engines() {
    for engine in [EngineChoice::Reference, EngineChoice::Fast] {
        let far = |reach: f64| {
            let scene = Scene::builtin(Builtin::Tet, 1).unwrap();
            let mut settings = Settings {
                active: PerFamily::builtin_list("volume").unwrap(),
                engine,
                reach,
                ..Settings::default()
            };
            settings.set_gravity(0.0);
            let mut simulation = Simulation::new(&scene, settings);
            let rest = simulation.rest_positions().to_vec();
            let centre = rest.iter().copied().sum::<DVec3>() / 4.0;
            let squeezed: Vec<DVec3> = rest.iter().map(|p| centre + (*p - centre) * 1e-4).collect();
            simulation.set_positions(&squeezed);
            simulation.step();
            let farthest = simulation
                .positions()
                .iter()
                .map(|p| p.distance(centre))
                .fold(0.0, f64::max);
            (farthest, simulation.skipped()[Family::VOLUME])
        };
        let (held, skipped) = far(100.0);
        assert!(held < 1e-3, "{engine:?}: held at {held} m");
        let substeps = u64::from(Settings::default().substeps);
        assert_eq!(
            skipped,
            SkipCounts {
                degenerate: 0,
                too_long: substeps
            },
            "{engine:?}: one skip per substep"
        );
        let (flung, skipped) = far(1e9);
        assert!(flung > 1e4, "{engine:?}: without a reach, flung {flung} m");
        assert!(skipped.is_zero());
    }
}

/// A body stretched far beyond the reach comes back: one corner of a tet under rigid edges
/// placed 300 rest edges away, so that its edges' corrections are about twice the reach, and
/// only they can bring it back. They pull the element together, so they are made
/// (`correct_in_reach`): the edges hold again within the first frame, the edit settling (the
/// command line's default), on both engines. (Before, measured against the rest size alone,
/// every one of them was skipped and counted, frame after frame, and the corner stayed where it
/// was put, 298-fold stretched after a second: a guard against a singular ∇C stopped the edges
/// from undoing the damage.)
#[test]
fn a_stretched_body_comes_back_under_its_edges_however_far_it_was_pulled() {
    for engine in [EngineChoice::Reference, EngineChoice::Fast] {
        let scene = Scene::builtin(Builtin::Tet, 1).unwrap();
        let mut settings = Settings {
            active: PerFamily::builtin_list("edges").unwrap(),
            engine,
            settle_edits: true,
            ..Settings::default()
        };
        settings.set_gravity(0.0);
        let mut simulation = Simulation::new(&scene, settings);
        let edge = simulation.body().mean_edge;
        let corner = simulation.positions()[0];
        simulation.place(0, corner + DVec3::new(-300.0, 0.0, 0.0) * edge);
        let before = Metrics::measure(&simulation).max_edge_strain;
        assert!(before > 250.0, "{engine:?}: stretched {before}-fold");
        let mut series = Vec::new();
        for _ in 0..5 {
            simulation.step();
            series.push(Metrics::measure(&simulation).max_edge_strain);
        }
        let after = *series.last().unwrap();
        assert!(after < 1e-3, "{engine:?}: edge strain {series:?}");
        assert_eq!(
            simulation.skipped()[Family::EDGES].too_long,
            0,
            "{engine:?}"
        );
    }
}

/// The dihedral angle's cosine with its own (right) gradient, on a flattened cube, where every
/// hinge is flat and ∇C vanishes: the code before the reach diverged at frame 1 (a coordinate at
/// −6.4 × 10⁴¹ m); now the steps beyond the reach are counted and the run stays sound.
#[test]
fn a_correct_constraint_with_a_vanishing_gradient_does_not_diverge() {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/constraints/dihedral-cosine.toml");
    let mut families = Families::builtin();
    let family = families
        .register(ConstraintFile::load(&path).unwrap())
        .unwrap();
    for engine in [EngineChoice::Reference, EngineChoice::Fast] {
        let scene = Scene::builtin(Builtin::Cube, 3).unwrap();
        let mut active = PerFamily::builtin_list("edges,volume").unwrap();
        active.set(family, true);
        let settings = Settings {
            active,
            engine,
            substeps: 10,
            ..Settings::default()
        };
        let mut simulation = Simulation::with_families(&scene, settings, families.clone());
        simulation.perturb(Perturbation::Flatten);
        for frame in 1..=30 {
            simulation.step();
            assert!(
                simulation.check().is_ok(),
                "{engine:?}: frame {frame}: {:?}",
                simulation.check()
            );
        }
        assert!(
            simulation.skipped()[family].too_long > 0,
            "{engine:?}: its singular steps are counted"
        );
    }
}

/// Every built-in family on the built-in scenes, perturbed every way, edits settling (the
/// command line's default) or not: no projection is skipped for its step, on either engine.
/// (So the reach changes no built-in result here; the hashes of `core/tests/ordering.rs`,
/// unchanged by it, say the same bit for bit. Projections with an undefined gradient are
/// skipped as they always were: a flattened cube's vertical edges have length 0.)
#[test]
fn the_reach_leaves_the_built_in_families_alone() {
    for builtin in [Builtin::Tet, Builtin::Cube, Builtin::Ball] {
        for perturbation in [
            Perturbation::Mirror,
            Perturbation::Flatten,
            Perturbation::Invert,
            Perturbation::Scramble(1),
        ] {
            for families in ["edges,volume", "edges,height,volume", "edges,neohookean"] {
                for (engine, settle_edits) in [
                    (EngineChoice::Reference, true),
                    (EngineChoice::Fast, true),
                    (EngineChoice::Reference, false),
                ] {
                    let scene = Scene::builtin(builtin, 2).unwrap();
                    let settings = Settings {
                        active: PerFamily::builtin_list(families).unwrap(),
                        engine,
                        settle_edits,
                        substeps: 20,
                        ..Settings::default()
                    };
                    let mut simulation = Simulation::new(&scene, settings);
                    simulation.perturb(perturbation);
                    for _ in 0..60 {
                        simulation.step();
                    }
                    let table = simulation.families();
                    for (family, skipped) in table.values(simulation.skipped()) {
                        assert_eq!(
                            skipped.too_long, 0,
                            "{builtin:?} {perturbation:?} {families} {engine:?} settle \
                             {settle_edits}: {family} {skipped:?}"
                        );
                    }
                }
            }
        }
    }
}
