//! Cook's membrane (Cook 1974): a tapered panel with corners (0, 0), (48, 44), (48, 60) and
//! (0, 44), clamped on its left edge and sheared by a uniform vertical traction on its right
//! edge. The reference is the vertical displacement of the upper right corner C = (48, 60):
//! 23.96 for E = 1, ν = 1/3, a total load F = 1 and thickness 1 in plane stress, the converged
//! value of Cook, Malkus & Plesha, *Concepts and Applications of Finite Element Analysis*
//! (3rd ed., 1989, §6.13), also Bergan & Felippa 1985 (23.9). It is a bending problem on a
//! skewed mesh, where low-order elements lock in shear.
//!
//! The panel is extruded one cell thick and every particle is held in z: plane strain. Plane
//! strain with (E, ν) is plane stress with E* = E / (1 − ν²) and ν* = ν / (1 − ν), so the
//! reference's ν* = 1/3 is ν = 1/4, and E = (15/16) E*. The panel is in metres (48 mm wide),
//! E* = 1 MPa, and the load small (the compressible, small-load variant): the reference tip
//! displacement 23.96 F / (E* t) is 10⁻⁴ m, 0.2 % of the panel, where the neo-Hookean pair is
//! linear to about that fraction. Linear elasticity scales, so the measured displacement ×
//! E* t / F is compared with 23.96.
//!
//! Locking as ν → ½: the same panel at ν = 0.4, 0.45 and 0.49 on the 8 × 8 mesh. Linear tets
//! lock volumetrically too (a tet's volume is one number, and near incompressibility every
//! tet's volume must hold, more constraints than the mesh has free coordinates), so the tip
//! displacement falls further below the continuum's, which changes only a little with ν. These
//! rows report the displacement relative to the ν = 1/4 run on the same mesh.

use super::at_rest::{AtRest, lattice_index, lattice_plane, mean};
use super::{Case, Check, Stop, Trial, observed_order};
use crate::constraints::material::Material;
use crate::scene::{Scene, lattice};
use glam::DVec3;

/// The case.
pub(super) const CASE: Case = Case {
    name: "cook",
    summary: "Cook's membrane, plane strain, neo-Hookean, against 23.96 (Cook et al. 1989), refined",
    quick: false,
    run,
};

/// The reference: u_y(C) × E* t / F.
const REFERENCE: f64 = 23.96;

/// The panel's E* (plane stress equivalent), Pa.
const STIFFNESS: f64 = 1e6;

/// The displacement the load aims at, m.
const TIP: f64 = 1e-4;

/// Thickness, m.
const THICKNESS: f64 = 0.003;

/// The panel rings at a few hundred radians a second: damping 200/s is about critical. At
/// 10⁻⁷ m/s the motion left is below 10⁻⁵ of the tip displacement.
const PROTOCOL: AtRest = AtRest {
    substeps: crate::simulation::DEFAULT_SUBSTEPS,
    iterations: 4,
    damping: 200.0,
    stop_speed: 1e-7,
    max_frames: 1200,
};

fn run(trial: &mut Trial) -> Result<Vec<Check>, Stop> {
    let load = TIP * STIFFNESS * THICKNESS / REFERENCE;
    let mut checks = Vec::new();
    let mut errors = Vec::new();
    let resolutions = [4usize, 8, 16];
    let locking_mesh = 8;
    let mut at_quarter = f64::NAN;
    for &n in &resolutions {
        let (tip, rest_checks) = membrane(trial, n, 0.25, load)?;
        checks.extend(rest_checks);
        let scaled = tip * STIFFNESS * THICKNESS / load;
        let check = Check::report(
            format!("tip displacement × E* t / F, {n} × {n} cells, ν = 1/4 (ν* = 1/3)"),
            REFERENCE,
            "Cook, Malkus & Plesha 1989, §6.13",
            scaled,
        );
        errors.push(check.error);
        checks.push(check);
        if n == locking_mesh {
            at_quarter = scaled;
        }
    }
    for (k, pair) in errors.windows(2).enumerate() {
        checks.push(Check {
            criterion: "the error falls: order > 0".into(),
            passed: Some(pair[1] < pair[0]),
            ..Check::report(
                format!(
                    "observed order, {} to {} cells a side",
                    resolutions[k],
                    resolutions[k + 1]
                ),
                2.0,
                "linear elements, asymptotically",
                observed_order(pair[0], pair[1], 2.0),
            )
        });
    }
    let n = locking_mesh;
    for nu in [0.4, 0.45, 0.49] {
        let (tip, rest_checks) = membrane(trial, n, nu, load)?;
        checks.extend(rest_checks);
        let scaled = tip * STIFFNESS * THICKNESS / load;
        checks.push(Check::report(
            format!("locking: tip displacement at ν = {nu}, relative to ν = 1/4, {n} × {n} cells"),
            1.0,
            "the continuum changes little with ν",
            scaled / at_quarter,
        ));
    }
    Ok(checks)
}

/// The panel of n × n cells at Poisson's ratio `nu`, E = (1 − ν²) E*, under `load`: the tip's
/// vertical displacement at rest, and the check that it came to rest.
fn membrane(trial: &mut Trial, n: usize, nu: f64, load: f64) -> Result<(f64, Vec<Check>), Stop> {
    let cells = [n, n, 1];
    let mut mesh = lattice(
        cells,
        DVec3::ZERO,
        DVec3::new(1.0 / n as f64, 1.0 / n as f64, 1.0),
    );
    // The unit square onto the panel: x = 48 ξ, y = 44 ξ + η (44 − 28 ξ), in mm.
    for p in &mut mesh.positions {
        let (xi, eta) = (p.x, p.y);
        *p = DVec3::new(48.0 * xi, 44.0 * xi + eta * (44.0 - 28.0 * xi), 0.0) * 1e-3
            + DVec3::Z * p.z * THICKNESS;
    }
    let left: Vec<u32> = lattice_plane(cells, 0, 0)
        .iter()
        .map(|&i| i as u32)
        .collect();
    let right = lattice_plane(cells, 0, n);
    let tip: Vec<usize> = (0..=1).map(|k| lattice_index(cells, n, n, k)).collect();
    // The traction lumped onto the right edge: each boundary triangle carries the load in
    // proportion to its area, a third at each corner (exact for linear elements).
    let on_right = |face: &[u32; 3]| face.iter().all(|i| right.contains(&(*i as usize)));
    let faces: Vec<[u32; 3]> = mesh.surface_faces().into_iter().filter(on_right).collect();
    let area = |f: &[u32; 3]| {
        let [a, b, c] = f.map(|i| mesh.positions[i as usize]);
        (b - a).cross(c - a).length() / 2.0
    };
    let total: f64 = faces.iter().map(area).sum();
    let mut forces = vec![DVec3::ZERO; mesh.positions.len()];
    for face in &faces {
        for &i in face {
            forces[i as usize] += DVec3::Y * load * area(face) / total / 3.0;
        }
    }
    let rest = mesh.positions.clone();
    let scene = Scene {
        name: format!("Cook's membrane {n}"),
        mesh,
        pinned: left,
        notes: Vec::new(),
    };
    let material = Material {
        young: STIFFNESS * (1.0 - nu * nu),
        poisson: nu,
    };
    let shortest = (44.0 - 28.0) / n as f64 * 1e-3;
    let settings = PROTOCOL.settings(material, 0.0, shortest.min(THICKNESS));
    let mut simulation = trial.simulation(&format!("{n}-cells-nu-{nu}"), &scene, settings);
    simulation.set_plane_strain(true);
    simulation.set_forces(forces);
    let rest_state = PROTOCOL.run(trial, &mut simulation)?;
    let displacement = mean(tip.iter().map(|&i| simulation.positions()[i].y - rest[i].y));
    let check = rest_state.check(&format!("{n} × {n} cells, ν = {nu}"), &PROTOCOL, &settings);
    Ok((displacement, vec![check]))
}
