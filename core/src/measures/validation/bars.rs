//! Bars under their own weight, against beam theory, under mesh refinement.
//!
//! - **Hanging bar** (ν = 0): a bar of length L hanging from its top face stretches by
//!   u(L) = ρ g L² / (2E) at its free end (the axial solution: the stress at height s above the
//!   end is ρ g s). With ν = 0 nothing contracts sideways, the 3D problem is the 1D one, and
//!   linear elements give its exact nodal values at any resolution (the 1D Green's function is
//!   piecewise linear). What is left is the neo-Hookean energy's nonlinearity, of the order of
//!   the strain ρ g L / E = 2·10⁻³.
//! - **Cantilever**: the beam scene (2 m × 0.5 m × 0.5 m, clamped at x = 0) against
//!   Euler–Bernoulli, δ = q L⁴ / (8 E I) with q = ρ g A and I = b h³ / 12, and Timoshenko's
//!   shear term q L² / (2 κ G A) (κ = 10 (1 + ν) / (12 + 11 ν), Cowper's for a rectangle), which
//!   a beam only four depths long needs: 6 % more. Linear tets lock in bending: a tet's strain is
//!   constant, so it cannot bend without shearing, and the spurious shear stiffens it. The
//!   deflection therefore converges from below, and slowly: the coarse meshes are far from the
//!   asymptotic rate of linear elements (h² for displacements).

use super::at_rest::{AtRest, courant, lattice_plane, mean};
use super::discrete::Judged;
use super::{Case, Check, Stop, Trial, observed_order};
use crate::constraints::material::Material;
use crate::scene::{Builtin, Scene, lattice};
use crate::simulation::DENSITY;
use glam::DVec3;

/// The hanging bar.
pub(super) const HANGING_BAR: Case = Case {
    name: "hanging-bar",
    summary: "a bar hanging under its weight, ν = 0, against ρ g L² / (2E), refined",
    quick: true,
    run: hanging_bar,
};

/// The cantilever.
pub(super) const CANTILEVER: Case = Case {
    name: "cantilever",
    summary: "the beam under gravity against Euler–Bernoulli and Timoshenko, refined",
    quick: true,
    run: cantilever,
};

const GRAVITY: f64 = 9.81;

/// The hanging bar's protocol. Its end moves 2 mm at about 0.15 m/s in its first mode
/// (ω = π c / 2L ≈ 78 /s): at 10⁻⁶ m/s what is left of the motion is 10⁻⁸ m, 10⁻⁵ of it.
const HANGING: AtRest = AtRest {
    substeps: crate::simulation::DEFAULT_SUBSTEPS,
    iterations: 4,
    damping: 10.0,
    stop_speed: 1e-6,
    max_frames: 1200,
};

/// The cantilever's protocol: table 14's damping; its tip swings at about 1 m/s in its first
/// mode (2 Hz), so at 10⁻⁵ m/s the motion left is 10⁻⁶ m, 10⁻⁵ of the deflection.
const BENDING: AtRest = AtRest {
    substeps: crate::simulation::DEFAULT_SUBSTEPS,
    iterations: 4,
    damping: 10.0,
    stop_speed: 1e-5,
    max_frames: 1800,
};

fn resolutions(trial: &Trial) -> &'static [usize] {
    if trial.full { &[1, 2, 4, 8] } else { &[1, 2] }
}

fn hanging_bar(trial: &mut Trial) -> Result<Vec<Check>, Stop> {
    let material = Material {
        young: 1e7,
        poisson: 0.0,
    };
    let length = 2.0;
    let theory = DENSITY * GRAVITY * length * length / (2.0 * material.young);
    let source = "axial solution ρ g L² / (2E)";
    // The largest strain, at the top: how far the neo-Hookean energy is from linear here.
    let strain = DENSITY * GRAVITY * length / material.young;
    let mut checks = Vec::new();
    let mut errors = Vec::new();
    for &n in resolutions(trial) {
        let cells = [n, 4 * n, n];
        let size = 0.5 / n as f64;
        let mesh = lattice(cells, DVec3::new(-0.25, 1.0, -0.25), DVec3::splat(size));
        let (top, bottom) = (lattice_plane(cells, 1, 4 * n), lattice_plane(cells, 1, 0));
        let rest = mesh.positions.clone();
        let scene = Scene {
            name: format!("hanging bar {n}"),
            mesh,
            pinned: top.iter().map(|&i| i as u32).collect(),
            notes: Vec::new(),
            bodies: Vec::new(),
        };
        let settings = HANGING.settings(material, GRAVITY, size);
        let mut simulation = trial.simulation(&format!("resolution-{n}"), &scene, settings);
        let rest_state = HANGING.run(trial, &mut simulation)?;
        let drop = |positions: &[DVec3]| mean(bottom.iter().map(|&i| rest[i].y - positions[i].y));
        checks.push(rest_state.check(&format!("resolution {n}"), &HANGING, &settings));
        let quantity = format!(
            "end's drop, resolution {n} ({} tets), m",
            scene.mesh.tets.len()
        );
        let exact = match &rest_state.exact {
            Ok(exact) => exact,
            Err(why) => {
                checks.push(Check::failed(quantity, why.clone()));
                continue;
            }
        };
        let (measured, discrete) = (drop(simulation.positions()), drop(exact));
        let judged = [
            (Judged::Total, 0.01),
            (Judged::Mesh, strain),
            (Judged::Solver, courant(&settings, material, size).powi(2)),
        ];
        for judged in judged {
            let check = Check::three(
                &quantity,
                (theory, source),
                (measured, discrete),
                Some(judged),
            );
            if judged.0 == Judged::Mesh {
                errors.push(check.error);
            }
            checks.push(check);
        }
    }
    for pair in errors.windows(2) {
        checks.push(Check::report(
            "observed order of the mesh's error (each refinement halves the cells)",
            f64::NAN,
            "exact nodal values for linear elements: no order to observe, the error is the energy's nonlinearity",
            observed_order(pair[0], pair[1], 2.0),
        ));
    }
    Ok(checks)
}

fn cantilever(trial: &mut Trial) -> Result<Vec<Check>, Stop> {
    let material = Material {
        young: 1e7,
        poisson: 0.3,
    };
    let (length, side): (f64, f64) = (2.0, 0.5);
    let area = side * side;
    let q = DENSITY * GRAVITY * area;
    let inertia = side.powi(4) / 12.0;
    let euler_bernoulli = q * length.powi(4) / (8.0 * material.young * inertia);
    let nu = material.poisson;
    let kappa = 10.0 * (1.0 + nu) / (12.0 + 11.0 * nu);
    let timoshenko = euler_bernoulli + q * length * length / (2.0 * kappa * material.mu() * area);
    let mut checks = Vec::new();
    let mut deflections = Vec::new();
    for &n in resolutions(trial) {
        let scene = Scene::builtin(Builtin::Beam, n as u32).expect("the beam is within limits");
        let cells = [4 * n, n, n];
        let tip = lattice_plane(cells, 0, 4 * n);
        let rest = scene.mesh.positions.clone();
        let cell = side / n as f64;
        let settings = BENDING.settings(material, GRAVITY, cell);
        let mut simulation = trial.simulation(&format!("resolution-{n}"), &scene, settings);
        let rest_state = BENDING.run(trial, &mut simulation)?;
        let deflection =
            |positions: &[DVec3]| mean(tip.iter().map(|&i| rest[i].y - positions[i].y));
        checks.push(rest_state.check(&format!("resolution {n}"), &BENDING, &settings));
        let quantity = format!(
            "tip deflection, resolution {n} ({} tets), m",
            scene.mesh.tets.len()
        );
        let exact = match &rest_state.exact {
            Ok(exact) => exact,
            Err(why) => {
                checks.push(Check::failed(quantity, why.clone()));
                return Ok(checks);
            }
        };
        let (measured, discrete) = (deflection(simulation.positions()), deflection(exact));
        checks.push(Check::three(
            &quantity,
            (euler_bernoulli, "Euler–Bernoulli q L⁴ / (8EI)"),
            (measured, discrete),
            Some((Judged::Solver, courant(&settings, material, cell).powi(2))),
        ));
        deflections.push(discrete);
    }
    for (k, pair) in deflections.windows(2).enumerate() {
        let coarse = (pair[0] - timoshenko).abs();
        let fine = (pair[1] - timoshenko).abs();
        checks.push(Check {
            criterion: "the error falls: order > 0".into(),
            passed: Some(fine < coarse),
            ..Check::report(
                format!(
                    "observed order of the mesh's error against Timoshenko, resolution {} to {}",
                    resolutions(trial)[k],
                    resolutions(trial)[k + 1]
                ),
                2.0,
                "linear elements, asymptotically",
                observed_order(coarse, fine, 2.0),
            )
        });
    }
    if let [.., a, b, c] = deflections[..] {
        // Richardson, on the exact solutions of the last three meshes (the mesh's error alone,
        // not XPBD's): the order they show, and the limit they extrapolate to. These meshes are
        // not yet asymptotic (the observed orders rise with each refinement towards linear
        // elements' 2, as the locking of the coarse meshes fades), so the order of the error
        // that remains lies between the one observed and 2, and the limit between the two
        // extrapolations: with the observed order (too far) and with 2 (not far enough).
        let p = ((b - a) / (c - b)).ln() / 2f64.ln();
        let extrapolate = |order: f64| c + (c - b) / (2f64.powf(order) - 1.0);
        let (observed, asymptotic) = (extrapolate(p), extrapolate(2.0));
        checks.push(Check::report(
            "self-convergence order of the last three meshes' exact solutions",
            2.0,
            "linear elements, asymptotically",
            p,
        ));
        checks.push(Check::report(
            "exact solutions' deflection extrapolated to zero cell size with the asymptotic order 2, m",
            timoshenko,
            "Timoshenko: Euler–Bernoulli + q L² / (2 κ G A)",
            asymptotic,
        ));
        let (low, high) = (observed.min(asymptotic), observed.max(asymptotic));
        checks.push(Check {
            criterion: format!("between the extrapolations: {low:.4} to {high:.4}"),
            passed: Some((low..=high).contains(&timoshenko)),
            ..Check::report(
                "exact solutions' deflection extrapolated to zero cell size with the observed order (Richardson), m",
                timoshenko,
                "Timoshenko: Euler–Bernoulli + q L² / (2 κ G A)",
                observed,
            )
        });
    }
    Ok(checks)
}
