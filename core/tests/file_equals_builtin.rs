//! One family, two routes: the source note's edge, height and volume written as constraint files
//! (`assets/constraints/`) against the built-in families, projection by projection and outcome
//! by outcome.
//!
//! - **Per projection.** At every constraint of the states a mirrored cube and a flattened bunny
//!   pass through on their way back, C and ∇C of each file (its gradient by automatic
//!   differentiation, and its own with `use_gradient = true`) equal the built-in's to 10⁻¹²
//!   relative in f64 and to 10⁻⁵ in f32, the fast engine's precision.
//! - **The same outcome.** Simulated, the files recover a mirrored cube and a flattened bunny
//!   where the built-ins do, on both engines.

#[path = "support/both_precisions.rs"]
mod both_precisions;
use both_precisions::Both;
use glam::DVec3;
use std::path::{Path, PathBuf};
use std::sync::LazyLock;
use tetlab_core::constraint_file::ConstraintFile;
use tetlab_core::constraints::material::Material;
use tetlab_core::constraints::{Families, Family, PerFamily};
use tetlab_core::input::shared_meshes;
use tetlab_core::measures::metrics::Metrics;
use tetlab_core::measures::outcome::Outcome;
use tetlab_core::scene::mesh::TetMesh;
use tetlab_core::scene::{Builtin, Perturbation, Scene};
use tetlab_core::simulation::{EngineChoice, Settings, Simulation};

fn asset(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../assets/constraints")
        .join(name)
}

/// A built-in family and the same family read from a file, by AD and by its own gradient.
struct Route {
    builtin: Family,
    by_ad: Family,
    own: Family,
}

/// The files' families, in one table ([`table`]).
static ROUTES: LazyLock<(Families, Vec<Route>)> = LazyLock::new(|| {
    let mut table = Families::builtin();
    let mut routes = Vec::new();
    for (builtin, file) in [
        (Family::EDGES, "edge.toml"),
        (Family::HEIGHT, "height.toml"),
        (Family::VOLUME, "volume.toml"),
    ] {
        let text = std::fs::read_to_string(asset(file)).unwrap();
        let name = text
            .lines()
            .find_map(|l| l.strip_prefix("name = "))
            .unwrap()
            .to_string();
        let own = text.replacen(
            &format!("name = {name}"),
            &format!(
                "name = {}\nuse_gradient = true",
                name.replace("my-", "own-")
            ),
            1,
        );
        let mut parse = |text: &str, path: &str| {
            table
                .register(ConstraintFile::parse(Path::new(path), text).unwrap())
                .unwrap()
        };
        routes.push(Route {
            builtin,
            by_ad: parse(&text, file),
            own: parse(&own, &format!("own-{file}")),
        });
    }
    (table, routes)
});

/// The table the routes' families are in.
fn table() -> &'static Families {
    &ROUTES.0
}

/// The largest relative differences, f64 and f32, over every constraint of `route` at
/// `positions`, and the constraints compared.
fn differences(route: &Route, mesh: &TetMesh, positions: &[DVec3]) -> ([f64; 2], [f64; 2], usize) {
    let family = route.builtin;
    let table = table();
    let arity = table.arity(family);
    let particles = table.binding(family).particles(mesh);
    let mut worst = [0.0f64; 2];
    let mut worst_own = [0.0f64; 2];
    let mut compared = 0;
    for constraint in particles.chunks(arity) {
        let shape: Vec<DVec3> = constraint
            .iter()
            .map(|&i| mesh.positions[i as usize])
            .collect();
        let points: Vec<DVec3> = constraint.iter().map(|&i| positions[i as usize]).collect();
        let rest = table
            .constraint(family)
            .rest_value(&shape, &Material::default());
        let at = |f: Family| {
            table.visit(
                f,
                Both {
                    points: &points,
                    rest,
                    shape: &shape,
                    stored: &[],
                },
            )
        };
        let builtin = at(family);
        if builtin[0].2 {
            continue;
        }
        compared += 1;
        for (file, worst) in [(route.by_ad, &mut worst), (route.own, &mut worst_own)] {
            let file = at(file);
            for precision in 0..2 {
                let (c, g, _) = builtin[precision];
                let (fc, fg, _) = file[precision];
                // C relative to the constraint's own size (|C|, its rest value, ∇C times an
                // edge); ∇C relative to its largest particle's.
                let reach = g.iter().map(|v| v.length()).fold(0.0, f64::max);
                let size = shape[0].distance(shape[1]);
                let c_scale = c.abs().max(rest.abs()).max(reach * size);
                let gap = ((c - fc).abs() / c_scale).max(
                    g.iter()
                        .zip(&fg)
                        .map(|(a, b)| (*a - *b).length() / reach)
                        .fold(0.0, f64::max),
                );
                worst[precision] = worst[precision].max(gap);
            }
        }
    }
    (worst, worst_own, compared)
}

/// The states a body passes through on its way back: the positions after each of `frames`
/// frames of the built-in edges, heights and volume (the command line's settings).
fn states(scene: &Scene, perturbation: Perturbation, frames: &[u64]) -> Vec<Vec<DVec3>> {
    let settings = Settings {
        active: PerFamily::builtin_list("edges,height,volume").unwrap(),
        engine: EngineChoice::Reference,
        settle_edits: true,
        ..Settings::default()
    };
    let mut simulation = Simulation::with_families(scene, settings, table().clone());
    simulation.perturb(perturbation);
    let mut out = Vec::new();
    for frame in 0..=*frames.iter().max().unwrap() {
        if frames.contains(&frame) {
            out.push(simulation.positions().to_vec());
        }
        simulation.step();
    }
    out
}

fn scenes() -> Vec<(Scene, Perturbation)> {
    let mut scenes = vec![(
        Scene::builtin(Builtin::Cube, 4).unwrap(),
        Perturbation::Mirror,
    )];
    if let Some(bunny) = shared_meshes::for_test("bunny.node") {
        scenes.push((Scene::load(&bunny).unwrap(), Perturbation::Flatten));
    }
    scenes
}

#[test]
fn every_projection_of_a_file_is_the_built_ins() {
    for (scene, perturbation) in scenes() {
        for positions in states(&scene, perturbation, &[0, 1, 2, 5, 20, 60]) {
            for route in ROUTES.1.iter() {
                let (ad, own, compared) = differences(route, &scene.mesh, &positions);
                println!(
                    "{} {perturbation:?}, {}: {compared} constraints; by AD {:.1e} (f64) {:.1e} (f32), its own gradient {:.1e} {:.1e}",
                    scene.name,
                    table().name(route.builtin),
                    ad[0],
                    ad[1],
                    own[0],
                    own[1]
                );
                assert!(compared > 0);
                for (what, [f64s, f32s]) in [("by AD", ad), ("its own gradient", own)] {
                    assert!(
                        f64s <= 1e-12,
                        "{}: {what}: f64 {f64s:e}",
                        table().name(route.builtin)
                    );
                    assert!(
                        f32s <= 1e-5,
                        "{}: {what}: f32 {f32s:e}",
                        table().name(route.builtin)
                    );
                }
            }
        }
    }
}

/// The outcome of a file is the built-in's. The mirrored cube is a knife edge (its recovery
/// hangs on the order of the projections: docs/performance.md, "The engines' contract"): under
/// some orderings edges + heights + volume lock into a tangle that stays, whichever route
/// computes them. Each family's order is drawn from the seed and its place in the table, so a
/// route's families see other orderings than the built-in's for the same seed; measured over
/// seeds 1…16 (60 frames), the built-in recovers in 16, the file by AD in 16 and the file's own
/// gradient in 14 on both engines, and with the two files' places swapped the by-AD file in 14
/// and 16 and its own gradient in 15: the failures go with the places (the orderings), not with
/// how ∇C is computed. So there each route runs under 16 order seeds and the counts of
/// recoveries may differ by what a different draw of orderings gives, 2 of 16. The flattened
/// bunny is not on an edge: one ordering each, and the outcomes must agree.
#[test]
fn a_file_recovers_where_the_built_in_does_on_both_engines() {
    let routes = &ROUTES.1;
    for (scene, perturbation) in scenes() {
        let seeds: Vec<Option<u64>> = if scene.name == "cube" {
            (1..=16).map(Some).collect()
        } else {
            vec![None]
        };
        for engine in [EngineChoice::Reference, EngineChoice::Fast] {
            let mut recovered = Vec::new();
            for pick in [
                |r: &Route| r.builtin,
                |r: &Route| r.by_ad,
                |r: &Route| r.own,
            ] {
                let families: Vec<Family> = routes.iter().map(pick).collect();
                let mut count = 0;
                for &order_seed in &seeds {
                    let settings = Settings {
                        active: table().per_family(|f| families.contains(&f)),
                        engine,
                        settle_edits: true,
                        order_seed,
                        ..Settings::default()
                    };
                    let mut simulation =
                        Simulation::with_families(&scene, settings, table().clone());
                    simulation.perturb(perturbation);
                    let start = Metrics::measure(&simulation);
                    let mut outcome = Outcome::start(&simulation, &start);
                    for _ in 0..60 {
                        simulation.step();
                        outcome.observe(&simulation, &Metrics::measure_sound(&simulation).unwrap());
                    }
                    println!(
                        "{} {engine:?} {families:?} seed {order_seed:?}: {}",
                        scene.name,
                        outcome.describe()
                    );
                    count += usize::from(outcome.recovered() && !outcome.thrown());
                }
                recovered.push(count);
            }
            let spread = if seeds.len() > 1 { 2 } else { 0 };
            for (route, &count) in ["by AD", "own gradient"].iter().zip(&recovered[1..]) {
                assert!(
                    count.abs_diff(recovered[0]) <= spread,
                    "{} on {engine:?}: the file ({route}) recovers in {count} of {}, the built-in in {}",
                    scene.name,
                    seeds.len(),
                    recovered[0]
                );
            }
        }
    }
}
