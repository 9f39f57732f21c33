//! Edits settle under every family, the material included: the flattened bunny
//! (`../shared/meshes/bunny.node`) under the neo-Hookean material recovers and stays within a
//! body length of where it lay with the default settings, on both engines and over 8 orderings;
//! let go without settling, its launch gains no energy.

use tetlab_core::constraints::PerFamily;
use tetlab_core::input::shared_meshes;
use tetlab_core::measures::energy_account::EnergyWatch;
use tetlab_core::measures::metrics::Metrics;
use tetlab_core::scene::{Perturbation, Scene};
use tetlab_core::simulation::{EngineChoice, Settings, Simulation};

/// The flattened bunny under the material, gravity 10 and the CLI's other defaults (edits settle
/// there unless `--no-settle-edits`: `settle`),
/// on `engine` in the order of `order_seed`; `None` when `../shared/meshes` is absent.
fn flattened_bunny(
    engine: EngineChoice,
    order_seed: Option<u64>,
    settle: bool,
) -> Option<Simulation> {
    let path = shared_meshes::for_test("bunny.node")?;
    let scene = Scene::load(&path).unwrap();
    let settings = Settings {
        active: PerFamily::builtin_list("neohookean").unwrap(),
        gravity: 10.0,
        engine,
        order_seed,
        settle_edits: settle,
        ..Settings::default()
    };
    let mut simulation = Simulation::new(&scene, settings);
    simulation.set_threads(2);
    simulation.perturb(Perturbation::Flatten);
    Some(simulation)
}

#[test]
fn the_flattened_bunny_under_the_material_settles_on_both_engines_in_8_orderings() {
    for engine in [EngineChoice::Reference, EngineChoice::Fast] {
        for seed in 1..=8 {
            let Some(mut simulation) = flattened_bunny(engine, Some(seed), true) else {
                return;
            };
            assert!(simulation.resolved().edits_settle());
            let length = simulation.body().rest_diagonal();
            let start = simulation.centre_of_mass(simulation.positions());
            let mut farthest: f64 = 0.0;
            for _ in 0..180 {
                simulation.step();
                let centre = simulation.centre_of_mass(simulation.positions());
                farthest = farthest.max(centre.distance(start));
            }
            let m = Metrics::measure_sound(&simulation).unwrap();
            let at = format!("{engine:?}, seed {seed}: {m:?}");
            assert_eq!(m.inverted_tets, 0, "{at}");
            assert!(
                farthest < length,
                "{at}: moved {farthest} m, body {length} m"
            );
        }
    }
}

#[test]
fn the_flattened_bunny_let_go_without_settling_gains_no_energy_on_either_engine() {
    for engine in [EngineChoice::Reference, EngineChoice::Fast] {
        let Some(mut simulation) = flattened_bunny(engine, None, false) else {
            return;
        };
        let mut watch = EnergyWatch::start(&simulation);
        for frame in 1..=180 {
            simulation.step();
            watch.observe(&simulation, frame);
        }
        assert_eq!(watch.gain, None, "{engine:?}: bound {}", watch.bound());
        assert_eq!(watch.released, 0.0, "{engine:?}: no rigid family is active");
    }
}
