//! What the end-of-sweep rebuild of the static-bias experiment costs a frame
//! (docs/experiments.md, "XPBD's static bias, and an experiment that removes it"): the cantilever
//! of `core/tests/static_bias.rs` (the beam scene at resolution 1, neo-Hookean E = 10 MPa,
//! ν = 0.3, 4 iterations) stepped one frame at 20 and 100 substeps on the reference engine and on
//! the engine that rebuilds the positions from the multipliers after every sweep
//! (`core/tests/support/rebuilt_engine.rs`, three fixed-point passes). `cargo bench -p
//! tetlab-core --bench static_bias`.

#[path = "../tests/support/rebuilt_engine.rs"]
mod rebuilt_engine;

use criterion::{Criterion, criterion_group, criterion_main};
use rebuilt_engine::Rebuilt;
use tetlab_core::constraints::PerFamily;
use tetlab_core::constraints::material::Material;
use tetlab_core::scene::{Builtin, Scene};
use tetlab_core::simulation::{Settings, Simulation};

/// The cantilever at `substeps`, hanging free, on the reference engine or the rebuilt one, a
/// few frames into its swing (so that every multiplier is at work).
fn cantilever(substeps: u32, rebuilt: bool) -> Simulation {
    let scene = Scene::builtin(Builtin::Beam, 1).unwrap();
    let mut settings = Settings {
        active: PerFamily::builtin_list("neohookean").unwrap(),
        substeps,
        iterations: 4,
        damping: 10.0,
        ..Settings::default()
    };
    settings.ground = false;
    settings.material = Material {
        young: 1e7,
        poisson: 0.3,
    };
    let mut simulation = Simulation::new(&scene, settings);
    if rebuilt {
        simulation.use_engine(Rebuilt::build, "rebuilt");
    }
    for _ in 0..10 {
        simulation.step();
    }
    simulation
}

fn frames(c: &mut Criterion) {
    let mut group = c.benchmark_group("cantilever frame");
    for substeps in [20, 100] {
        for (name, rebuilt) in [("xpbd", false), ("rebuilt", true)] {
            let mut simulation = cantilever(substeps, rebuilt);
            group.bench_function(format!("{name}, {substeps} substeps"), |b| {
                b.iter(|| simulation.step())
            });
        }
    }
    group.finish();
}

criterion_group!(benches, frames);
criterion_main!(benches);
