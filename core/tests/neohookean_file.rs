//! The neo-Hookean pair written as a constraint file (`assets/constraints/neohookean.toml`: two
//! `[[constraint]]` tables, a `pair`, each `stiffness` from the material, F from the rest shape)
//! against the built-in `neohookean`, projection by projection and outcome by outcome, on both
//! engines.
//!
//! - **Per projection.** At every tet of the states a mirrored cube passes through, C and ∇C of
//!   each of the file's two constraints, with what its tet stores, equal the built-in's to
//!   10⁻¹² relative in f64 and 10⁻⁵ in f32.
//! - **The same simulation.** The file's families are projected as a pair with the built-in's
//!   compliances, so a run of the file follows the built-in's to rounding: after 30 frames of the
//!   mirrored cube on the reference engine, every position agrees to 10⁻⁸ of the cube's size, and
//!   both recover (or neither) on each engine and under each of four order seeds.

#[path = "support/both_precisions.rs"]
mod both_precisions;
use both_precisions::Both;
use glam::DVec3;
use std::path::Path;
use tetlab_core::constraint_file::ConstraintFile;
use tetlab_core::constraints::material::Material;
use tetlab_core::constraints::{Families, Family, PerFamily};
use tetlab_core::measures::metrics::Metrics;
use tetlab_core::measures::outcome::Outcome;
use tetlab_core::scene::{Builtin, Perturbation, Scene};
use tetlab_core::simulation::{EngineChoice, Settings, Simulation};

/// The built-in table with the file's two families, and those families (deviatoric, then
/// hydrostatic).
fn table() -> (Families, [Family; 2]) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/constraints/neohookean.toml");
    let files = ConstraintFile::load_all(&path).unwrap_or_else(|e| panic!("{e}"));
    let mut families = Families::builtin();
    // What a tet stores: inverse(Dm)'s nine entries as columns (for F) and as rows (for ∇C) and s
    // for the deviatoric, s / det(Dm) for the hydrostatic (docs/gradients.md).
    assert_eq!(
        files.iter().map(|f| f.stored_len()).collect::<Vec<_>>(),
        [19, 1]
    );
    let added = families.register_all(files).unwrap();
    (families, [added[0], added[1]])
}

fn settings(active: PerFamily<bool>, engine: EngineChoice, order_seed: Option<u64>) -> Settings {
    Settings {
        active,
        engine,
        order_seed,
        settle_edits: true,
        ..Settings::default()
    }
}

#[test]
fn every_projection_of_the_file_is_the_built_ins() {
    let (table, file) = table();
    let scene = Scene::builtin(Builtin::Cube, 4).unwrap();
    let both = table.per_family(|f| f == file[0] || f == file[1]);
    let mut simulation = Simulation::with_families(
        &scene,
        settings(both, EngineChoice::Reference, None),
        table.clone(),
    );
    simulation.perturb(Perturbation::Mirror);
    let mut compared = 0;
    for frame in 0..=30 {
        if [0, 1, 2, 5, 10, 30].contains(&frame) {
            let positions = simulation.positions().to_vec();
            let mut worst = [0.0f64; 2];
            for (builtin, file) in [
                (Family::NEOHOOKEAN_DEVIATORIC, file[0]),
                (Family::NEOHOOKEAN_HYDROSTATIC, file[1]),
            ] {
                let set = simulation.constraints(file);
                let particles = table.binding(file).particles(&scene.mesh);
                for (c, tet) in particles.chunks(4).enumerate() {
                    let shape: Vec<DVec3> = tet
                        .iter()
                        .map(|&i| scene.mesh.positions[i as usize])
                        .collect();
                    let points: Vec<DVec3> = tet.iter().map(|&i| positions[i as usize]).collect();
                    let material = Material::default();
                    let rest = table.constraint(builtin).rest_value(&shape, &material);
                    assert!(
                        (set.rest()[c] - rest).abs() <= 1e-15 * rest.abs().max(1.0),
                        "the rest values: {} against {rest}",
                        set.rest()[c]
                    );
                    let at = |f: Family, stored: &[f64]| {
                        table.visit(
                            f,
                            Both {
                                points: &points,
                                rest,
                                shape: &shape,
                                stored,
                            },
                        )
                    };
                    let ours = at(builtin, &[]);
                    if ours[0].2 {
                        continue;
                    }
                    let theirs = at(file, set.stored(c));
                    compared += 1;
                    for precision in 0..2 {
                        let ((c0, g0, _), (c1, g1, _)) = (ours[precision], theirs[precision]);
                        let reach = g0.iter().map(|v| v.length()).fold(0.0, f64::max);
                        let c_scale = c0.abs().max(rest.abs()).max(reach);
                        let gap = ((c0 - c1).abs() / c_scale).max(
                            g0.iter()
                                .zip(&g1)
                                .map(|(a, b)| (*a - *b).length() / reach)
                                .fold(0.0, f64::max),
                        );
                        worst[precision] = worst[precision].max(gap);
                    }
                }
            }
            println!(
                "frame {frame}: largest relative difference {:.1e} (f64), {:.1e} (f32)",
                worst[0], worst[1]
            );
            assert!(
                worst[0] <= 1e-12 && worst[1] <= 1e-5,
                "frame {frame}: {worst:?}"
            );
        }
        simulation.step();
    }
    assert!(compared > 2000, "{compared}");
}

#[test]
fn a_run_of_the_file_follows_the_built_in_on_both_engines() {
    let (table, file) = table();
    let scene = Scene::builtin(Builtin::Cube, 4).unwrap();
    let builtin = PerFamily::builtin_list("neohookean").unwrap();
    let ours = table.per_family(|f| f == file[0] || f == file[1]);
    // Position by position, on the reference engine.
    let run = |active: PerFamily<bool>, frames: usize| {
        let mut simulation = Simulation::with_families(
            &scene,
            settings(active, EngineChoice::Reference, None),
            table.clone(),
        );
        simulation.perturb(Perturbation::Mirror);
        for _ in 0..frames {
            simulation.step();
        }
        simulation.positions().to_vec()
    };
    let (a, b) = (run(builtin, 30), run(ours, 30));
    let gap = a
        .iter()
        .zip(&b)
        .map(|(x, y)| x.distance(*y))
        .fold(0.0, f64::max);
    println!("after 30 frames the positions differ by at most {gap:.1e} m");
    assert!(gap < 1e-8, "{gap}");
    // Outcome by outcome, both engines, four orders.
    for engine in [EngineChoice::Reference, EngineChoice::Fast] {
        for order_seed in [None, Some(1), Some(2), Some(3)] {
            let outcomes: Vec<String> = [builtin, ours]
                .into_iter()
                .map(|active| {
                    let mut simulation = Simulation::with_families(
                        &scene,
                        settings(active, engine, order_seed),
                        table.clone(),
                    );
                    simulation.perturb(Perturbation::Mirror);
                    let start = Metrics::measure(&simulation);
                    let mut outcome = Outcome::start(&simulation, &start);
                    for _ in 0..60 {
                        simulation.step();
                        outcome.observe(&simulation, &Metrics::measure_sound(&simulation).unwrap());
                    }
                    format!(
                        "recovered {} thrown {}",
                        outcome.recovered(),
                        outcome.thrown()
                    )
                })
                .collect();
            println!(
                "{engine:?} seed {order_seed:?}: built-in {}; file {}",
                outcomes[0], outcomes[1]
            );
            assert_eq!(outcomes[0], outcomes[1], "{engine:?} seed {order_seed:?}");
        }
    }
}
