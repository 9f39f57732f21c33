//! Physics checked against theory: the validation suite (`tetlab validate`).
//!
//! Each [`Case`] builds a scene, runs it on one engine and compares what it measured with a
//! number that theory gives, as [`Check`]s: the quantity, the reference value and its source,
//! the measured value, the error, the criterion and whether it held. The cases:
//!
//! | case | what theory says | file |
//! | --- | --- | --- |
//! | `patch` | boundary on an affine map x ↦ Ax + b: every interior particle ends at Ax + b | `patch` |
//! | `hanging-bar` | a bar hanging under its weight (ν = 0) stretches by ρ g L² / (2E) | `bars` |
//! | `cantilever` | Euler–Bernoulli q L⁴ / (8EI), under refinement | `bars` |
//! | `stretch` | uniaxial stretch: lateral contraction −ν ε, then V/V₀ of the energy | `stretch` |
//! | `twist`, `compression`, `slivers` | large deformations: finite, no energy gained, recovered | `large_deformation` |
//! | `cook` | Cook's membrane: 23.96 at the tip (plane stress, E = 1, ν = 1/3, F = 1) | `cook` |
//!
//! Every static case runs XPBD with at least 4 iterations to rest under the protocol of
//! `at_rest`, which states its damping and its stop speed. [`Case::quick`] cases form the
//! subset the test command runs; the others (finer meshes, Cook's membrane) only the full suite.

mod at_rest;
mod bars;
mod cook;
pub mod discrete;
mod large_deformation;
mod patch;
mod stretch;

pub use discrete::Judged;

use crate::measures::metrics::Metrics;
use crate::scene::Scene;
use crate::simulation::divergence::Divergence;
use crate::simulation::{EngineChoice, Settings, Simulation};

/// One comparison with theory.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Check {
    /// The case it belongs to.
    pub case: &'static str,
    /// The engine it ran on: `reference` or `fast`.
    pub engine: &'static str,
    /// What was measured, with its conditions ("tip deflection, resolution 2").
    pub quantity: String,
    /// What theory gives (NaN when the row only reports).
    pub reference: f64,
    /// Where the reference comes from.
    pub source: String,
    /// What the run measured.
    pub measured: f64,
    /// The same quantity of the exact solution of the same discrete problem (the Newton
    /// reference on the same mesh, [`discrete`]), for a static case.
    pub discrete: Option<f64>,
    /// The solver's error: |measured − discrete| / |discrete|.
    pub solver_error: Option<f64>,
    /// The mesh's error: |discrete − reference| / |reference|.
    pub mesh_error: Option<f64>,
    /// Which error the criterion is on ([`Judged`]).
    pub judged: Judged,
    /// The error the criterion is on: |measured − reference| / |reference| (or the absolute
    /// error where the reference is 0), or the solver's or the mesh's ([`Check::judged`]).
    pub error: f64,
    /// What passing means ("error ≤ 1 %").
    pub criterion: String,
    /// Whether the criterion held; `None` for a row that only reports (a locking ratio).
    pub passed: Option<bool>,
}

impl Check {
    /// A row of `case` and `engine` still unnamed ([`run`] names them).
    fn row(
        quantity: impl Into<String>,
        (reference, source): (f64, impl Into<String>),
        (measured, error): (f64, f64),
        criterion: String,
        passed: Option<bool>,
    ) -> Check {
        Check {
            case: "",
            engine: "",
            quantity: quantity.into(),
            reference,
            source: source.into(),
            measured,
            discrete: None,
            solver_error: None,
            mesh_error: None,
            judged: Judged::Total,
            error,
            criterion,
            passed,
        }
    }

    /// Passes when the relative error |measured − reference| / |reference| is at most
    /// `tolerance`.
    pub fn relative(
        quantity: impl Into<String>,
        reference: f64,
        source: impl Into<String>,
        measured: f64,
        tolerance: f64,
    ) -> Check {
        let error = ((measured - reference) / reference).abs();
        let criterion = format!("relative error ≤ {}", percent(tolerance));
        Check::row(
            quantity,
            (reference, source),
            (measured, error),
            criterion,
            Some(error <= tolerance),
        )
    }

    /// Passes when |measured − reference| is at most `tolerance`.
    pub fn absolute(
        quantity: impl Into<String>,
        reference: f64,
        source: impl Into<String>,
        measured: f64,
        tolerance: f64,
    ) -> Check {
        let error = (measured - reference).abs();
        let criterion = format!("error ≤ {tolerance:.3e}");
        Check::row(
            quantity,
            (reference, source),
            (measured, error),
            criterion,
            Some(error <= tolerance),
        )
    }

    /// Passes when `measured` is at most `limit` (an upper bound theory gives: no energy
    /// gained, no tet left inverted).
    pub(crate) fn at_most(
        quantity: impl Into<String>,
        limit: f64,
        source: impl Into<String>,
        measured: f64,
    ) -> Check {
        let error = (measured - limit).max(0.0);
        let criterion = format!("≤ {limit:.4e}");
        Check::row(
            quantity,
            (limit, source),
            (measured, error),
            criterion,
            Some(measured <= limit),
        )
    }

    /// A row that reports a number and checks nothing (how far linear tets lock, say).
    pub fn report(
        quantity: impl Into<String>,
        reference: f64,
        source: impl Into<String>,
        measured: f64,
    ) -> Check {
        let error = if reference.is_finite() && reference != 0.0 {
            ((measured - reference) / reference).abs()
        } else {
            f64::NAN
        };
        Check::row(
            quantity,
            (reference, source),
            (measured, error),
            "reported".into(),
            None,
        )
    }

    /// A failed row: the run diverged or did not come to rest.
    pub fn failed(quantity: impl Into<String>, why: impl Into<String>) -> Check {
        let criterion = "the run stays finite and comes to rest".into();
        Check::row(
            quantity,
            (f64::NAN, why),
            (f64::NAN, f64::NAN),
            criterion,
            Some(false),
        )
    }
}

fn percent(fraction: f64) -> String {
    let p = fraction * 100.0;
    if p >= 1.0 {
        format!("{p:.0} %")
    } else {
        format!("{p:.2} %")
    }
}

/// What watches the runs of a case: a recording, or nothing ([`Unwatched`]).
pub trait Watch {
    /// A run starts: its label (`cantilever/reference/resolution-2`), scene and simulation.
    fn begin(&mut self, label: &str, scene: &Scene, simulation: &Simulation) {
        let _ = (label, scene, simulation);
    }
    /// A frame was stepped, and measured. False stops the case ([`Stop::Interrupted`]).
    fn frame(&mut self, simulation: &Simulation, metrics: &Metrics) -> bool {
        let _ = (simulation, metrics);
        true
    }
}

/// Why a case stopped before its end.
#[derive(Clone, Debug, PartialEq)]
pub enum Stop {
    /// A run's numbers stopped being finite: a failed case.
    Diverged(Divergence),
    /// The watcher asked to stop (Ctrl-C).
    Interrupted,
}

impl From<Divergence> for Stop {
    fn from(divergence: Divergence) -> Stop {
        Stop::Diverged(divergence)
    }
}

/// Watches nothing.
pub struct Unwatched;

impl Watch for Unwatched {}

/// What a case runs with: the engine, the fast engine's threads, and who watches.
pub struct Trial<'w> {
    /// [`EngineChoice::Reference`] or [`EngineChoice::Fast`].
    pub engine: EngineChoice,
    /// Threads for the fast engine (the results are the same bits for any count).
    pub threads: usize,
    /// Whether to run the full suite's version of the case (finer meshes).
    pub full: bool,
    case: &'static str,
    watch: &'w mut dyn Watch,
    watched: bool,
}

impl<'w> Trial<'w> {
    /// A trial on `engine`; `watch` sees every run.
    pub fn new(
        engine: EngineChoice,
        threads: usize,
        full: bool,
        watch: &'w mut dyn Watch,
    ) -> Trial<'w> {
        Trial {
            engine,
            threads,
            full,
            case: "",
            watch,
            watched: false,
        }
    }

    /// A simulation of `scene` with `settings` on this trial's engine, shown to the watcher as
    /// `case/engine/label`.
    pub fn simulation(&mut self, label: &str, scene: &Scene, settings: Settings) -> Simulation {
        let mut simulation = Simulation::new(
            scene,
            Settings {
                engine: self.engine,
                ..settings
            },
        );
        simulation.set_threads(self.threads);
        let label = format!("{}/{}/{}", self.case, self.engine.name(), slug(label));
        self.watch.begin(&label, scene, &simulation);
        self.watched = true;
        simulation
    }

    /// One frame, checked: an error when the state stopped being finite, or when the watcher
    /// asks to stop.
    pub fn step(&mut self, simulation: &mut Simulation) -> Result<Metrics, Stop> {
        simulation.step();
        let metrics = Metrics::measure_sound(simulation)?;
        if self.watched && !self.watch.frame(simulation, &metrics) {
            return Err(Stop::Interrupted);
        }
        Ok(metrics)
    }
}

/// `label` as an entity path part: letters, digits and dots, every other run of characters one
/// dash ("twisted 360°" → "twisted-360").
fn slug(label: &str) -> String {
    let mut out = String::new();
    for c in label.chars() {
        if c.is_ascii_alphanumeric() || c == '.' {
            out.push(c);
        } else if !out.ends_with('-') {
            out.push('-');
        }
    }
    out.trim_matches('-').to_owned()
}

/// One case of the suite.
pub struct Case {
    /// The name `tetlab validate NAME` runs it by.
    pub name: &'static str,
    /// What it checks, in one line.
    pub summary: &'static str,
    /// Whether the quick subset (the test command's) runs it.
    pub quick: bool,
    /// Runs it on the trial's engine.
    pub run: fn(&mut Trial) -> Result<Vec<Check>, Stop>,
}

/// Every case, in the order the suite runs them.
pub const CASES: &[Case] = &[
    patch::CASE,
    bars::HANGING_BAR,
    bars::CANTILEVER,
    stretch::CASE,
    large_deformation::TWIST,
    large_deformation::COMPRESSION,
    large_deformation::SLIVERS,
    cook::CASE,
];

/// The case of this name.
pub fn case(name: &str) -> Option<&'static Case> {
    CASES.iter().find(|c| c.name == name)
}

/// The names of every case, comma-separated (for error messages).
pub fn names() -> String {
    CASES.iter().map(|c| c.name).collect::<Vec<_>>().join(", ")
}

/// Runs `case` on `trial`'s engine: its checks, named, or one failed check when a run stopped
/// being finite; `None` when the watcher stopped it.
pub fn run(case: &'static Case, trial: &mut Trial) -> Option<Vec<Check>> {
    trial.case = case.name;
    let checks = match (case.run)(trial) {
        Ok(checks) => checks,
        Err(Stop::Diverged(divergence)) => vec![Check::failed(
            "the run stays finite",
            divergence.to_string(),
        )],
        Err(Stop::Interrupted) => return None,
    };
    let engine = trial.engine.name();
    Some(
        checks
            .into_iter()
            .map(|check| Check {
                case: case.name,
                engine,
                ..check
            })
            .collect(),
    )
}

/// The observed order of convergence between two refinements by `ratio` (2 when the cell size
/// halves): p = log(e_coarse / e_fine) / log(ratio). Positive when the error falls.
pub(crate) fn observed_order(coarse_error: f64, fine_error: f64, ratio: f64) -> f64 {
    (coarse_error / fine_error).ln() / ratio.ln()
}

#[cfg(test)]
mod examples {
    #[allow(unused_imports)]
    use super::*;

    /// The example of `observed_order`'s documentation (a unit test: the item is not exported).
    #[test]
    fn observed_order_example() {
        use crate::measures::validation::observed_order;
        // An error that falls as h²: a quarter for half the cells' size.
        assert!((observed_order(0.08, 0.02, 2.0) - 2.0).abs() < 1e-12);
    }
}
