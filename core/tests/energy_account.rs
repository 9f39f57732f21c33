//! The energy account: the material's energy is the one its constraints stand for, no shipped
//! scene gains energy under any perturbation on either engine, a launched body's energy only
//! falls, and a rise the account cannot explain is flagged with its frame and its source.

use glam::{DMat3, DVec3};
use tetlab_core::constraints::PerFamily;
use tetlab_core::measures::energy_account::{Energy, EnergyWatch};
use tetlab_core::scene::{Builtin, Perturbation, Scene};
use tetlab_core::simulation::{EngineChoice, Settings, Simulation};

/// Σ over tets of V₀ Ψ(F), the stable neo-Hookean energy written out independently:
/// Ψ = μ/2 (tr FᵀF − 3) + λ/2 ((J − γ)² − (1 − γ)²), zero at rest.
fn neo_hookean_energy(simulation: &Simulation) -> f64 {
    let material = simulation.settings().material;
    let (mu, lambda, gamma) = (material.mu(), material.lambda(), material.gamma());
    let (rest, now) = (simulation.rest_positions(), simulation.positions());
    simulation
        .tets()
        .iter()
        .map(|tet| {
            let [a, b, c, d] = tet.map(|i| rest[i as usize]);
            let dm = DMat3::from_cols(b - a, c - a, d - a);
            let [p, q, r, s] = tet.map(|i| now[i as usize]);
            let f = DMat3::from_cols(q - p, r - p, s - p) * dm.inverse();
            let frobenius =
                f.x_axis.length_squared() + f.y_axis.length_squared() + f.z_axis.length_squared();
            let j = f.determinant();
            let psi = mu / 2.0 * (frobenius - 3.0)
                + lambda / 2.0 * ((j - gamma).powi(2) - (1.0 - gamma).powi(2));
            dm.determinant().abs() / 6.0 * psi
        })
        .sum()
}

fn material_run(engine: EngineChoice, gravity: f64) -> Simulation {
    let scene = Scene::builtin(Builtin::Cube, 2).unwrap();
    let mut settings = Settings {
        active: PerFamily::builtin_list("neohookean").unwrap(),
        engine,
        ..Settings::default()
    };
    settings.set_gravity(gravity);
    Simulation::new(&scene, settings)
}

#[test]
fn the_materials_energy_is_what_its_constraints_stand_for() {
    let mut simulation = material_run(EngineChoice::Reference, 0.0);
    simulation.perturb(Perturbation::Scramble(3));
    let energy = Energy::measure(&simulation);
    let elastic: f64 = simulation.families().all().map(|f| energy.elastic[f]).sum();
    let expected = neo_hookean_energy(&simulation);
    assert!(expected > 0.0);
    assert!(
        ((elastic - expected) / expected).abs() < 1e-9,
        "the account {elastic}, V₀ Ψ {expected}"
    );
    assert_eq!(energy.kinetic, 0.0);
}

#[test]
fn a_flattened_material_cube_launched_never_gains_energy_on_either_engine() {
    for engine in [EngineChoice::Reference, EngineChoice::Fast] {
        let mut simulation = material_run(engine, 10.0);
        simulation.perturb(Perturbation::Flatten);
        let mut watch = EnergyWatch::start(&simulation);
        let start = watch.last().total;
        assert!(start > 0.0);
        for frame in 1..=120 {
            simulation.step();
            watch.observe(&simulation, frame);
        }
        assert_eq!(watch.gain, None, "{engine:?}: bound {}", watch.bound());
        assert_eq!(watch.released, 0.0, "no rigid family is active");
        assert!(watch.last().total < start, "{engine:?}");
    }
}

#[test]
fn no_shipped_scene_gains_energy_under_any_perturbation_on_either_engine_in_any_ordering() {
    let perturbations = [
        None,
        Some(Perturbation::Invert),
        Some(Perturbation::Mirror),
        Some(Perturbation::Flatten),
    ];
    for builtin in Builtin::ALL {
        let scene = Scene::builtin(builtin, 2).unwrap();
        for perturbation in perturbations {
            for engine in [EngineChoice::Reference, EngineChoice::Fast] {
                // The mesh's order and three drawn ones, edits settling (the CLI's default) or
                // not: 8 of 8 gain none.
                let runs = [None, Some(1), Some(2), Some(3)]
                    .into_iter()
                    .flat_map(|seed| [(seed, false), (seed, true)]);
                for (order_seed, settle_edits) in runs {
                    let settings = Settings {
                        engine,
                        substeps: 20,
                        order_seed,
                        settle_edits,
                        ..Settings::default()
                    };
                    let mut simulation = Simulation::new(&scene, settings);
                    if let Some(p) = perturbation {
                        simulation.perturb(p);
                    }
                    let mut watch = EnergyWatch::start(&simulation);
                    for frame in 1..=60 {
                        simulation.step();
                        watch.observe(&simulation, frame);
                    }
                    assert_eq!(
                        watch.gain,
                        None,
                        "{} {perturbation:?} on {engine:?}, order {order_seed:?}, settling \
                         {settle_edits}: bound {}",
                        scene.name,
                        watch.bound()
                    );
                }
            }
        }
    }
}

#[test]
fn a_rise_the_account_cannot_explain_is_flagged_with_its_frame_and_source() {
    // A body at rest lifted by an edit gains the height it was lifted by: the account sees it.
    let scene = Scene::builtin(Builtin::Cube, 2).unwrap();
    let mut simulation = Simulation::new(&scene, Settings::default());
    let mut watch = EnergyWatch::start(&simulation);
    for frame in 1..=5 {
        simulation.step();
        watch.observe(&simulation, frame);
    }
    assert_eq!(watch.gain, None);
    for i in 0..simulation.positions().len() {
        let lifted = simulation.positions()[i] + DVec3::Y;
        simulation.place(i, lifted);
    }
    simulation.step();
    watch.observe(&simulation, 6);
    let gain = watch.gain.clone().expect("lifting the body is a gain");
    assert_eq!((gain.frame, gain.from.as_str()), (6, "gravitational"));
    assert!(gain.amount > watch.bound());
}

/// The 2 × 2 × 2 cube under `settings` on each engine: reference, fast and the Newton reference.
fn small_cube_on_every_engine(
    settings: Settings,
) -> impl Iterator<Item = (EngineChoice, Simulation)> {
    let scene = Scene::builtin(Builtin::Cube, 2).unwrap();
    [
        EngineChoice::Reference,
        EngineChoice::Fast,
        EngineChoice::Newton,
    ]
    .into_iter()
    .map(move |engine| {
        let settings = Settings { engine, ..settings };
        (engine, Simulation::new(&scene, settings))
    })
}

/// One second (60 frames) of `simulation` under a watch: the watch, the total at the start
/// and at the end.
fn watched_second(simulation: &mut Simulation) -> (EnergyWatch, f64, f64) {
    let mut watch = EnergyWatch::start(simulation);
    let start = watch.last().total;
    for frame in 1..=60 {
        simulation.step();
        watch.observe(simulation, frame);
    }
    let end = watch.last().total;
    (watch, start, end)
}

/// Particles dropped 1 m onto the ground with nothing between them (no family active): the
/// ground stops each where it lands, so what it took is all the fall gave, E_start − E_end, less
/// what the integration itself loses (½ m g² h² a substep, under 0.1 % here), on every engine.
#[test]
fn what_the_ground_took_is_what_a_drop_onto_it_lost_on_every_engine() {
    let settings = Settings {
        active: PerFamily::builtin_list("none").unwrap(),
        settle_edits: false,
        ..Settings::default()
    };
    for (engine, mut simulation) in small_cube_on_every_engine(settings) {
        let lifted: Vec<DVec3> = (simulation.positions().iter())
            .map(|p| *p + DVec3::Y)
            .collect();
        simulation.set_positions(&lifted);
        let (watch, start, end) = watched_second(&mut simulation);
        let taken = watch.taken();
        let lost = start - end;
        assert!(lost > 0.9 * start, "{engine:?}: {start} J to {end} J");
        assert!(
            (taken.ground - lost).abs() < 2e-3 * lost,
            "{engine:?}: the ground took {} J of {lost} J lost",
            taken.ground
        );
        assert_eq!((taken.damping, taken.settling), (0.0, 0.0));
        assert_eq!(watch.gain, None, "{engine:?}");
    }
}

/// A body falling freely (no ground) under damping: what damping took is the kinetic energy it
/// removed, so the total with it added back stays where it started, less the integration's own
/// ½ m g² h² a substep; on every engine.
#[test]
fn what_damping_took_is_what_it_removed_from_a_free_fall_on_every_engine() {
    let settings = Settings {
        damping: 2.0,
        ground: false,
        ..Settings::default()
    };
    for (engine, mut simulation) in small_cube_on_every_engine(settings) {
        let (watch, start, end) = watched_second(&mut simulation);
        let taken = watch.taken();
        let fall = start - end;
        assert!(
            taken.damping > 0.1 * fall,
            "{engine:?}: {taken:?} of {fall} J"
        );
        assert!(
            (taken.damping - fall).abs() < 2e-3 * fall,
            "{engine:?}: damping took {} J, the total fell {fall} J",
            taken.damping
        );
        assert_eq!((taken.ground, taken.settling), (0.0, 0.0));
    }
}
