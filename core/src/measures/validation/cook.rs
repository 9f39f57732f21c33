//! Cook's membrane (Cook 1974): a tapered panel with corners (0, 0), (48, 44), (48, 60) and
//! (0, 44), clamped on its left edge and sheared by a uniform vertical traction on its right
//! edge. The reference is the vertical displacement of the loaded edge's midpoint (48, 52):
//! 23.96 for E = 1, ν = 1/3, a total load F = 1 and thickness 1 in plane stress, the converged
//! value of Cook, Malkus & Plesha, *Concepts and Applications of Finite Element Analysis*
//! (3rd ed., 1989, §6.13), also Bergan & Felippa 1985 (23.9). (Quadratic tets on this lattice
//! converge to 23.95 there, and to about 25.2 at the upper corner (48, 60), which is not the
//! reference's point.) It is a bending problem on a skewed mesh, where low-order elements lock
//! in shear.
//!
//! Each mesh's answer comes with the exact solution of its discrete problem (the Newton
//! reference, [`super::discrete`]): XPBD against it is the solver's error, it against 23.96 the
//! mesh's. The observed order and the locking rows are the mesh's, from the exact solutions;
//! XPBD's answers beside them show its bias, largest here, where the substep sits at the
//! material's stability bound.
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
//! rows report the displacement relative to the ν = 1/4 solution on the same mesh.

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

/// The reference: u_y at the loaded edge's midpoint × E* t / F.
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
    let scaled = |u: f64| u * STIFFNESS * THICKNESS / load;
    let mut checks = Vec::new();
    let mut errors = Vec::new();
    let resolutions = [4usize, 8, 16];
    let locking_mesh = 8;
    let mut at_quarter = None;
    for &n in &resolutions {
        let (answer, rest_checks) = membrane(trial, n, 0.25, load)?;
        checks.extend(rest_checks);
        let Some(answer) = answer else { continue };
        let (measured, discrete) = (scaled(answer.measured), scaled(answer.discrete));
        let quantity =
            format!("midpoint displacement × E* t / F, {n} × {n} cells, ν = 1/4 (ν* = 1/3)");
        let source = "Cook, Malkus & Plesha 1989, §6.13, at (48, 52)";
        // Reported: the substep sits at the material's stability bound (a Courant number near
        // 1), where XPBD's bias bounds nothing; the mesh's error is what is checked, below.
        let report = Check::three(&quantity, (REFERENCE, source), (measured, discrete), None);
        errors.push(report.mesh_error.unwrap_or(f64::NAN));
        checks.push(report);
        if n == locking_mesh {
            at_quarter = Some((measured, discrete));
        }
    }
    for (k, pair) in errors.windows(2).enumerate() {
        checks.push(Check {
            criterion: "the mesh's error falls: order > 0".into(),
            passed: Some(pair[1] < pair[0]),
            ..Check::report(
                format!(
                    "observed order of the mesh's error, {} to {} cells a side",
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
    let Some((measured_quarter, discrete_quarter)) = at_quarter else {
        return Ok(checks);
    };
    for nu in [0.4, 0.45, 0.49] {
        let (answer, rest_checks) = membrane(trial, n, nu, load)?;
        checks.extend(rest_checks);
        let Some(answer) = answer else { continue };
        checks.push(Check::three(
            format!(
                "locking: midpoint displacement at ν = {nu}, relative to ν = 1/4, {n} × {n} cells"
            ),
            (1.0, "the continuum changes little with ν"),
            (
                scaled(answer.measured) / measured_quarter,
                scaled(answer.discrete) / discrete_quarter,
            ),
            None,
        ));
    }
    Ok(checks)
}

/// A membrane's answer: the midpoint's vertical displacement by XPBD and in the exact solution
/// of the same discrete problem.
struct Answer {
    measured: f64,
    discrete: f64,
}

/// The panel of n × n cells (n even) at Poisson's ratio `nu`, E = (1 − ν²) E*, under `load`:
/// the loaded edge's midpoint's vertical displacement at rest and in the exact solution, and
/// the check that the run came to rest (and, with no answer, a failed check where the exact
/// solution could not be had).
fn membrane(
    trial: &mut Trial,
    n: usize,
    nu: f64,
    load: f64,
) -> Result<(Option<Answer>, Vec<Check>), Stop> {
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
    // The loaded edge's midpoint, (48, 52) mm: η = ½ on the right edge.
    let tip: Vec<usize> = (0..=1).map(|k| lattice_index(cells, n, n / 2, k)).collect();
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
        bodies: Vec::new(),
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
    let displacement = |x: &[DVec3]| mean(tip.iter().map(|&i| x[i].y - rest[i].y));
    let check = rest_state.check(&format!("{n} × {n} cells, ν = {nu}"), &PROTOCOL, &settings);
    let exact = match &rest_state.exact {
        Ok(exact) => exact,
        Err(why) => {
            let quantity = format!("{n} × {n} cells, ν = {nu}: the exact solution");
            return Ok((None, vec![check, Check::failed(quantity, why.clone())]));
        }
    };
    let answer = Answer {
        measured: displacement(simulation.positions()),
        discrete: displacement(exact),
    };
    Ok((Some(answer), vec![check]))
}
