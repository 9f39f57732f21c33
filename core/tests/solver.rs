//! The solver: what the geometry guarantees about the source note's claims, and the properties the
//! rest of tetlab relies on (determinism, no allocation per step, pins, grabs, the ground,
//! masses, XPBD and PBD stiffness).

use glam::DVec3;
use tetlab_core::constraints::{Family, PerFamily};
use tetlab_core::measures::metrics::Metrics;
use tetlab_core::scene::mesh::TetMesh;
use tetlab_core::scene::{Builtin, Perturbation, Scene};
use tetlab_core::simulation::{
    DEFAULT_SUBSTEPS, DENSITY, EngineChoice, Method, Settings, Simulation,
};

// Counts each thread's allocations; the allocator needs `unsafe impl GlobalAlloc`.
#[allow(unsafe_code)]
#[path = "support/live_bytes.rs"]
mod live_bytes;

use live_bytes::allocations;

fn families(edges: bool, height: bool, volume: bool) -> PerFamily<bool> {
    let mut active = PerFamily::splat(false);
    active[Family::EDGES] = edges;
    active[Family::HEIGHT] = height;
    active[Family::VOLUME] = volume;
    active
}

fn run(
    builtin: Builtin,
    perturbation: Option<Perturbation>,
    settings: Settings,
    frames: usize,
) -> (Simulation, Metrics) {
    let scene = Scene::builtin(builtin, 3).unwrap();
    let mut simulation = Simulation::new(&scene, settings);
    if let Some(p) = perturbation {
        simulation.perturb(p);
    }
    for _ in 0..frames {
        simulation.step();
    }
    let metrics = Metrics::measure(&simulation);
    (simulation, metrics)
}

fn settings(active: PerFamily<bool>, gravity: f64) -> Settings {
    Settings {
        active,
        gravity,
        ground: gravity != 0.0,
        ..Settings::default()
    }
}

#[test]
fn an_inverted_tet_stays_inverted_under_edges_alone() {
    for gravity in [0.0, 9.81] {
        let (_, m) = run(
            Builtin::Tet,
            Some(Perturbation::Invert),
            settings(families(true, false, false), gravity),
            300,
        );
        assert_eq!(m.inverted_tets, 1, "gravity {gravity}");
        assert!(
            m.max_edge_strain < 1e-4,
            "the edges are satisfied: {}",
            m.max_edge_strain
        );
    }
}

/// The four heights fix only four of a tet's six shape degrees of freedom: without gravity the
/// tet comes back to its rest shape, but on the ground under gravity it un-inverts and then drifts
/// along the two free ones (docs/experiments.md has the numbers).
#[test]
fn an_inverted_tet_recovers_under_the_height_constraints_alone() {
    let (_, m) = run(
        Builtin::Tet,
        Some(Perturbation::Invert),
        settings(families(false, true, false), 0.0),
        300,
    );
    assert_eq!(m.inverted_tets, 0);
    assert!(
        (m.min_volume_ratio - 1.0).abs() < 1e-3,
        "V/V0 = {}",
        m.min_volume_ratio
    );
    let (_, m) = run(
        Builtin::Tet,
        Some(Perturbation::Invert),
        settings(families(false, true, false), 9.81),
        300,
    );
    assert_eq!(m.inverted_tets, 0);
    assert!(
        m.residual[Family::HEIGHT] < 1e-3 * m.residual[Family::EDGES],
        "the heights hold while the shape drifts"
    );
}

#[test]
fn an_inverted_tet_recovers_under_edges_and_volume() {
    for gravity in [0.0, 9.81] {
        let (_, m) = run(
            Builtin::Tet,
            Some(Perturbation::Invert),
            settings(families(true, false, true), gravity),
            300,
        );
        assert_eq!(m.inverted_tets, 0, "gravity {gravity}");
        assert!((m.min_volume_ratio - 1.0).abs() < 1e-3);
        assert!(m.max_edge_strain < 1e-3);
    }
}

#[test]
fn a_mirrored_cube_stays_fully_inverted_under_edges_alone() {
    let (simulation, m) = run(
        Builtin::Cube,
        Some(Perturbation::Mirror),
        settings(families(true, false, false), 9.81),
        300,
    );
    assert_eq!(m.inverted_tets, simulation.tets().len());
    assert!(
        (m.min_volume_ratio + 1.0).abs() < 1e-3,
        "every tet is its mirror image: {}",
        m.min_volume_ratio
    );
}

#[test]
fn a_mirrored_cube_recovers_under_edges_and_volume() {
    let (_, m) = run(
        Builtin::Cube,
        Some(Perturbation::Mirror),
        settings(families(true, false, true), 9.81),
        300,
    );
    assert_eq!(m.inverted_tets, 0);
}

/// On either engine, with a particle held and an edit settling: after the first frame (which
/// builds the fast engine), a frame allocates nothing, the fast engine's taking up of an edit
/// and its writing back included.
#[test]
fn a_step_allocates_nothing() {
    for engine in [EngineChoice::Reference, EngineChoice::Fast] {
        for method in [Method::Xpbd, Method::Pbd] {
            let scene = Scene::builtin(Builtin::Cube, 3).unwrap();
            let mut simulation = Simulation::new(
                &scene,
                Settings {
                    method,
                    engine,
                    settle_edits: true,
                    active: families(true, true, true),
                    ..Settings::default()
                },
            );
            simulation.grab(0, DVec3::new(0.0, 2.0, 0.0));
            simulation.step();
            simulation.perturb(Perturbation::Scramble(3));
            let before = allocations();
            for k in 0..5 {
                simulation.move_grab(DVec3::new(0.1 * k as f64, 2.0, 0.0));
                simulation.step();
            }
            simulation.place(5, DVec3::ONE);
            simulation.step();
            assert_eq!(allocations(), before, "{engine:?}, {method:?}");
            assert!(simulation.is_settling() || engine == EngineChoice::Reference);
        }
    }
}

/// With contact, the pairs are found again every frame: the grid holds one entry per surface
/// particle, and the pairs keep room for twice the most yet and at least twice the surface's
/// particles (how many a frame finds changes with the speeds), so a cube dropped onto another,
/// grabbed by a bottom corner and dragged across it allocates nothing once it has landed.
#[test]
fn a_step_with_contact_allocates_nothing_once_its_arrays_have_grown() {
    let text = "[[body]]\nmesh = \"cube\"\nresolution = 3\n\
                [[body]]\nmesh = \"cube\"\nresolution = 2\nscale = 0.5\n\
                rotate = [0, 30, 0]\ntranslate = [0, 0.9, 0]\n";
    let scene = Scene::parse_file(std::path::Path::new("stack.toml"), text).unwrap();
    for engine in [EngineChoice::Reference, EngineChoice::Fast] {
        let mut simulation = Simulation::new(&scene, Settings::default());
        let active = simulation
            .families()
            .parse_list("edges,volume,contact")
            .unwrap();
        simulation.set_settings(Settings {
            active,
            engine,
            ..Settings::default()
        });
        for _ in 0..30 {
            simulation.step();
        }
        // Its first particle is a bottom corner: dragged along the lower cube's top.
        let corner = scene.bodies[1].particles.start as usize;
        let at = simulation.positions()[corner];
        simulation.grab(corner, at);
        simulation.step();
        let before = allocations();
        for k in 0..10 {
            simulation.move_grab(at + DVec3::new(0.005 * k as f64, 0.0, 0.0));
            simulation.step();
        }
        assert_eq!(allocations(), before, "{engine:?}");
        assert!(
            Metrics::measure(&simulation).contacts > 0,
            "{engine:?}: the cubes touch"
        );
    }
}

#[test]
fn masses_are_lumped_from_density_times_rest_volume() {
    let scene = Scene::builtin(Builtin::Ball, 2).unwrap();
    let simulation = Simulation::new(&scene, Settings::default());
    let total_mass: f64 = simulation.inverse_masses().iter().map(|w| 1.0 / w).sum();
    let total_volume: f64 = simulation.constraints(Family::VOLUME).rest().iter().sum();
    assert!((total_mass - DENSITY * total_volume).abs() < 1e-9 * total_mass);
}

#[test]
fn pinned_particles_stay_put_and_the_beam_sags() {
    let scene = Scene::builtin(Builtin::Beam, 2).unwrap();
    assert!(!scene.pinned.is_empty());
    // A rigid beam sags only as far as its constraints are unconverged: visibly at 10 substeps
    // (at the default 100 it is 0.2 mm).
    let settings = Settings {
        substeps: 10,
        ..Settings::default()
    };
    let mut simulation = Simulation::new(&scene, settings);
    for _ in 0..60 {
        simulation.step();
    }
    for &i in &scene.pinned {
        assert_eq!(
            simulation.positions()[i as usize],
            scene.mesh.positions[i as usize]
        );
    }
    let tip_drop = (0..scene.mesh.positions.len())
        .map(|i| scene.mesh.positions[i].y - simulation.positions()[i].y)
        .fold(0.0, f64::max);
    assert!(
        tip_drop > 1e-3,
        "the free end sags under gravity: {tip_drop}"
    );
}

#[test]
fn the_ground_holds_a_falling_body() {
    let scene = Scene::builtin(Builtin::Cube, 3).unwrap();
    let mut simulation = Simulation::new(&scene, Settings::default());
    simulation.perturb(Perturbation::Scramble(1));
    for p in 0..simulation.positions().len() {
        let lifted = simulation.positions()[p] + DVec3::Y;
        simulation.place(p, lifted);
    }
    for _ in 0..120 {
        simulation.step();
        let lowest = simulation
            .positions()
            .iter()
            .map(|p| p.y)
            .fold(f64::INFINITY, f64::min);
        assert!(lowest > -1e-3, "below the ground: {lowest}");
    }
    assert!(Metrics::measure(&simulation).inverted_tets == 0);
}

#[test]
fn a_rigid_grab_carries_the_particle_and_release_hands_over_the_velocity() {
    let scene = Scene::builtin(Builtin::Cube, 2).unwrap();
    let mut simulation = Simulation::new(
        &scene,
        Settings {
            gravity: 0.0,
            ground: false,
            ..Settings::default()
        },
    );
    let start = simulation.positions()[0];
    simulation.grab(0, start);
    let step = DVec3::new(0.0, 0.0, -0.01);
    for k in 1..=10 {
        simulation.move_grab(start + step * k as f64);
        simulation.step();
        assert_eq!(simulation.positions()[0], start + step * k as f64);
    }
    let mass_while_held = simulation.inverse_masses()[0];
    simulation.release();
    assert_eq!(mass_while_held, 0.0);
    assert!(
        simulation.inverse_masses()[0] > 0.0,
        "release restores the mass"
    );
    let expected = step / simulation.settings().dt;
    assert!(
        (simulation.velocities()[0] - expected).length() < 1e-9,
        "{}",
        simulation.velocities()[0]
    );
}

#[test]
fn a_soft_grab_pulls_toward_the_target() {
    let scene = Scene::builtin(Builtin::Cube, 2).unwrap();
    let settings = Settings {
        gravity: 0.0,
        ground: false,
        grab_compliance: 1e-3,
        ..Settings::default()
    };
    let mut simulation = Simulation::new(&scene, settings);
    let start = simulation.positions()[0];
    let target = start + DVec3::new(-0.5, 0.0, 0.0);
    simulation.grab(0, target);
    simulation.step();
    let moved = simulation.positions()[0];
    assert!(moved.distance(target) < start.distance(target));
    assert!(
        moved.distance(target) > 1e-6,
        "a compliant grab does not snap"
    );
}

/// One free particle hanging from three pinned ones by three edges: a single tet.
fn hanging_tet(settings: Settings) -> Simulation {
    let scene = Scene::builtin(Builtin::Tet, 1).unwrap();
    let apex = 3;
    let mut flipped = scene.clone();
    // Hang the apex below the base: reflect it through the base plane y = 0, then lift everything.
    flipped.mesh.positions[apex].y *= -1.0;
    for p in &mut flipped.mesh.positions {
        p.y += 2.0;
    }
    let (mesh, _) = TetMesh::new(flipped.mesh.positions.clone(), flipped.mesh.tets.clone());
    let scene = Scene {
        mesh,
        pinned: vec![0, 1, 2],
        ..flipped
    };
    Simulation::new(&scene, settings)
}

fn sag(settings: Settings) -> f64 {
    let mut simulation = hanging_tet(settings);
    let rest = simulation.positions()[3].y;
    for _ in 0..600 {
        simulation.step();
    }
    rest - simulation.positions()[3].y
}

#[test]
fn xpbd_compliance_is_a_spring_whose_stiffness_does_not_depend_on_iterations() {
    let base = Settings {
        active: families(true, false, false),
        ground: false,
        damping: 5.0,
        ..Settings::default()
    };
    let alpha = 1e-5;
    let soft = |iterations| {
        sag(Settings {
            iterations,
            compliance: PerFamily::splat(alpha),
            ..base
        })
    };
    let (one, twenty) = (soft(1), soft(20));
    assert!(one > 1e-4, "a compliant edge stretches: {one}");
    assert!(
        (one - twenty).abs() < 0.02 * one,
        "1 iteration sags {one}, 20 sag {twenty}"
    );
    let softer = sag(Settings {
        compliance: PerFamily::splat(2.0 * alpha),
        ..base
    });
    assert!(
        (softer / one - 2.0).abs() < 0.05,
        "sag ∝ α: {one} then {softer}"
    );
}

#[test]
fn pbd_stiffness_is_corrected_for_the_iteration_count() {
    // A tet with its base pinned and only the volume constraint: V is linear in the apex, so each
    // PBD projection removes exactly the fraction k′ of the error, and n iterations of
    // k′ = 1 − (1 − k)^(1/n) leave 1 − k of it whatever n is.
    let k = 0.5;
    for iterations in [1, 4, 16] {
        let scene = Scene {
            pinned: vec![0, 1, 2],
            ..Scene::builtin(Builtin::Tet, 1).unwrap()
        };
        let settings = Settings {
            method: Method::Pbd,
            active: families(false, false, true),
            stiffness: PerFamily::splat(k),
            iterations,
            substeps: 1,
            gravity: 0.0,
            ground: false,
            ..Settings::default()
        };
        let mut simulation = Simulation::new(&scene, settings);
        let rest = simulation.positions()[3];
        simulation.place(3, rest - DVec3::new(0.0, 0.3, 0.0));
        let before = Metrics::measure(&simulation).volume_error;
        simulation.substep();
        let remaining = Metrics::measure(&simulation).volume_error / before;
        assert!(
            (remaining - (1.0 - k)).abs() < 1e-9,
            "{iterations} iterations left {remaining} of the error"
        );
    }
}

/// A cube of 3³ cells perturbed with `perturbation`, then run for three seconds at `substeps`: the
/// highest its centre of mass got, the frame from which none was inverted, and the frames the
/// edit took to settle.
fn after_perturbing_a_cube(
    perturbation: Perturbation,
    settle_edits: bool,
    substeps: u32,
) -> (f64, Option<usize>, Option<usize>) {
    let scene = Scene::builtin(Builtin::Cube, 3).unwrap();
    let mut simulation = Simulation::new(
        &scene,
        Settings {
            settle_edits,
            active: families(true, true, true),
            substeps,
            ..Settings::default()
        },
    );
    simulation.perturb(perturbation);
    let (mut highest, mut recovered, mut settled) = (f64::MIN, None, None);
    for frame in 0..180 {
        simulation.step();
        let positions = simulation.positions();
        let centre = positions.iter().map(|p| p.y).sum::<f64>() / positions.len() as f64;
        highest = highest.max(centre);
        if recovered.is_none() && Metrics::measure(&simulation).inverted_tets == 0 {
            recovered = Some(frame);
        }
        if settled.is_none() && !simulation.is_settling() {
            settled = Some(frame + 1);
        }
    }
    (highest, recovered, settled)
}

#[test]
fn settling_undoes_a_mirror_or_a_flatten_without_launching_the_body() {
    // At 10 and at the default 100 substeps: a rule for "settled" in Δp per substep held at 10
    // and let the cube take off at 100.
    for (perturbation, substeps) in [Perturbation::Mirror, Perturbation::Flatten]
        .into_iter()
        .flat_map(|p| [(p, 10), (p, DEFAULT_SUBSTEPS)])
    {
        let (launched, recovered, _) = after_perturbing_a_cube(perturbation, false, substeps);
        assert!(recovered.is_some());
        assert!(
            launched > 20.0,
            "{perturbation:?}: rigid snap-back becomes velocity, the cube's centre (0.5 m at \
             rest) reaches {launched} m"
        );
        let (highest, recovered, settled) = after_perturbing_a_cube(perturbation, true, substeps);
        assert!(
            recovered.is_some(),
            "{perturbation:?}: recovers when settled"
        );
        // A unit cube on the ground has its centre at most √3/2 above it (standing on a corner,
        // where a mirror sometimes leaves it).
        assert!(
            highest < 0.75f64.sqrt() + 0.05,
            "{perturbation:?} at {substeps} substeps: settled, the cube stays on the ground: \
             its centre reached {highest} m"
        );
        let settled = settled.expect("the edit settles within the three seconds");
        assert!(
            settled >= 2,
            "{perturbation:?} at {substeps} substeps: settling lasts while the violation is \
             undone, not one frame: {settled} frames"
        );
    }
}

/// A soft tet far from rest is corrected for many frames: while it settles no particle speeds
/// up, however long that takes (there is no time limit: a body still tangled when a limit of one
/// second ran out was launched at hundreds of m/s), until a frame's corrections are within the
/// tolerance; without settling, corrections are velocity.
#[test]
fn settling_never_speeds_a_particle_up_and_lasts_until_the_violation_is_undone() {
    let scene = Scene::builtin(Builtin::Tet, 1).unwrap();
    let settings = Settings {
        settle_edits: true,
        gravity: 0.0,
        ground: false,
        compliance: PerFamily::splat(1e-4),
        ..Settings::default()
    };
    let mut simulation = Simulation::new(&scene, settings);
    simulation.place(3, simulation.positions()[3] + DVec3::new(0.0, 30.0, 0.0));
    let mut frames = 0;
    while simulation.is_settling() {
        simulation.step();
        frames += 1;
        assert!(frames < 10_000, "the soft tet comes back");
        let fastest = simulation
            .velocities()
            .iter()
            .map(|v| v.length())
            .fold(0.0, f64::max);
        assert_eq!(
            fastest, 0.0,
            "at rest and without gravity, settling adds no speed"
        );
    }
    assert!(frames > 60, "a second was once the limit: {frames} frames");
    // Moved away again without settling, the tet's corrections are velocity.
    let mut settings = *simulation.settings();
    settings.settle_edits = false;
    simulation.set_settings(settings);
    simulation.place(3, simulation.positions()[3] + DVec3::new(0.0, 1.0, 0.0));
    simulation.step();
    assert!(
        simulation.velocities()[3].length() > 0.0,
        "without settling, corrections are velocity"
    );
}

#[test]
fn corrections_are_the_projection_displacements_and_conserve_momentum() {
    let scene = Scene::builtin(Builtin::Cube, 2).unwrap();
    let mut simulation = Simulation::new(
        &scene,
        Settings {
            gravity: 0.0,
            ground: false,
            active: families(true, true, true),
            ..Settings::default()
        },
    );
    simulation.perturb(Perturbation::Scramble(3));
    assert!(simulation.corrections().iter().all(|c| *c == DVec3::ZERO));
    let before = simulation.positions().to_vec();
    simulation.substep();
    let mut momentum = DVec3::ZERO;
    let mut largest: f64 = 0.0;
    for (i, correction) in simulation.corrections().iter().enumerate() {
        // At rest without gravity the prediction is the old position.
        assert!((simulation.positions()[i] - before[i] - *correction).length() < 1e-12);
        momentum += *correction / simulation.inverse_masses()[i];
        largest = largest.max(correction.length());
    }
    assert!(largest > 1e-2, "a scrambled body is corrected: {largest}");
    assert!(
        momentum.length() < 1e-9 * largest / simulation.inverse_masses()[0],
        "internal constraints move no centre of mass: Σ m Δp = {momentum}"
    );
}

/// A height constraint whose apex and two face corners are held, with the free corner where the
/// height barely depends on it (∇C → 0 there): projecting it asked for a move of |C| / |∇C|,
/// thousands of metres, and the next projections fed on it (found by the abuse runs). Such a
/// constraint is LOCKED and skipped; in the fast engine too.
#[test]
fn a_constraint_its_free_particles_can_barely_change_is_skipped() {
    // Rest: a positive tet; vertex 1 is the apex of the height kept over the face (0, 2, 3).
    let rest = vec![
        DVec3::new(0.0, -1.0, -1.0),
        DVec3::new(0.0, 1.0, 0.0),
        DVec3::new(-1.0, 0.0, 0.0),
        DVec3::new(1.0, 0.0, 0.0),
    ];
    let (mesh, _) = TetMesh::new(rest, vec![[0, 1, 2, 3]]);
    let scene = Scene {
        name: "held".into(),
        mesh,
        pinned: vec![1, 2, 3],
        notes: Vec::new(),
        bodies: Vec::new(),
    };
    let mut settings = settings(families(false, true, false), 0.0);
    settings.substeps = 1;
    let mut simulation = Simulation::new(&scene, settings);
    // The face (0, 2, 3) turns about the x axis as vertex 0 moves; at (0, ε, 1) the apex's
    // height over it changes only as ε / r² with vertex 0.
    let mut positions = simulation.positions().to_vec();
    positions[0] = DVec3::new(0.0, 1e-3, 1.0);
    simulation.set_positions(&positions);
    let fast = tetlab_core::simulation::fast::FastSimulation::new(simulation.start());
    simulation.step();
    let moved = simulation.positions()[0].distance(positions[0]);
    assert!(moved < 2.0, "the free corner was flung {moved} m");
    let mut fast = fast;
    fast.step();
    let moved = fast.positions()[0].distance(positions[0]);
    assert!(moved < 2.0, "fast engine: flung {moved} m");
}

/// What a simulation will call per projection of a constraint file's family: no allocation (the
/// compiled program's registers are on the stack).
#[test]
fn a_constraint_file_evaluates_without_allocating() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/constraints/height.toml");
    let file = tetlab_core::constraint_file::ConstraintFile::load(&path).unwrap();
    let p = [DVec3::ZERO, DVec3::new(0.2, 0.3, 1.0), DVec3::X, DVec3::Y];
    let before = allocations();
    let mut sum = 0.0;
    for _ in 0..100 {
        let e = file.evaluate_vectors(&p, 0.5, &[]);
        sum += e.value + e.gradients[1].z;
    }
    assert_eq!(allocations(), before, "allocations in 100 evaluations");
    assert!((sum - 100.0 * (1.0 - 0.5 + 1.0)).abs() < 1e-9, "{sum}");
}
