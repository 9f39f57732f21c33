//! The Newton reference against answers worked out by hand, and XPBD against it: a tet's apex
//! pulled against a compliant volume (linear in the apex: the answer in closed form) and against
//! three compliant edges (one scalar equation by symmetry), a rigid volume held by the augmented
//! Lagrangian, free fall, and XPBD's static answer approaching the exact one of the same mesh as
//! its iterations grow.

use glam::DVec3;
use tetlab_core::constraints::{Family, PerFamily};
use tetlab_core::scene::mesh::TetMesh;
use tetlab_core::scene::{Builtin, Perturbation, Scene};
use tetlab_core::simulation::newton::{NewtonEngine, Options, equilibrium};
use tetlab_core::simulation::{EngineChoice, Settings, Simulation};

/// A regular tet of edge 1 with its base (0, 1, 2) in the plane y = 0 around the y axis and its
/// apex 3 above, the base pinned.
fn apex_tet() -> Scene {
    let r = 1.0 / 3f64.sqrt();
    let base: Vec<DVec3> = (0..3)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / 3.0;
            DVec3::new(r * a.cos(), 0.0, r * a.sin())
        })
        .collect();
    let height = (2.0f64 / 3.0).sqrt();
    let mut positions = base;
    positions.push(DVec3::new(0.0, height, 0.0));
    // Oriented so that its signed volume is positive.
    let tets = vec![[0, 2, 1, 3]];
    Scene {
        name: "apex".into(),
        mesh: TetMesh { positions, tets },
        pinned: vec![0, 1, 2],
        notes: Vec::new(),
        bodies: Vec::new(),
    }
}

/// The apex tet with `families`, their compliance `alpha`, no gravity, and `force` on the apex.
fn pulled(families: &str, alpha: f64, force: DVec3) -> Simulation {
    let mut settings = Settings {
        active: PerFamily::builtin_list(families).unwrap(),
        ..Settings::default()
    };
    settings.set_gravity(0.0);
    for family in settings.active.families() {
        settings.compliance[family] = alpha;
    }
    let mut simulation = Simulation::new(&apex_tet(), settings);
    simulation.set_forces(vec![DVec3::ZERO, DVec3::ZERO, DVec3::ZERO, force]);
    simulation
}

#[test]
fn a_compliant_volume_gives_way_by_alpha_times_the_force_over_its_gradient_squared() {
    // C = V − V₀ is linear in the apex, ∇C = a its face's area vector / 3: the apex moves along a
    // by δ = α F / |a|², where C / α · |a| = F. The volume leaves the apex free to slide along
    // its face, where no force pulls: Newton's steps do not move it there.
    let (alpha, force) = (2e-3, 0.05);
    let simulation = pulled("volume", alpha, DVec3::Y * force);
    let rest = simulation.rest_positions().to_vec();
    let tet = [rest[0], rest[2], rest[1], rest[3]];
    let a = (tet[1] - tet[0]).cross(tet[2] - tet[0]) / 6.0;
    assert!(
        a.normalize().dot(DVec3::Y) > 1.0 - 1e-12,
        "the base's normal is y"
    );
    let expected = rest[3] + DVec3::Y * alpha * force / a.length_squared();
    let (x, report) = equilibrium(simulation.start(), &Options::default()).unwrap();
    assert!(report.converged && report.residual <= 1e-10, "{report:?}");
    assert!(
        (x[3] - expected).length() < 1e-12,
        "{} against {expected}",
        x[3]
    );
    for i in 0..3 {
        assert_eq!(x[i], rest[i], "the base is pinned");
    }
}

#[test]
fn three_compliant_edges_hold_the_apex_where_their_pull_balances_the_force() {
    // By symmetry the apex stays on the axis, at height z with ℓ = √(r² + z²) for each edge:
    // 3 (ℓ − 1) / α · z / ℓ = F. Solved by bisection to rounding.
    let (alpha, force) = (0.05, 0.4);
    let simulation = pulled("edges", alpha, DVec3::Y * force);
    let r2 = 1.0 / 3.0;
    let balance = |z: f64| {
        let l = (r2 + z * z).sqrt();
        3.0 * (l - 1.0) / alpha * z / l - force
    };
    let (mut lo, mut hi) = ((2.0f64 / 3.0).sqrt(), 3.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if balance(mid) > 0.0 {
            hi = mid
        } else {
            lo = mid
        }
    }
    let (x, report) = equilibrium(simulation.start(), &Options::default()).unwrap();
    assert!(report.converged, "{report:?}");
    let z = 0.5 * (lo + hi);
    assert!((x[3].y - z).abs() < 1e-11 * z, "{} against {z}", x[3].y);
    assert!(
        x[3].x.abs() < 1e-12 && x[3].z.abs() < 1e-12,
        "on the axis: {}",
        x[3]
    );
}

#[test]
fn a_rigid_volume_is_held_by_the_augmented_lagrangian() {
    // The volume is rigid and the edges compliant: a sideways pull moves the apex in its plane
    // only (the volume keeps its height), to where the edges balance the pull.
    let (alpha, force) = (0.05, DVec3::new(0.3, 0.0, 0.1));
    let simulation = pulled("edges,volume", alpha, DVec3::ZERO);
    let mut settings = *simulation.settings();
    settings.compliance[Family::VOLUME] = 0.0;
    let mut simulation = Simulation::new(&apex_tet(), settings);
    simulation.set_forces(vec![DVec3::ZERO, DVec3::ZERO, DVec3::ZERO, force]);
    let (x, report) = equilibrium(simulation.start(), &Options::default()).unwrap();
    assert!(report.converged && report.violation <= 1e-10, "{report:?}");
    let rest = simulation.rest_positions();
    // |C| ≤ 10⁻¹⁰ (the tet's size is 1) allows the height to move by |C| / |∇C|, |∇C| = 0.144.
    assert!(
        (x[3].y - rest[3].y).abs() < 1e-9,
        "the volume holds the height: {}",
        x[3]
    );
    assert!((x[3] - rest[3]).length() > 1e-3, "the apex moved sideways");
    // The edges' pull balances the force sideways.
    let mut pull = DVec3::ZERO;
    for &b in &rest[..3] {
        let edge = x[3] - b;
        let l = edge.length();
        pull += -(l - (rest[3] - b).length()) / alpha * edge / l;
    }
    let sideways = |v: DVec3| DVec3::new(v.x, 0.0, v.z);
    assert!((sideways(pull) + sideways(force)).length() < 1e-9, "{pull}");
}

#[test]
fn in_free_fall_the_implicit_step_is_the_prediction() {
    let scene = Scene::builtin(Builtin::Cube, 2).unwrap();
    let settings = Settings {
        active: PerFamily::builtin_list("none").unwrap(),
        ground: false,
        substeps: 5,
        ..Settings::default()
    };
    let mut reference = Simulation::new(&scene, settings);
    let mut newton = Simulation::new(
        &scene,
        Settings {
            engine: EngineChoice::Newton,
            ..settings
        },
    );
    for _ in 0..3 {
        reference.step();
        newton.step();
    }
    assert_eq!(reference.positions(), newton.positions());
    assert!(newton.describe_engine().starts_with("newton"));
}

#[test]
fn xpbd_approaches_the_implicit_step_as_its_substeps_shorten() {
    // One frame from the same scrambled state, on a soft cube. XPBD's sweeps do not converge to
    // the implicit step the Newton reference solves: each correction is added along ∇C at the
    // moment it is made, and what is left is XPBD's bias, which shrinks with the substep as
    // (c h / L)². More sweeps bring it down to that bias; shorter substeps bring the bias down.
    let scene = Scene::builtin(Builtin::Cube, 2).unwrap();
    let run = |engine, substeps, iterations| {
        let mut settings = Settings {
            active: PerFamily::builtin_list("edges,volume").unwrap(),
            substeps,
            iterations,
            engine,
            ..Settings::default()
        };
        settings.compliance[Family::EDGES] = 1e-3;
        settings.compliance[Family::VOLUME] = 1e-2;
        let mut simulation = Simulation::new(&scene, settings);
        simulation.perturb(Perturbation::Scramble(7));
        simulation.step();
        simulation
    };
    let gap = |substeps, iterations| {
        let exact = run(EngineChoice::Newton, substeps, 1);
        let xpbd = run(EngineChoice::Reference, substeps, iterations);
        (xpbd.positions().iter().zip(exact.positions()))
            .map(|(a, b)| a.distance(*b))
            .fold(0.0, f64::max)
    };
    let (one, ten, hundred) = (gap(5, 1), gap(5, 10), gap(5, 100));
    let (twenty, eighty) = (gap(20, 100), gap(80, 100));
    println!(
        "largest distance from the implicit step, 5 substeps: 1 sweep {one:.3e}, 10 {ten:.3e}, \
         100 {hundred:.3e}; 100 sweeps at 20 substeps {twenty:.3e}, at 80 {eighty:.3e}"
    );
    assert!(ten < one && hundred <= ten, "{one} {ten} {hundred}");
    assert!(
        twenty < hundred / 4.0 && eighty < twenty / 4.0,
        "{hundred} {twenty} {eighty}"
    );
    let mut exact = run(EngineChoice::Newton, 20, 1);
    let newton = exact.engine_as::<NewtonEngine>().unwrap();
    let report = newton.last_report();
    assert!(
        report.converged && newton.unconverged() == 0,
        "{report:?}, {}",
        newton.unconverged()
    );
}
