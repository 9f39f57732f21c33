//! Real meshes under the defaults: every built-in scene and every mesh of `../shared/meshes`,
//! loaded as `tetlab run` and the workbench load them and played for 10 s with
//! [`Settings::default`], ends at rest with no inverted tet and every edge within 5 % of its rest
//! length. Each run also reports the largest edge strain along the way (the impact), which is how
//! far from converged the rigid constraints are; docs/experiments.md table 15 lists the same runs.

use std::io::Write;
use tetlab_core::input::shared_meshes;
use tetlab_core::measures::metrics::Metrics;
use tetlab_core::scene::{Builtin, Scene};
use tetlab_core::simulation::{Settings, Simulation};

/// 10 s at the default Δt of 1/60 s.
const FRAMES: u64 = 600;
/// The largest edge strain allowed at the end.
const STRAIN_AT_THE_END: f64 = 0.05;

/// Plays `scene` under the defaults for [`FRAMES`] frames and checks the end state; prints one
/// line with the largest strain during the run (past the harness's capture, so that
/// `cargo test` shows it).
fn plays_under_the_defaults(scene: &Scene) {
    let settings = Settings::default();
    let mut simulation = Simulation::new(scene, settings);
    let mut largest = (0.0f64, 0);
    let mut last_inverted = None;
    for frame in 1..=FRAMES {
        simulation.step();
        let metrics = Metrics::measure_sound(&simulation)
            .unwrap_or_else(|d| panic!("{}: diverged: {d}", scene.name));
        if metrics.max_edge_strain > largest.0 {
            largest = (metrics.max_edge_strain, frame);
        }
        if metrics.inverted_tets > 0 {
            last_inverted = Some(frame);
        }
    }
    let end = Metrics::measure(&simulation);
    let _ = writeln!(
        std::io::stderr(),
        "{} ({} tets, {} substeps): inverted at the end {}, last inverted frame {:?}, \
         largest edge strain {:.4} at frame {}, at the end {:.4}",
        scene.name,
        simulation.tets().len(),
        settings.substeps,
        end.inverted_tets,
        last_inverted,
        largest.0,
        largest.1,
        end.max_edge_strain
    );
    assert_eq!(
        end.inverted_tets, 0,
        "{}: {} tets inverted after {FRAMES} frames under the defaults",
        scene.name, end.inverted_tets
    );
    assert!(
        end.max_edge_strain < STRAIN_AT_THE_END,
        "{}: max edge strain {:.4} after {FRAMES} frames under the defaults (limit {STRAIN_AT_THE_END})",
        scene.name,
        end.max_edge_strain
    );
}

/// A built-in scene at the resolutions the front ends open it at: `tetlab run`'s default (4)
/// and the workbench's (3).
fn builtin(builtin: Builtin) {
    for resolution in [3, 4] {
        plays_under_the_defaults(&Scene::builtin(builtin, resolution).unwrap());
    }
}

/// A mesh of `../shared/meshes`, loaded as `tetlab run --scene PATH` loads it (lifted onto the
/// ground); skips when the folder is absent.
fn shared(name: &str) {
    let Some(path) = shared_meshes::for_test(name) else {
        return;
    };
    let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    plays_under_the_defaults(&scene);
}

#[test]
fn the_tet_under_the_defaults() {
    plays_under_the_defaults(&Scene::builtin(Builtin::Tet, 1).unwrap());
}

#[test]
fn the_cube_under_the_defaults() {
    builtin(Builtin::Cube);
}

#[test]
fn the_beam_under_the_defaults() {
    builtin(Builtin::Beam);
}

#[test]
fn the_ball_under_the_defaults() {
    builtin(Builtin::Ball);
}

#[test]
fn the_bunny_under_the_defaults() {
    shared("bunny.node");
}

/// It loads standing on one toe; at 10 substeps it crushed the toe, fell over and kept two tets
/// flat against the ground (docs/experiments.md table 15).
#[test]
fn the_armadillo_under_the_defaults() {
    shared("armadillo_4k.node");
}

#[test]
fn the_gmsh_balls_under_the_defaults() {
    shared("ball_v41.msh");
    shared("ball_v22.msh");
}

#[test]
fn the_gmsh_beam_under_the_defaults() {
    shared("beam_v41.msh");
}
