//! The patch test: a block whose boundary particles are pinned on an affine map x ↦ Ax + b, with
//! no gravity. Every tet of the deformed block then has the same deformation gradient F = A, and
//! for linear tets and a homogeneous material that state is an exact equilibrium: the forces a
//! uniform stress puts on an interior particle cancel, since the faces around it close. So every
//! interior particle must end at Ax + b, up to what the solver leaves unconverged. A formula,
//! a gradient or a lumping that is wrong shows as an interior particle left off the map.

use super::at_rest::{AtRest, lattice_index};
use super::discrete::Judged;
use super::{Case, Check, Stop, Trial};
use crate::constraints::material::Material;
use crate::scene::{Scene, lattice};
use glam::{DMat3, DVec3};

/// The case.
pub(super) const CASE: Case = Case {
    name: "patch",
    summary: "neo-Hookean patch test: boundary pinned on x ↦ Ax + b, interior ends on the map",
    quick: true,
    run,
};

/// Cells along each side of the unit block.
const CELLS: usize = 4;

/// The protocol: gravity 0, the default material, damped to rest.
const PROTOCOL: AtRest = AtRest {
    substeps: crate::simulation::DEFAULT_SUBSTEPS,
    iterations: 4,
    damping: 20.0,
    stop_speed: 1e-7,
    max_frames: 1200,
};

/// The tolerance on the largest distance of an interior particle from Ax + b, in cell sizes:
/// what f32 positions (relative precision 6·10⁻⁸ on a 1 m block) and the stop speed leave,
/// with a margin of 10.
const TOLERANCE: f64 = 1e-4;

/// The affine map: a stretch, a shear and a translation, det A ≈ 1.05.
fn map() -> (DMat3, DVec3) {
    let a = DMat3::from_cols(
        DVec3::new(1.06, 0.02, -0.01),
        DVec3::new(0.03, 0.96, 0.0),
        DVec3::new(0.0, 0.04, 1.03),
    );
    (a, DVec3::new(0.05, 0.02, -0.03))
}

fn run(trial: &mut Trial) -> Result<Vec<Check>, Stop> {
    let cells = [CELLS; 3];
    let size = 1.0 / CELLS as f64;
    let mesh = lattice(cells, DVec3::ZERO, DVec3::splat(size));
    let on_boundary =
        |i: usize, j: usize, k: usize| [i, j, k].iter().any(|&c| c == 0 || c == CELLS);
    let mut boundary = Vec::new();
    let mut interior = Vec::new();
    for i in 0..=CELLS {
        for j in 0..=CELLS {
            for k in 0..=CELLS {
                let n = lattice_index(cells, i, j, k) as u32;
                if on_boundary(i, j, k) {
                    boundary.push(n);
                } else {
                    interior.push(n);
                }
            }
        }
    }
    let rest = mesh.positions.clone();
    let scene = Scene {
        name: "patch".into(),
        mesh,
        pinned: boundary.clone(),
        notes: Vec::new(),
        bodies: Vec::new(),
    };
    let settings = PROTOCOL.settings(Material::default(), 0.0, size);
    let mut simulation = trial.simulation("block", &scene, settings);
    let (a, b) = map();
    let target = |p: DVec3| a * p + b;
    for &n in &boundary {
        simulation.place(n as usize, target(rest[n as usize]));
    }
    let rest_state = PROTOCOL.run(trial, &mut simulation)?;
    let off_map = |p: &[DVec3]| {
        interior
            .iter()
            .map(|&n| p[n as usize].distance(target(rest[n as usize])))
            .fold(0.0, f64::max)
    };
    let moved = interior
        .iter()
        .map(|&n| rest[n as usize].distance(target(rest[n as usize])))
        .fold(0.0, f64::max);
    let quantity = |of: &str| {
        format!(
            "largest distance of an interior particle from Ax + b, {of}, in cells \
             ({} interior particles, moved up to {:.3} cells by the map)",
            interior.len(),
            moved / size
        )
    };
    let source = "exact: a uniform F is an equilibrium of linear tets";
    // The exact solution of the discrete problem is Ax + b itself (the mesh's error is 0), so
    // XPBD's distance from it is the solver's error.
    let mesh = match &rest_state.exact {
        Ok(exact) => Check {
            judged: Judged::Mesh,
            criterion: format!("the mesh's error ≤ {TOLERANCE:.3e}"),
            ..Check::absolute(
                quantity("the exact solution"),
                0.0,
                source,
                off_map(exact) / size,
                TOLERANCE,
            )
        },
        Err(why) => Check::failed(quantity("the exact solution"), why.clone()),
    };
    Ok(vec![
        rest_state.check("patch", &PROTOCOL, &settings),
        mesh,
        Check {
            judged: Judged::Solver,
            criterion: format!("the solver's error ≤ {TOLERANCE:.3e}"),
            ..Check::absolute(
                quantity("XPBD"),
                0.0,
                source,
                off_map(simulation.positions()) / size,
                TOLERANCE,
            )
        },
    ])
}
