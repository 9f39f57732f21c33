//! The bindings of the surface: `triangles` (each surface triangle, wound outwards) and `hinges`
//! (two surface triangles sharing an edge), what they give at boundary and non-manifold edges,
//! and the bending and surface-area examples of `assets/constraints` simulated on both engines.

use glam::DVec3;
use tetlab_core::constraints::{Binding, Families, PerFamily};
use tetlab_core::measures::metrics::Metrics;
use tetlab_core::scene::mesh::TetMesh;
use tetlab_core::scene::{Builtin, Scene};
use tetlab_core::simulation::{EngineChoice, Settings, Simulation};

#[path = "support/example_files.rs"]
mod example_files;
use example_files::example;

#[test]
fn surface_triangles_are_wound_outwards() {
    let cube = Scene::builtin(Builtin::Cube, 3).unwrap().mesh;
    let flat = Binding::Triangles.particles(&cube);
    let (triangles, _) = flat.as_chunks::<3>();
    // 6 faces of 3 × 3 squares, two triangles each.
    assert_eq!(triangles.len(), 6 * 9 * 2);
    // Each normal points away from the centre of the cube.
    let centre = cube.positions.iter().sum::<DVec3>() / cube.positions.len() as f64;
    for t in triangles {
        let [a, b, c] = t.map(|i| cube.positions[i as usize]);
        let normal = (b - a).cross(c - a);
        assert!(normal.dot((a + b + c) / 3.0 - centre) > 0.0, "{t:?}");
    }
}

#[test]
fn a_hinge_is_an_edge_of_two_surface_triangles_and_its_angle_is_their_fold() {
    let cube = Scene::builtin(Builtin::Cube, 2).unwrap().mesh;
    let flat = Binding::Hinges.particles(&cube);
    let (hinges, _) = flat.as_chunks::<4>();
    // Every edge of a closed surface is shared by two triangles: E = 3F / 2.
    let faces = cube.surface_faces().len();
    assert_eq!(hinges.len(), 3 * faces / 2);
    let bending = example("bending.toml");
    let (mut flat_hinges, mut folds) = (0, 0);
    for h in hinges {
        let p = h.map(|i| cube.positions[i as usize]);
        let theta = bending.value(&p, 0.0, &[]);
        if theta.abs() < 1e-12 {
            flat_hinges += 1;
        } else {
            // A hinge on the cube's own edges folds by a right angle, outwards.
            assert!(
                (theta.abs() - std::f64::consts::FRAC_PI_2).abs() < 1e-12,
                "{theta}"
            );
            folds += 1;
        }
    }
    // 12 edges of the cube, 2 segments each at resolution 2; the rest lie in its faces.
    assert_eq!(folds, 12 * 2);
    assert_eq!(flat_hinges, hinges.len() - folds);
}

#[test]
fn a_non_manifold_edge_makes_no_hinge() {
    // Two tets that share only the edge 0–1: four surface triangles meet there.
    let mesh = TetMesh {
        positions: vec![
            DVec3::ZERO,
            DVec3::Z,
            DVec3::X,
            DVec3::new(1.0, 1.0, 0.0),
            -DVec3::X,
            DVec3::new(-1.0, -1.0, 0.0),
        ],
        tets: vec![[0, 2, 3, 1], [0, 4, 5, 1]],
    };
    let hinges = mesh.surface_hinges();
    assert!(
        hinges
            .iter()
            .all(|h| [h[0], h[1]] != [0, 1] && [h[0], h[1]] != [1, 0]),
        "{hinges:?}"
    );
    // Each tet's other five edges are still hinges.
    assert_eq!(hinges.len(), 10);
}

/// The beam of lesson 10: soft edges alone, then with bending; on `engine`.
fn beam(engine: EngineChoice, bending: bool) -> Metrics {
    let mut families = Families::builtin();
    let family = families.register(example("bending.toml")).unwrap();
    let mut active = PerFamily::builtin_list("edges").unwrap();
    active.set(family, bending);
    let mut compliance = PerFamily::splat(0.0);
    compliance.set(tetlab_core::constraints::Family::EDGES, 1e-4);
    let settings = Settings {
        active,
        compliance,
        engine,
        ..Settings::default()
    };
    let scene = Scene::builtin(Builtin::Beam, 2).unwrap();
    let mut simulation = Simulation::with_families(&scene, settings, families);
    for _ in 0..120 {
        simulation.step();
    }
    Metrics::measure_sound(&simulation).unwrap()
}

#[test]
fn bending_on_the_hinges_holds_a_soft_beam_on_both_engines() {
    for engine in [EngineChoice::Reference, EngineChoice::Fast] {
        let (soft, bent) = (beam(engine, false), beam(engine, true));
        println!(
            "{engine:?}: edges alone sag {:.3} m ({} inverted), with bending {:.4} m ({} inverted)",
            soft.max_displacement, soft.inverted_tets, bent.max_displacement, bent.inverted_tets
        );
        assert!(soft.max_displacement > 0.5 && soft.inverted_tets > 0);
        assert!(bent.max_displacement < 0.05 && bent.inverted_tets == 0);
    }
}

#[test]
fn the_surface_area_of_a_flattened_cube_comes_back_on_both_engines() {
    let mut families = Families::builtin();
    let area = families.register(example("surface-area.toml")).unwrap();
    let scene = Scene::builtin(Builtin::Cube, 3).unwrap();
    for engine in [EngineChoice::Reference, EngineChoice::Fast] {
        let mut active = PerFamily::builtin_list("edges,volume").unwrap();
        active.set(area, true);
        let settings = Settings {
            active,
            engine,
            settle_edits: true,
            ..Settings::default()
        };
        let mut simulation = Simulation::with_families(&scene, settings, families.clone());
        simulation.perturb(tetlab_core::scene::Perturbation::Flatten);
        for _ in 0..60 {
            simulation.step();
        }
        let m = Metrics::measure_sound(&simulation).unwrap();
        println!(
            "{engine:?}: residual of the surface area {:.1e}",
            m.residual[area]
        );
        assert!(m.residual[area] < 1e-3, "{engine:?}: {}", m.residual[area]);
        assert_eq!(m.inverted_tets, 0);
    }
}
