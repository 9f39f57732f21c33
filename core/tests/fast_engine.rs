//! The fast engine against the reference one it is built from: the same constraints coloured
//! and renumbered, the same outcomes, the same bits on any number of threads, and what it counts.

use tetlab_core::constraints::{Family, PerFamily};
use tetlab_core::measures::metrics::Metrics;
use tetlab_core::scene::{Builtin, Perturbation, Scene};
#[cfg(feature = "parallel")]
use tetlab_core::simulation::fast::PARALLEL_MIN;
use tetlab_core::simulation::fast::{FastSimulation, Order};
use tetlab_core::simulation::{Settings, Simulation};

fn cube(resolution: u32, active: PerFamily<bool>) -> Simulation {
    let scene = Scene::builtin(Builtin::Cube, resolution).unwrap();
    Simulation::new(
        &scene,
        Settings {
            active,
            ..Settings::default()
        },
    )
}

#[test]
fn colours_share_no_particle_and_cover_every_constraint_once() {
    let simulation = cube(4, PerFamily::splat(true));
    let fast = FastSimulation::new(simulation.start());
    let n = simulation.positions().len();
    for family in Family::builtins() {
        assert!(fast.batches(family).colouring_is_valid(n), "{family}");
        let set = simulation.constraints(family);
        assert_eq!(fast.batches(family).len(), set.len(), "{family}");
    }
    let volumes = simulation.constraints(Family::VOLUME);
    let mut before: Vec<&[u32]> = (0..volumes.len()).map(|c| volumes.particles(c)).collect();
    let renumbered: Vec<[u32; 4]> = fast
        .batches(Family::VOLUME)
        .constraints()
        .map(|(p, _)| p.map(|i| fast.original()[i as usize]))
        .collect();
    let mut after: Vec<&[u32]> = renumbered.iter().map(|p| &p[..]).collect();
    before.sort_unstable();
    after.sort_unstable();
    assert_eq!(before, after, "the same constraints, renumbered");
}

#[test]
fn a_mirrored_cube_recovers_on_the_fast_path_as_on_the_reference() {
    let mut reference = cube(3, PerFamily::splat(true));
    reference.set_settings(Settings {
        settle_edits: false,
        ..*reference.settings()
    });
    reference.perturb(Perturbation::Mirror);
    let mut fast = FastSimulation::new(reference.start());
    for _ in 0..60 {
        reference.step();
        fast.step();
    }
    let mut check = reference.clone();
    check.set_positions(&fast.positions());
    assert_eq!(Metrics::measure(&reference).inverted_tets, 0);
    assert_eq!(Metrics::measure(&check).inverted_tets, 0);
}

#[test]
fn edges_alone_leave_a_mirrored_cube_inverted_on_the_fast_path_too() {
    let mut reference = cube(3, PerFamily::builtin_list("edges").unwrap());
    reference.perturb(Perturbation::Mirror);
    let mut fast = FastSimulation::new(reference.start());
    for _ in 0..60 {
        fast.step();
    }
    let mut check = reference.clone();
    check.set_positions(&fast.positions());
    assert_eq!(
        Metrics::measure(&check).inverted_tets,
        reference.tets().len()
    );
}

/// The threads share out a level's groups of regions and the last level's large colours, each
/// taking a contiguous part: two and three threads (parts of unequal sizes) give the bits of one,
/// in either order.
#[cfg(feature = "parallel")]
#[test]
fn two_and_three_threads_give_the_same_bits_as_one() {
    // Cubes of 4,913 and 17,576 particles: 2 and 8 regions, so one level of groups and three
    // before the last (three threads share two groups, and eight unevenly).
    for (resolution, regions) in [(16, 2), (25, 8)] {
        let mut reference = cube(resolution, PerFamily::builtin_list("edges,volume").unwrap());
        reference.set_settings(Settings {
            substeps: 10,
            ..*reference.settings()
        });
        reference.perturb(Perturbation::Scramble(4));
        let fast = FastSimulation::new(reference.start());
        assert_eq!(fast.batches(Family::VOLUME).regions(), regions);
        the_same_bits_on_any_number_of_threads(&reference);
    }
}

#[cfg(feature = "parallel")]
fn the_same_bits_on_any_number_of_threads(reference: &Simulation) {
    for order in [Order::GaussSeidel, Order::Jacobi { relaxation: 1.5 }] {
        let mut one = FastSimulation::new(reference.start());
        one.set_order(order);
        for _ in 0..5 {
            one.step();
        }
        for threads in [2, 3] {
            let mut many = FastSimulation::new(tetlab_core::simulation::Start {
                threads,
                ..reference.start()
            });
            many.set_order(order);
            assert_eq!(many.threads(), threads);
            let volume = many.batches(Family::VOLUME);
            assert!(
                volume.regions() > 1 || volume.colours().iter().any(|c| c.elements >= PARALLEL_MIN),
                "the threads share groups, or some colour is large enough to be shared"
            );
            for _ in 0..5 {
                many.step();
            }
            assert_eq!(
                one.positions(),
                many.positions(),
                "{order:?}, {threads} threads"
            );
        }
    }
}

#[test]
fn the_threads_keep_mostly_to_their_own_particles() {
    // Each thread projects its own regions through all their colours, then a large colour of the
    // last level is shared in contiguous parts (a colour's elements are sorted by their lowest
    // particle in Morton order, so a part is a region of the body): only the lines of particles
    // at the cut between the regions were written by another thread since this one last touched
    // them. (Shares dealt batch by batch in turn would find about half their lines written by
    // another thread.)
    let simulation = cube(15, PerFamily::builtin_list("edges,volume").unwrap());
    let fast = FastSimulation::new(simulation.start());
    for family in [Family::EDGES, Family::VOLUME] {
        assert_eq!(fast.lines_from_other_threads(family, 1), (0, 0), "{family}");
        let fraction = |threads| {
            let (other, lines) = fast.lines_from_other_threads(family, threads);
            assert!(lines > 0 && other <= lines, "{family}: {other} of {lines}");
            other as f64 / lines as f64
        };
        let (two, three) = (fraction(2), fraction(3));
        assert!(two > 0.0 && two < 0.15, "{family}, two threads: {two}");
        assert!(
            three > two,
            "{family}: three threads have more borders ({three} ≤ {two})"
        );
    }
}

#[test]
fn a_mirrored_cube_recovers_in_jacobi_order_too() {
    let mut reference = cube(3, PerFamily::splat(true));
    reference.perturb(Perturbation::Mirror);
    let mut fast = FastSimulation::new(reference.start());
    fast.set_order(Order::Jacobi { relaxation: 1.0 });
    assert_eq!(fast.order(), Order::Jacobi { relaxation: 1.0 });
    for _ in 0..60 {
        fast.step();
    }
    let mut check = reference.clone();
    check.set_positions(&fast.positions());
    assert!(fast.is_sound());
    assert_eq!(Metrics::measure(&check).inverted_tets, 0);
}

/// Jacobi averages where Gauss–Seidel chains: with the same projections per frame, a body
/// resting under gravity holds its edges and volumes less tightly.
#[test]
fn the_jacobi_order_holds_the_constraints_less_tightly_than_gauss_seidel() {
    let simulation = cube(4, PerFamily::builtin_list("edges,volume").unwrap());
    let error = |order| {
        let mut fast = FastSimulation::new(simulation.start());
        fast.set_order(order);
        for _ in 0..60 {
            fast.step();
        }
        fast.relative_error()
    };
    let gauss_seidel = error(Order::GaussSeidel);
    let jacobi = error(Order::Jacobi { relaxation: 1.0 });
    assert_eq!(gauss_seidel[Family::HEIGHT], None, "heights not active");
    for family in [Family::EDGES, Family::VOLUME] {
        let (gs, j) = (gauss_seidel[family], jacobi[family]);
        let (gs, j) = (gs.unwrap(), j.unwrap());
        assert!(gs > 0.0 && j > 2.0 * gs, "Gauss–Seidel {gs}, Jacobi {j}");
    }
}

#[test]
fn projections_and_memory_are_counted() {
    let simulation = cube(4, PerFamily::builtin_list("edges,volume").unwrap());
    let mut fast = FastSimulation::new(simulation.start());
    let count = |f| simulation.constraint_count(f) as u64;
    let substeps = simulation.settings().substeps as u64;
    let per_frame = (count(Family::EDGES) + count(Family::VOLUME)) * substeps;
    assert_eq!(fast.projections_per_frame(), per_frame);
    fast.step();
    let t = fast.timings();
    assert_eq!(
        t.projections[Family::EDGES] + t.projections[Family::VOLUME],
        per_frame
    );
    assert_eq!(t.projections[Family::HEIGHT], 0);
    let per_tet = fast.heap_bytes() / fast.tet_count();
    assert!((100..300).contains(&per_tet), "{per_tet} bytes per tet");
}
