//! Uniaxial stretch of a neo-Hookean bar five times as long as it is wide, both end faces
//! pinned in all three coordinates, no gravity.
//!
//! Half-way along, far from the pinned ends (2.5 widths: an end's disturbance dies out within
//! about a width, Saint-Venant), the bar is in uniaxial tension.
//! - At 1 % strain its lateral strain is −ν times the axial one.
//! - Beyond, the energy Ψ = μ/2 tr FᵀF + λ/2 (det F − γ)² ([`crate::constraints::material`]) gives the
//!   volume exactly. With F = diag(s, t, t) and no lateral stress,
//!   P₂₂ = μ t + λ (J − γ) J / t = 0 with J = s t², so J = γ − μ / (λ s). At s = 1 this is 1,
//!   and dJ/ds = μ/λ = 1 − 2ν, linear elasticity's volume change.

use super::at_rest::{AtRest, lattice_plane, mean};
use super::discrete::Judged;
use super::{Case, Check, Stop, Trial};
use crate::constraints::material::Material;
use crate::constraints::volume::signed_volume;
use crate::scene::{Scene, lattice};
use crate::simulation::Simulation;
use glam::DVec3;

/// The case.
pub(super) const CASE: Case = Case {
    name: "stretch",
    summary: "uniaxial stretch of a 5:1 bar: lateral contraction against ν at 1 %, V/V₀ at 50 %",
    quick: true,
    run,
};

/// At 1 % the bar's particles move up to 10⁻² m at about 0.5 m/s; at 10⁻⁷ m/s the motion left
/// is 10⁻⁵ of the lateral contraction.
const PROTOCOL: AtRest = AtRest {
    substeps: crate::simulation::DEFAULT_SUBSTEPS,
    iterations: 4,
    damping: 20.0,
    stop_speed: 1e-7,
    max_frames: 1800,
};

/// Frames over which the end is pulled from 1 % to 50 %.
const RAMP: u32 = 60;

fn run(trial: &mut Trial) -> Result<Vec<Check>, Stop> {
    let material = Material::default();
    let n = if trial.full { 4 } else { 2 };
    let cells = [5 * n, n, n];
    let (width, length) = (0.2, 1.0);
    let size = width / n as f64;
    let mesh = lattice(cells, DVec3::new(0.0, 0.5, -0.1), DVec3::splat(size));
    let plane = |i: usize| lattice_plane(cells, 0, i);
    let (left, right) = (plane(0), plane(5 * n));
    let rest = mesh.positions.clone();
    let middle_tets: Vec<usize> = (0..mesh.tets.len())
        .filter(|&t| {
            let x = mesh.tets[t]
                .iter()
                .map(|&i| rest[i as usize].x)
                .sum::<f64>()
                / 4.0;
            (x - length / 2.0).abs() < size
        })
        .collect();
    let scene = Scene {
        name: "bar 5:1".into(),
        mesh,
        pinned: left.iter().chain(&right).map(|&i| i as u32).collect(),
        notes: Vec::new(),
        bodies: Vec::new(),
    };
    let settings = PROTOCOL.settings(material, 0.0, size);
    let mut simulation = trial.simulation(&format!("resolution-{n}"), &scene, settings);
    let pull = |simulation: &mut Simulation, strain: f64| {
        for &i in &right {
            simulation.place(i, rest[i] + DVec3::X * strain * length);
        }
    };
    let middle = 5 * n / 2;
    let measure = |p: &[DVec3]| {
        let mean_x = |i: usize| mean(plane(i).iter().map(|&q| p[q].x));
        let axial = (mean_x(middle + 1) - mean_x(middle - 1)) / (2.0 * size);
        let span = |axis: usize| {
            let nodes = plane(middle);
            let values = nodes.iter().map(|&q| p[q].to_array()[axis]);
            let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            });
            hi - lo
        };
        let lateral = (span(1) + span(2)) / (2.0 * width);
        let volume = mean(middle_tets.iter().map(|&t| {
            let tet = scene.mesh.tets[t];
            signed_volume(&tet.map(|i| p[i as usize]))
                / signed_volume(&tet.map(|i| rest[i as usize]))
        }));
        (axial, lateral, volume)
    };

    let mut checks = Vec::new();
    pull(&mut simulation, 0.01);
    let small = PROTOCOL.run(trial, &mut simulation)?;
    checks.push(small.check("1 % stretch", &PROTOCOL, &settings));
    let poisson = |p: &[DVec3]| {
        let (s, t, _) = measure(p);
        (s, (1.0 - t) / (s - 1.0))
    };
    let (s, measured) = poisson(simulation.positions());
    let quantity = format!(
        "Poisson's ratio −ε_lateral / ε_axial at mid-length (axial strain {:.4})",
        s - 1.0
    );
    match &small.exact {
        Ok(exact) => checks.push(Check::three(
            quantity,
            (material.poisson, "the material's ν (small strain)"),
            (measured, poisson(exact).1),
            Some((Judged::Total, 0.02)),
        )),
        Err(why) => checks.push(Check::failed(quantity, why.clone())),
    }

    for frame in 1..=RAMP {
        pull(&mut simulation, 0.01 + 0.49 * frame as f64 / RAMP as f64);
        trial.step(&mut simulation)?;
    }
    let large = PROTOCOL.run(trial, &mut simulation)?;
    checks.push(large.check("50 % stretch", &PROTOCOL, &settings));
    let (s, _, volume) = measure(simulation.positions());
    let theory = material.gamma() - material.mu() / (material.lambda() * s);
    let quantity = format!("V/V₀ at mid-length, axial stretch {s:.4}");
    match &large.exact {
        Ok(exact) => checks.push(Check::three(
            quantity,
            (theory, "the energy's uniaxial state: J = γ − μ / (λ s)"),
            (volume, measure(exact).2),
            Some((Judged::Total, 0.01)),
        )),
        Err(why) => checks.push(Check::failed(quantity, why.clone())),
    }
    Ok(checks)
}
