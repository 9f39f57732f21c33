//! Whose error a static case's error is: the exact solution of the case's discrete problem (the
//! Newton reference's equilibrium on the same mesh, pins, loads and material,
//! [`crate::simulation::newton::equilibrium`]) stands between the engine's answer and theory's,
//! and splits their difference in two ([`Judged`]): the engine's answer against the exact
//! discrete one is the solver's error (XPBD's bias, the motion left at rest), the exact discrete
//! answer against theory is the mesh's error (the elements, the nonlinearity of the energy). A
//! check says which of the three it is on.

use super::{Check, percent};
use crate::simulation::Simulation;
use crate::simulation::newton::{Options, equilibrium};
use glam::DVec3;

/// Which error a check's criterion is on.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub enum Judged {
    /// The engine's answer against theory.
    #[default]
    Total,
    /// The engine's answer against the exact solution of the same discrete problem: the
    /// solver's error.
    Solver,
    /// The exact solution of the discrete problem against theory: the mesh's error.
    Mesh,
}

impl Judged {
    /// "the solver's error", as the criterion names it.
    pub fn name(self) -> &'static str {
        match self {
            Judged::Total => "error against theory",
            Judged::Solver => "the solver's error",
            Judged::Mesh => "the mesh's error",
        }
    }
}

/// |a − b| / |b|.
fn relative(a: f64, b: f64) -> f64 {
    ((a - b) / b).abs()
}

/// The exact solution of `simulation`'s static problem as it stands (its pins, loads and
/// material), from its current positions: the positions, or why the Newton reference could not
/// solve it to its tolerance.
pub(super) fn exact(simulation: &Simulation) -> Result<Vec<DVec3>, String> {
    let (positions, report) = equilibrium(simulation.start(), &Options::default())?;
    if report.converged {
        Ok(positions)
    } else {
        Err(format!(
            "the Newton reference stopped at a residual of {:.1e} after {} steps",
            report.residual, report.newton_iterations
        ))
    }
}

impl Check {
    /// A row with the three numbers of a static case: theory's `reference`, the engine's
    /// `measured` and the exact discrete `discrete`; `judged` says which error the criterion
    /// (relative, at most `tolerance`) is on, `None` reports all three and checks nothing.
    pub(super) fn three(
        quantity: impl Into<String>,
        (reference, source): (f64, impl Into<String>),
        (measured, discrete): (f64, f64),
        judged: Option<(Judged, f64)>,
    ) -> Check {
        let solver = relative(measured, discrete);
        let mesh = relative(discrete, reference);
        let total = relative(measured, reference);
        let (judged_by, error, criterion, passed) = match judged {
            Some((judged, tolerance)) => {
                let error = match judged {
                    Judged::Total => total,
                    Judged::Solver => solver,
                    Judged::Mesh => mesh,
                };
                let criterion = format!("{} ≤ {}", judged.name(), percent(tolerance));
                (judged, error, criterion, Some(error <= tolerance))
            }
            None => (Judged::Total, total, "reported".to_owned(), None),
        };
        Check {
            discrete: Some(discrete),
            solver_error: Some(solver),
            mesh_error: Some(mesh),
            judged: judged_by,
            ..Check::row(
                quantity,
                (reference, source),
                (measured, error),
                criterion,
                passed,
            )
        }
    }
}
