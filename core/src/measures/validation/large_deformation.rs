//! Large deformations: the neo-Hookean pair must stay finite, gain no energy and come back to
//! its rest shape, however far it is taken.
//!
//! - **Twist**: a 5:1 bar turned through 360° about its axis, one end against the other, then
//!   let go (no pins, no gravity).
//! - **Compression**: a cube squashed to 10 % of its height, then let go.
//! - **Slivers**: a block meshed with tets ten times as wide as they are thick (cells
//!   0.25 × 0.025 × 0.25 m), dropped 0.5 m onto the ground.
//!
//! A free elastic body has one stable equilibrium, its rest shape up to a rigid motion, so once
//! at rest every edge must have its rest length again (edge strain is blind to rigid motion).
//! And a damped passive body can never move with more kinetic energy than it started with, in
//! elastic or in potential energy: a kinetic energy above that is a blow-up.

use super::at_rest::{AtRest, neohookean};
use super::{Case, Check, Stop, Trial};
use crate::constraints::material::Material;
use crate::measures::energy_account::EnergyWatch;
use crate::scene::{Scene, lattice};
use glam::{DQuat, DVec3};

/// The twist.
pub(super) const TWIST: Case = Case {
    name: "twist",
    summary: "a 5:1 bar twisted through 360° and let go: finite, recovers its rest shape",
    quick: true,
    run: twist,
};

/// The compression.
pub(super) const COMPRESSION: Case = Case {
    name: "compression",
    summary: "a cube squashed to 10 % of its height and let go: finite, recovers",
    quick: true,
    run: compression,
};

/// The slivers.
pub(super) const SLIVERS: Case = Case {
    name: "slivers",
    summary: "a block of 10:1 sliver tets dropped on the ground: no energy gained, no blow-up",
    quick: true,
    run: slivers,
};

/// Recovery: damped to rest (10⁻⁵ m/s is 10⁻⁵ of the speeds a release reaches).
const RECOVERY: AtRest = AtRest {
    substeps: crate::simulation::DEFAULT_SUBSTEPS,
    iterations: 4,
    damping: 5.0,
    stop_speed: 1e-5,
    max_frames: 1800,
};

/// Recovered: the largest edge strain at rest. The static error of a body at rest without
/// loads is the solver's, far below this (the patch test's is 10⁻⁴ of a cell).
const RECOVERED: f64 = 1e-3;

fn twist(trial: &mut Trial) -> Result<Vec<Check>, Stop> {
    let n = 2;
    let (width, length) = (0.2, 1.0);
    let size = width / n as f64;
    let mesh = lattice(
        [5 * n, n, n],
        DVec3::new(0.0, 0.5, -0.1),
        DVec3::splat(size),
    );
    let axis = DVec3::new(0.0, 0.6, 0.0);
    let twisted: Vec<DVec3> = mesh
        .positions
        .iter()
        .map(|&p| {
            let turn = DQuat::from_rotation_x(std::f64::consts::TAU * p.x / length);
            axis + turn * (p - axis)
        })
        .collect();
    let scene = scene("bar 5:1", mesh);
    recover(trial, &scene, "twisted 360°", &twisted, 0.0)
}

fn compression(trial: &mut Trial) -> Result<Vec<Check>, Stop> {
    let n = 4;
    let mesh = lattice(
        [n; 3],
        DVec3::new(-0.5, 0.0, -0.5),
        DVec3::splat(1.0 / n as f64),
    );
    let squashed: Vec<DVec3> = mesh
        .positions
        .iter()
        .map(|&p| DVec3::new(p.x, 0.1 * p.y, p.z))
        .collect();
    let scene = scene("cube", mesh);
    recover(trial, &scene, "squashed to 10 %", &squashed, 0.0)
}

fn slivers(trial: &mut Trial) -> Result<Vec<Check>, Stop> {
    let size = DVec3::new(0.25, 0.025, 0.25);
    let mesh = lattice([4, 4, 4], DVec3::new(-0.5, 0.5, -0.5), size);
    let start = mesh.positions.clone();
    let scene = scene("slivers 10:1", mesh);
    recover(trial, &scene, "dropped 0.5 m", &start, 9.81)
}

fn scene(name: &str, mesh: crate::scene::mesh::TetMesh) -> Scene {
    Scene {
        name: name.into(),
        mesh,
        pinned: Vec::new(),
        notes: Vec::new(),
        bodies: Vec::new(),
    }
}

/// Starts `scene` at `start`, at rest, lets it go under `gravity` and checks it: no energy
/// gained, back at rest within the protocol, no tet inverted and every edge at its rest length.
fn recover(
    trial: &mut Trial,
    scene: &Scene,
    what: &str,
    start: &[DVec3],
    gravity: f64,
) -> Result<Vec<Check>, Stop> {
    let material = Material::default();
    let shortest = scene
        .mesh
        .edges()
        .iter()
        .map(|&[i, j]| scene.mesh.positions[i as usize].distance(scene.mesh.positions[j as usize]))
        .fold(f64::INFINITY, f64::min);
    let settings = RECOVERY.settings(material, gravity, shortest);
    debug_assert_eq!(settings.active, neohookean());
    let mut simulation = trial.simulation(what, scene, settings);
    simulation.set_positions(start);
    let mut account = EnergyWatch::start(&simulation);
    let budget = account.last().total;
    let mut most_kinetic: f64 = 0.0;
    let rest_state = RECOVERY.run_watching(trial, &mut simulation, |simulation| {
        let energy = account.observe(simulation, simulation.frame());
        most_kinetic = most_kinetic.max(energy.kinetic);
    })?;
    let metrics = crate::measures::metrics::Metrics::measure(&simulation);
    Ok(vec![
        Check::at_most(
            format!("{what}: largest kinetic energy during the run, J"),
            budget,
            "energy at the start (elastic + potential above the ground): a damped body gains none",
            most_kinetic,
        ),
        Check::at_most(
            format!("{what}: largest rise of the energy above its lowest before, J"),
            account.bound(),
            "the energy account: nothing gives energy (1 % of what the body could give back)",
            account.gain.as_ref().map_or(0.0, |g| g.amount),
        ),
        rest_state.check(what, &RECOVERY, &settings),
        Check::at_most(
            format!("{what}: inverted tets at rest"),
            0.0,
            "the rest shape, the only stable equilibrium",
            metrics.inverted_tets as f64,
        ),
        Check::at_most(
            format!("{what}: largest edge strain at rest"),
            RECOVERED,
            "the rest shape, up to a rigid motion",
            metrics.max_edge_strain,
        ),
    ])
}
