//! What contact costs a frame (docs/performance.md, "Contact's cost"): on the scenes of
//! `assets/scenes` that drop bodies of ../shared/meshes on one another (the bunny on a ball, two
//! armadillos, twenty bunnies), the broad phase alone ([`ContactFinder::find`], once a frame)
//! beside a whole frame with contact on the fast engine (edges, volume and contact, the
//! defaults: 100 substeps), each taken a second into the fall, when bodies touch. `cargo bench
//! -p tetlab-core --bench contact`; without ../shared/meshes it says so and measures nothing.

use criterion::{Criterion, criterion_group, criterion_main};
use std::path::Path;
use tetlab_core::scene::Scene;
use tetlab_core::simulation::contact::{ContactFinder, Reach};
use tetlab_core::simulation::{EngineChoice, Settings, Simulation};

const SCENES: [&str; 3] = [
    "bunny-on-ball.toml",
    "two-armadillos.toml",
    "twenty-bunnies.toml",
];

fn contact(c: &mut Criterion) {
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/scenes");
    let mut group = c.benchmark_group("contact");
    group.sample_size(10);
    for file in SCENES {
        let scene = match Scene::from_spec(folder.join(file).to_str().unwrap(), 4) {
            Ok(scene) => scene,
            Err(e) => {
                println!("{file}: not measured ({e}; ../shared/meshes is needed)");
                continue;
            }
        };
        let mut simulation = Simulation::new(&scene, Settings::default());
        let mut settings = *simulation.settings();
        settings.active = simulation
            .families()
            .parse_list("edges,volume,contact")
            .unwrap();
        settings.engine = EngineChoice::Fast;
        simulation.set_settings(settings);
        for _ in 0..60 {
            simulation.step();
        }
        let tets = simulation.tets().len();
        let reach = Reach {
            thickness: settings.contact.thickness,
            dt: settings.dt,
            gravity: settings.gravity,
        };
        let mut finder = ContactFinder::default();
        let surface = simulation.body().contact_surface();
        let pairs = finder
            .find(
                surface,
                simulation.positions(),
                simulation.velocities(),
                reach,
            )
            .len();
        println!("{file}: {tets} tets, {pairs} pairs found at frame 60");
        group.bench_function(format!("{file}: broad phase"), |b| {
            b.iter(|| {
                finder
                    .find(
                        surface,
                        simulation.positions(),
                        simulation.velocities(),
                        reach,
                    )
                    .len()
            })
        });
        let mut stepped = simulation.clone();
        group.bench_function(format!("{file}: frame with contact"), |b| {
            b.iter(|| stepped.step())
        });
    }
    group.finish();
}

criterion_group!(benches, contact);
criterion_main!(benches);
