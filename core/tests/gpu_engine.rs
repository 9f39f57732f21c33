//! The GPU engine (`simulation/gpu`) against the fast engine, whose model it is, on whatever
//! adapter the machine has (Mesa's software Vulkan, lavapipe, here and in CI):
//!
//! - **Frame 1 within the contract's bound.** After one frame the two engines' positions differ
//!   by rounding alone, within the bound of docs/performance.md ("The engines' contract") that
//!   the engine matrix holds the fast engine to against the reference one: every stage of the
//!   substep (gravity, the ground, damping, the settling cap, external forces, plane strain,
//!   pins, both grabs, XPBD and PBD, every built-in family and the neo-Hookean pair).
//! - **A constraint file as its built-in.** The source note's edge, height and volume written as
//!   files run on the GPU, translated from their tapes, and give the built-ins' frame.
//! - **The same outcome.** The mirrored cube of the README recovers on the GPU, as on the fast
//!   engine, in the table's order and under an order seed.
//! - **The same bits run to run**, and the skips counted as the fast engine counts them.
//! - **A frame with contact** runs on the CPU, says so, and gives the fast engine's bits.
//! - **The page's engine**, which never waits for the GPU (a frame started in one call and
//!   finished in a later one), gives the same bits as the desktop's, an edit made while a frame
//!   is under way included.
//!
//! Without an adapter these tests skip, saying so; under `CI=true` they must run.

#[path = "support/contract.rs"]
mod contract;

use contract::{frame_bound, largest_gap};
use glam::DVec3;
use std::path::Path;
use tetlab_core::constraint_file::ConstraintFile;
use tetlab_core::constraints::{Families, Family, PerFamily};
use tetlab_core::measures::metrics::Metrics;
use tetlab_core::measures::outcome::Outcome;
use tetlab_core::scene::{Builtin, Perturbation, Scene};
use tetlab_core::simulation::{EngineChoice, Method, Settings, Simulation};

fn cube() -> Scene {
    Scene::builtin(Builtin::Cube, 4).unwrap()
}

fn settings(families: &str, engine: EngineChoice) -> Settings {
    Settings {
        active: PerFamily::builtin_list(families).unwrap(),
        engine,
        ..Settings::default()
    }
}

/// One stage of the substep, shown on a scene: the settings and an edit of the simulation.
struct Case {
    name: &'static str,
    families: &'static str,
    tweak: fn(&mut Settings),
    edit: fn(&mut Simulation),
}

fn nothing(_: &mut Settings) {}
fn untouched(_: &mut Simulation) {}

const CASES: &[Case] = &[
    Case {
        name: "a cube falls (edges, volume)",
        families: "edges,volume",
        tweak: nothing,
        edit: untouched,
    },
    Case {
        name: "edges, heights and volume",
        families: "edges,height,volume",
        tweak: nothing,
        edit: untouched,
    },
    Case {
        name: "PBD, four sweeps, stiffness 0.5",
        families: "edges,volume",
        tweak: |s| {
            s.method = Method::Pbd;
            s.iterations = 4;
            s.stiffness.set(Family::EDGES, 0.5);
            s.stiffness.set(Family::VOLUME, 0.5);
        },
        edit: untouched,
    },
    Case {
        name: "the neo-Hookean pair, squashed",
        families: "neohookean",
        tweak: nothing,
        edit: |s| {
            let squashed: Vec<DVec3> = (s.positions().iter())
                .map(|p| DVec3::new(p.x * 1.2, p.y * 0.8 + 0.5, p.z))
                .collect();
            s.set_positions(&squashed);
        },
    },
    Case {
        name: "damped, no ground, 20 substeps",
        families: "edges,volume",
        tweak: |s| {
            s.damping = 5.0;
            s.ground = false;
            s.substeps = 20;
        },
        edit: untouched,
    },
    Case {
        name: "two particles pinned, one held by a rigid grab",
        families: "edges,height,volume",
        tweak: nothing,
        edit: |s| {
            s.set_pinned(0, true);
            s.set_pinned(4, true);
            let far = s.positions().len() - 1;
            let target = s.positions()[far] + DVec3::new(0.3, 0.2, 0.0);
            s.grab(far, target);
        },
    },
    Case {
        name: "a compliant grab",
        families: "edges,volume",
        tweak: |s| s.grab_compliance = 1e-3,
        edit: |s| {
            let target = s.positions()[7] + DVec3::new(-0.2, 0.4, 0.1);
            s.grab(7, target);
        },
    },
    Case {
        name: "external forces in plane strain",
        families: "edges,volume",
        tweak: nothing,
        edit: |s| {
            let n = s.positions().len();
            s.set_forces(
                (0..n)
                    .map(|i| DVec3::new(0.5, (i % 3) as f64, 0.2))
                    .collect(),
            );
            s.set_plane_strain(true);
        },
    },
    Case {
        name: "an edit settling (a tet inverted by hand)",
        families: "edges,height,volume",
        tweak: |s| s.settle_edits = true,
        edit: |s| s.perturb(Perturbation::Invert),
    },
];

/// Both engines on one case, one frame (two for the second frame of a settling edit).
fn frame_one(case: &Case, scene: &Scene) -> Option<String> {
    let make = |engine| {
        let mut settings = settings(case.families, engine);
        (case.tweak)(&mut settings);
        let mut simulation = Simulation::new(scene, settings);
        // Lifted half a metre, so that every case moves (and falls, where there is gravity).
        let lifted: Vec<DVec3> = (simulation.positions().iter())
            .map(|p| *p + 0.5 * DVec3::Y)
            .collect();
        simulation.set_positions(&lifted);
        (case.edit)(&mut simulation);
        simulation
    };
    let (mut fast, mut gpu) = (make(EngineChoice::Fast), make(EngineChoice::Gpu));
    fast.step();
    gpu.step();
    let described = gpu.describe_engine();
    assert!(
        described.starts_with("gpu (f32, ") && !described.contains("CPU"),
        "{}: {described}",
        case.name
    );
    let bound = frame_bound(fast.rest_diagonal(), fast.settings().substeps);
    let gap = largest_gap(fast.positions(), gpu.positions());
    let velocity_gap = largest_gap(fast.velocities(), gpu.velocities());
    println!(
        "{}: frame 1 gap {gap:.2e} m (bound {bound:.2e}), velocities {velocity_gap:.2e} m/s",
        case.name
    );
    // A case where nothing moves would prove nothing: each moves by more than a millimetre.
    let moved = largest_gap(fast.positions(), scene.mesh.positions.as_slice());
    assert!(moved > 1e-3, "{}: nothing moved", case.name);
    (gap > bound).then(|| format!("{}: frame 1: {gap:.2e} > {bound:.2e}", case.name))
}

#[test]
fn every_stage_of_a_frame_is_the_fast_engines_within_the_contract() {
    if !EngineChoice::Gpu.for_test() {
        return;
    }
    let scene = cube();
    let failures: Vec<String> = CASES.iter().filter_map(|c| frame_one(c, &scene)).collect();
    assert!(failures.is_empty(), "{failures:#?}");
}

fn asset(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../assets/constraints")
        .join(name)
}

#[test]
fn a_constraint_file_runs_on_the_gpu_as_its_built_in() {
    if !EngineChoice::Gpu.for_test() {
        return;
    }
    let mut families = Families::builtin();
    let mut names = Vec::new();
    for file in ["edge.toml", "height.toml", "volume.toml"] {
        let file = ConstraintFile::load(&asset(file)).unwrap();
        let family = families.define(file).unwrap();
        names.push(families.name(family).to_owned());
    }
    let scene = cube();
    let lifted: Vec<DVec3> = (scene.mesh.positions.iter())
        .map(|p| DVec3::new(p.x * 1.1, p.y + 0.5, p.z))
        .collect();
    let mut built_in = Simulation::new(&scene, settings("edges,height,volume", EngineChoice::Fast));
    let mut settings = Settings {
        engine: EngineChoice::Gpu,
        ..Settings::default()
    };
    settings.active = families.parse_list(&names.join(",")).unwrap();
    let mut file = Simulation::with_families(&scene, settings, families);
    built_in.set_positions(&lifted);
    file.set_positions(&lifted);
    built_in.step();
    file.step();
    assert!(!file.describe_engine().contains("CPU"));
    let bound = frame_bound(built_in.rest_diagonal(), built_in.settings().substeps);
    let gap = largest_gap(built_in.positions(), file.positions());
    println!(
        "the files on the GPU, the built-ins on the fast engine: {gap:.2e} (bound {bound:.2e})"
    );
    assert!(gap <= bound, "{gap:.2e} > {bound:.2e}");
}

/// The README's first command on the GPU: a mirrored cube recovers (no tet inverted at the
/// end, not thrown) in as many of four orderings (the table's and order seeds 1 to 3) as on the
/// fast engine, give or take one, as the engine matrix holds the CPU engines on a knife edge.
/// (It is one: nudged by 10⁻⁷ m, the fast engine's natural order ends tangled in 2 of 8 nudges,
/// and on the GPU, whose rounding differs by that much, the natural order ends twisted, V/V₀
/// 0.14, with no tet inverted.)
#[test]
fn the_mirrored_cube_recovers_on_the_gpu_in_as_many_orderings() {
    if !EngineChoice::Gpu.for_test() {
        return;
    }
    let scene = cube();
    let seeds = [None, Some(1), Some(2), Some(3)];
    let recovered = |engine: EngineChoice| {
        let mut k = 0;
        for seed in seeds {
            let mut settings = settings("edges,height,volume", engine);
            settings.order_seed = seed;
            settings.settle_edits = true;
            let mut simulation = Simulation::new(&scene, settings);
            simulation.perturb(Perturbation::Mirror);
            let start = Metrics::measure(&simulation);
            let mut outcome = Outcome::start(&simulation, &start);
            for _ in 0..20 {
                simulation.step();
                let metrics = Metrics::measure_sound(&simulation).unwrap();
                outcome.observe(&simulation, &metrics);
            }
            println!("seed {seed:?}: {}: {}", engine.name(), outcome.describe());
            k += usize::from(outcome.recovered() && !outcome.thrown());
        }
        k
    };
    let (fast, gpu) = (recovered(EngineChoice::Fast), recovered(EngineChoice::Gpu));
    let n = seeds.len();
    println!("recovered: fast {fast} of {n}, gpu {gpu} of {n}");
    assert!(
        fast.abs_diff(gpu) <= 1,
        "fast {fast} of {n}, gpu {gpu} of {n}"
    );
    assert!(gpu >= n - 1, "gpu {gpu} of {n}");
}

#[test]
fn the_gpu_gives_the_same_bits_run_to_run() {
    if !EngineChoice::Gpu.for_test() {
        return;
    }
    let scene = cube();
    let run = || {
        let mut simulation =
            Simulation::new(&scene, settings("edges,height,volume", EngineChoice::Gpu));
        simulation.perturb(Perturbation::Mirror);
        for _ in 0..3 {
            simulation.step();
        }
        simulation.positions().to_vec()
    };
    assert_eq!(run(), run());
}

/// A flattened cube's tets have no volume: the heights' projections are degenerate at first,
/// skipped and counted, on the GPU as on the fast engine.
#[test]
fn degenerate_projections_are_skipped_and_counted_as_on_the_fast_engine() {
    if !EngineChoice::Gpu.for_test() {
        return;
    }
    let scene = cube();
    let counts = |engine| {
        let mut settings = settings("edges,height,volume", engine);
        settings.substeps = 1;
        let mut simulation = Simulation::new(&scene, settings);
        simulation.perturb(Perturbation::Flatten);
        simulation.step();
        let skipped = *simulation.skipped();
        let families = simulation.families().clone();
        families
            .all()
            .map(|f| (skipped[f].degenerate, skipped[f].too_long))
            .collect::<Vec<_>>()
    };
    let (fast, gpu) = (counts(EngineChoice::Fast), counts(EngineChoice::Gpu));
    println!("fast {fast:?}\ngpu  {gpu:?}");
    assert!(
        fast.iter().any(|&(d, _)| d > 0),
        "the flattened cube has degenerate heights"
    );
    assert_eq!(fast, gpu);
}

/// A frame with contact runs on the CPU: the engine says so, and the frame is the fast
/// engine's, to the bit (the GPU engine's CPU copy is a fast engine on one thread).
#[test]
fn a_frame_with_contact_runs_on_the_cpu_and_says_so() {
    if !EngineChoice::Gpu.for_test() {
        return;
    }
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/scenes/stacked-cubes.toml");
    let scene = Scene::load_file(&path).unwrap();
    let run = |engine| {
        let mut simulation = Simulation::new(&scene, settings("edges,volume,contact", engine));
        simulation.set_threads(1);
        simulation.step();
        simulation.step();
        (
            simulation.positions().to_vec(),
            simulation.describe_engine(),
        )
    };
    let ((fast, _), (gpu, described)) = (run(EngineChoice::Fast), run(EngineChoice::Gpu));
    assert!(described.contains("contact runs on the CPU"), "{described}");
    assert_eq!(fast, gpu);
}

/// The page's GPU engine returns from a step once the frame is submitted; the frame finishes
/// in a later step. Its frames are the desktop's to the bit, and an edit made while one is under
/// way (here the mirror perturbation, during frame 3) is the state the frame is stepped from, as
/// an edit made before it is on the desktop.
#[cfg(feature = "gpu")]
#[test]
fn the_engine_that_never_waits_gives_the_same_bits() {
    use tetlab_core::simulation::gpu::GpuEngine;
    if !EngineChoice::Gpu.for_test() {
        return;
    }
    let scene = cube();
    let new = |build: tetlab_core::simulation::Build| {
        let mut simulation =
            Simulation::new(&scene, settings("edges,height,volume", EngineChoice::Fast));
        simulation.use_engine(build, "gpu");
        simulation
    };
    let mut desktop = new(|start| Box::new(GpuEngine::new(start)));
    let mut page = new(|start| Box::new(GpuEngine::asynchronous(start)));
    let mut calls_pending = 0;
    for frame in 0..4u64 {
        let edit: fn(&mut Simulation) = match frame {
            2 => |s| s.perturb(Perturbation::Mirror),
            _ => untouched,
        };
        let before = page.positions().to_vec();
        page.step();
        assert!(page.pending(), "frame {frame}: the page's engine waited");
        assert_eq!(
            page.positions(),
            before,
            "a pending frame changed the state"
        );
        edit(&mut page);
        while page.pending() || page.frame() == frame {
            assert!(calls_pending < 1_000_000, "the frame never finished");
            calls_pending += 1;
            page.step();
        }
        edit(&mut desktop);
        desktop.step();
        assert!(!desktop.pending());
        assert_eq!(page.frame(), desktop.frame());
        assert_eq!(page.positions(), desktop.positions(), "after frame {frame}");
        assert_eq!(
            page.velocities(),
            desktop.velocities(),
            "after frame {frame}"
        );
    }
    println!("{calls_pending} calls found a frame under way");
    assert!(
        page.describe_engine().starts_with("gpu (f32"),
        "{}",
        page.describe_engine()
    );
}
