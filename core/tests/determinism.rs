//! The same inputs give the same bits: in another process, and on the fast engine on any number
//! of threads. A run in this process cannot show nondeterminism that comes from outside it (an
//! address, a hash seed, the scheduling of threads), so the run is made in child processes of
//! this test binary (the ignored test below, asked through `TETLAB_BITS_OF`), and their bits are
//! compared with each other and with this process's.

use tetlab_core::constraints::{Family, PerFamily};
use tetlab_core::scene::{Builtin, Perturbation, Scene};
use tetlab_core::simulation::fast::FastSimulation;
use tetlab_core::simulation::fast::PARALLEL_MIN;
use tetlab_core::simulation::{EngineChoice, Settings, Simulation};

/// A scrambled 16³ cube (24 576 tets: its colours are large enough to be shared between
/// threads), on `engine` with `threads` threads.
fn simulation(engine: EngineChoice, threads: usize) -> Simulation {
    let scene = Scene::builtin(Builtin::Cube, 16).unwrap();
    let mut simulation = Simulation::new(
        &scene,
        Settings {
            engine,
            substeps: 10,
            damping: 1.0,
            active: PerFamily::builtin_list("edges,height,volume").unwrap(),
            ..Settings::default()
        },
    );
    simulation.set_threads(threads);
    simulation.perturb(Perturbation::Scramble(4));
    simulation
}

/// FNV-1a over the bits of every coordinate of [`simulation`] after two frames, and of what the
/// ground, damping and the settling cap took (summed over the particles: in the same order for
/// any thread count).
fn bits_of_a_run(engine: EngineChoice, threads: usize) -> u64 {
    let mut simulation = simulation(engine, threads);
    for _ in 0..2 {
        simulation.step();
    }
    let taken = simulation.state().taken;
    assert!(taken.ground > 0.0 && taken.damping > 0.0, "{taken:?}");
    let mut hash = 0xcbf2_9ce4_8422_2325_u64;
    let coordinates = simulation.positions().iter().flat_map(|p| p.to_array());
    for coordinate in coordinates.chain([taken.ground, taken.damping, taken.settling]) {
        for byte in coordinate.to_bits().to_le_bytes() {
            hash = (hash ^ u64::from(byte)).wrapping_mul(0x0100_0000_01b3);
        }
    }
    hash
}

/// The run a parent asks for (`TETLAB_BITS_OF=ENGINE,THREADS`), its bits printed; it does
/// nothing on its own, so it runs only when asked.
#[test]
#[ignore = "run by the_same_bits_in_other_processes_and_on_any_thread_count"]
fn print_the_bits_of_a_run() {
    let asked = std::env::var("TETLAB_BITS_OF").expect("run by its parent");
    let (engine, threads) = asked.split_once(',').unwrap();
    let bits = bits_of_a_run(
        EngineChoice::parse(engine).unwrap(),
        threads.parse().unwrap(),
    );
    println!("bits {bits:016x}");
}

/// The bits of the run in a new process of this binary.
fn bits_in_a_child(engine: &str, threads: usize) -> u64 {
    let output = std::process::Command::new(std::env::current_exe().unwrap())
        .args([
            "--ignored",
            "--exact",
            "print_the_bits_of_a_run",
            "--nocapture",
        ])
        .env("TETLAB_BITS_OF", format!("{engine},{threads}"))
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "{stdout}");
    let line = stdout
        .lines()
        .find_map(|l| l.strip_prefix("bits "))
        .unwrap_or_else(|| panic!("no bits in {stdout}"));
    u64::from_str_radix(line.trim(), 16).unwrap()
}

#[test]
fn the_same_bits_in_other_processes_and_on_any_thread_count() {
    let reference = bits_of_a_run(EngineChoice::Reference, 1);
    assert_eq!(bits_in_a_child("reference", 1), reference);
    assert_eq!(bits_in_a_child("reference", 1), reference);
    let fast = bits_of_a_run(EngineChoice::Fast, 1);
    assert_ne!(
        fast, reference,
        "f32 is not f64: the two runs are told apart"
    );
    let threads = if cfg!(feature = "parallel") { 2 } else { 1 };
    let mut shared = simulation(EngineChoice::Fast, threads);
    let colours = shared
        .engine_as::<FastSimulation>()
        .expect("the fast engine")
        .batches(Family::VOLUME)
        .colours()
        .to_vec();
    assert!(
        colours.iter().any(|c| c.elements >= PARALLEL_MIN),
        "some colour is large enough to be shared"
    );
    assert_eq!(bits_in_a_child("fast", 1), fast);
    assert_eq!(bits_in_a_child("fast", threads), fast);
    assert_eq!(bits_of_a_run(EngineChoice::Fast, threads), fast);
}
