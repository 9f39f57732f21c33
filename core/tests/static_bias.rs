//! XPBD's static bias, and an experiment that removes it. A cantilever (the beam scene at
//! resolution 1, clamped at x = 0, neo-Hookean E = 10 MPa, ν = 0.3) damped to rest under its
//! weight, at 4 iterations and 5, 20 and 100 substeps: its tip deflection on the reference
//! engine and on an engine that rebuilds the positions from the multipliers after every sweep
//! (`support/rebuilt_engine.rs`), each against the exact static solution of the same mesh (the
//! Newton reference's equilibrium). XPBD's answer is stiff by a bias that falls as h² (−8.6 %,
//! −0.80 %, −0.032 %); rebuilt, it is the exact one to 10⁻⁷ at 20 substeps and 10⁻⁹ at 100, but
//! at 5, where the substep is near the material's stability bound, the fixed point diverges and
//! throws the beam: why the rebuild is not tetlab's rule (docs/experiments.md).

#[path = "support/rebuilt_engine.rs"]
mod rebuilt_engine;

#[path = "support/cantilever.rs"]
mod cantilever;

use cantilever::cantilever;
use glam::DVec3;
use rebuilt_engine::Rebuilt;
use tetlab_core::constraints::PerFamily;
use tetlab_core::scene::{Builtin, Scene};
use tetlab_core::simulation::newton::{Options, equilibrium};
use tetlab_core::simulation::{Settings, Simulation};

/// The mean downward deflection of the particles at the beam's free end, from `rest`.
fn tip(rest: &[DVec3], x: &[DVec3]) -> f64 {
    let end = rest.iter().map(|p| p.x).fold(f64::NEG_INFINITY, f64::max);
    let (sum, n) = rest
        .iter()
        .zip(x)
        .filter(|(r, _)| (r.x - end).abs() < 1e-9)
        .fold((0.0, 0), |(s, n), (r, p)| (s + r.y - p.y, n + 1));
    sum / n as f64
}

/// The cantilever at `substeps`, damped to rest (600 frames, damping 10/s: its motion falls by
/// e⁻¹⁰⁰), on the reference engine or the rebuilt one: its tip deflection, and the exact one.
fn at_rest(substeps: u32, rebuilt: bool) -> (f64, f64) {
    let mut simulation = cantilever(substeps, rebuilt);
    for _ in 0..600 {
        simulation.step();
    }
    let (exact, report) = equilibrium(simulation.start(), &Options::default()).unwrap();
    assert!(report.converged, "{report:?}");
    let rest = simulation.rest_positions();
    (tip(rest, simulation.positions()), tip(rest, &exact))
}

#[test]
fn rebuilding_the_positions_from_the_multipliers_removes_xpbds_static_bias() {
    let mut rows = Vec::new();
    for substeps in [5, 20, 100] {
        let (xpbd, exact) = at_rest(substeps, false);
        let (rebuilt, _) = at_rest(substeps, true);
        let bias = |d: f64| (d - exact) / exact;
        rows.push((substeps, bias(xpbd), bias(rebuilt)));
    }
    for (substeps, xpbd, rebuilt) in &rows {
        println!(
            "{substeps} substeps: XPBD {xpbd:+.3e}, rebuilt {rebuilt:+.3e} of the exact deflection"
        );
    }
    // XPBD is stiff (its deflection short of the exact one) by a bias that falls as h².
    let xpbd: Vec<f64> = rows.iter().map(|r| r.1).collect();
    assert!(xpbd.iter().all(|&b| b < 0.0), "{rows:?}");
    assert!(xpbd[1].abs() < xpbd[0].abs() / 8.0, "{rows:?}");
    assert!(xpbd[2].abs() < xpbd[1].abs() / 16.0, "{rows:?}");
    // Rebuilt, it is gone from 20 substeps on, to far less than XPBD's bias at 100.
    for (substeps, xpbd, rebuilt) in &rows[1..] {
        assert!(
            rebuilt.abs() < xpbd.abs() / 100.0 && rebuilt.abs() < 1e-6,
            "{substeps} substeps: XPBD {xpbd}, rebuilt {rebuilt}"
        );
    }
    // At 5 the rebuild's fixed point does not hold: far worse than XPBD, or not a number.
    let (_, xpbd, rebuilt) = rows[0];
    assert!(
        rebuilt.is_nan() || rebuilt.abs() > xpbd.abs(),
        "the rebuild holds at 5 substeps ({rebuilt} against XPBD's {xpbd}): say so in the docs"
    );
}

/// What the rebuild does to the recovery claims, as k of N: the 2 × 2 × 2 cube inverted,
/// mirrored and flattened, under edges + volume, edges + heights + volume and the neo-Hookean
/// material, at the default 100 substeps and 1 iteration, in 8 orderings each (order seeds
/// 1..=8), edits settling: how many end (120 frames) with no tet inverted, on XPBD and rebuilt,
/// and whether any run gained energy. Printed, for docs/experiments.md (`cargo test --release -p
/// tetlab-core --test static_bias -- --ignored --nocapture`); it asserts only that both ran.
#[test]
#[ignore = "an experiment's table: run by hand"]
fn what_the_rebuild_does_to_the_recovery_claims() {
    use tetlab_core::measures::energy_account::EnergyWatch;
    use tetlab_core::measures::metrics::Metrics;
    use tetlab_core::scene::Perturbation;
    let scene = Scene::builtin(Builtin::Cube, 2).unwrap();
    for families in ["edges,volume", "edges,height,volume", "neohookean"] {
        for perturbation in [
            Perturbation::Invert,
            Perturbation::Mirror,
            Perturbation::Flatten,
        ] {
            let mut row = format!("{families}, {perturbation:?}:");
            for rebuilt in [false, true] {
                let (mut recovered, mut gained) = (0, 0);
                for seed in 1..=8 {
                    let settings = Settings {
                        active: PerFamily::builtin_list(families).unwrap(),
                        order_seed: Some(seed),
                        settle_edits: true,
                        ..Settings::default()
                    };
                    let mut simulation = Simulation::new(&scene, settings);
                    if rebuilt {
                        simulation.use_engine(Rebuilt::build, "rebuilt");
                    }
                    simulation.perturb(perturbation);
                    let mut watch = EnergyWatch::start(&simulation);
                    for frame in 1..=120 {
                        simulation.step();
                        watch.observe(&simulation, frame);
                    }
                    let sound = simulation.is_sound();
                    if sound && Metrics::measure(&simulation).inverted_tets == 0 {
                        recovered += 1;
                    }
                    if !sound || watch.gain.is_some() {
                        gained += 1;
                    }
                }
                let name = if rebuilt { "rebuilt" } else { "XPBD" };
                row += &format!(" {name} recovers in {recovered} of 8 ({gained} gained energy);");
            }
            println!("{row}");
        }
    }
}
