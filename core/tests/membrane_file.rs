//! A surface triangle's 2 × 2 and 3 × 2 matrices (`Dm`, `Ds`, `F`, `A0` on a `triangles`
//! binding) through `assets/constraints/membrane-strain.toml`, C = √A₀ ‖½ (FᵀF − I)‖: the check
//! agrees with its hand gradient; C is zero under every rigid motion and what the formula says
//! under a stretch; and on a scrambled cube the file alone pulls the surface back towards its rest
//! shape, on both engines.

use glam::DVec3;
use std::path::Path;
use tetlab_core::constraint_file::ConstraintFile;
use tetlab_core::constraint_file::check::{Reflection, check};
use tetlab_core::constraints::Families;
use tetlab_core::constraints::material::Material;
use tetlab_core::measures::metrics::Metrics;
use tetlab_core::numbers::random::SplitMix64;
use tetlab_core::scene::{Builtin, Perturbation, Scene};
use tetlab_core::simulation::{EngineChoice, Settings, Simulation};

fn load() -> ConstraintFile {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/constraints/membrane-strain.toml");
    ConstraintFile::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn the_check_agrees_with_the_hand_gradient() {
    let report = check(&load(), 2000, 3);
    assert!(report.agrees(), "{report:?}");
    assert!(report.translation_invariant() && report.rotation_invariant());
    // A mirror image of a triangle is congruent to it: FᵀF is unchanged.
    assert_eq!(report.reflection, Reflection::Unchanged);
}

#[test]
fn rigid_motions_cost_nothing_and_a_stretch_costs_what_the_formula_says() {
    let file = load();
    let material = Material::default();
    let mut random = SplitMix64::new(9);
    for _ in 0..200 {
        let shape: Vec<DVec3> = (0..3).map(|_| random.in_cube(1.0)).collect();
        let stored = file.store(&shape, &material);
        let area = 0.5 * (shape[1] - shape[0]).cross(shape[2] - shape[0]).length();
        let size = (shape[1] - shape[0]).length().max(1e-3);
        // Moved rigidly (a random turn and shift): C = 0 to rounding.
        let (turn, shift) = (random.rotation(), random.in_cube(3.0));
        let moved: Vec<DVec3> = shape.iter().map(|q| turn * *q + shift).collect();
        let c = file.value(&moved, 0.0, &stored);
        assert!(
            c.abs() < 1e-12 * area.sqrt().max(1.0) / size.min(1.0).powi(2),
            "{c}"
        );
        // Stretched by 1 + e along the first edge: E = diag(((1 + e)² − 1) / 2, 0) in the
        // triangle's frame, so C = √A₀ ((1 + e)² − 1) / 2.
        let e = random.range(0.05, 0.5);
        let axis = (shape[1] - shape[0]) / (shape[1] - shape[0]).length();
        let stretched: Vec<DVec3> = shape
            .iter()
            .map(|q| *q + axis * (e * axis.dot(*q - shape[0])))
            .collect();
        let expected = area.sqrt() * ((1.0 + e).powi(2) - 1.0) / 2.0;
        let c = file.value(&stretched, 0.0, &stored);
        assert!(
            (c - expected).abs() < 1e-9 * expected.max(1.0),
            "{c} against {expected}"
        );
    }
}

#[test]
fn a_scrambled_surface_is_pulled_back_on_both_engines() {
    let scene = Scene::builtin(Builtin::Cube, 3).unwrap();
    let mut table = Families::builtin();
    let family = table.register_all(vec![load()]).unwrap()[0];
    for engine in [EngineChoice::Reference, EngineChoice::Fast] {
        let settings = Settings {
            active: table.per_family(|f| f == family),
            engine,
            gravity: 0.0,
            ground: false,
            ..Settings::default()
        };
        let mut simulation = Simulation::with_families(&scene, settings, table.clone());
        simulation.perturb(Perturbation::Scramble(4));
        let start = Metrics::measure(&simulation).residual[family];
        for _ in 0..60 {
            simulation.step();
        }
        let end = Metrics::measure_sound(&simulation).unwrap().residual[family];
        println!("{engine:?}: the surface's RMS C went from {start:.3e} to {end:.3e}");
        assert!(start > 1e-2, "{start}");
        // Compliant (1/μ), one iteration a substep, and nothing but the surface constrained (it
        // may bend and fold freely): the strain falls steadily rather than at once, 26-fold in
        // these 60 frames on either engine and on to 2·10⁻³ by frame 240.
        assert!(end < 0.1 * start, "{engine:?}: {start} -> {end}");
    }
}
