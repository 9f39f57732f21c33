//! `tetlab validate`: the physics against theory ([`tetlab_core::measures::validation`]). Each case runs on
//! the reference engine and on the fast one; the checks go to stdout as a Markdown table, to a
//! JSON file with `--json`, and every run to a Rerun recording with `--record`. Exit status 0
//! when every check passes, 1 when one fails.

use super::UsageError;
use crate::record::{ArrowsMode, Destination, Recorder, Session};
use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;
use tetlab_core::measures::metrics::Metrics;
use tetlab_core::measures::validation::{self, Case, Check, Judged, Trial, Unwatched, Watch};
use tetlab_core::scene::Scene;
use tetlab_core::simulation::{EngineChoice, Simulation};

/// Options of `tetlab validate`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Run only this case (patch, hanging-bar, cantilever, stretch, twist, compression,
    /// slivers, cook). Without it: every case of the quick subset, or of the full suite with
    /// --full.
    case: Option<String>,
    /// The full suite: finer meshes, and the cases the quick subset leaves out (cook).
    #[arg(long)]
    full: bool,
    /// The engines to run on: both position-based ones (the default), reference, fast, or newton
    /// (whose answer at rest is the exact one, by construction).
    #[arg(long, default_value = "both", value_name = "ENGINE")]
    engine: String,
    /// Threads for the fast engine (1..=256; the same bits for any count) [default: every core].
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=256))]
    threads: Option<u64>,
    /// Also write the checks to this file as JSON.
    #[arg(long, value_name = "FILE.json")]
    json: Option<PathBuf>,
    /// Log every run to this Rerun recording, each under its own entity root.
    #[arg(long, value_name = "FILE.rrd")]
    record: Option<PathBuf>,
    /// List the cases and exit.
    #[arg(long)]
    list: bool,
}

/// How the suite ended.
pub enum Outcome {
    /// Every check passed.
    Passed,
    /// Some check failed.
    Failed,
    /// Ctrl-C stopped it.
    Interrupted,
}

/// Sets up (cases, engines, the recording), runs with [`run`], and reports.
pub fn main(args: &Args, out: &mut impl Write) -> Result<Outcome, UsageError> {
    if args.list {
        for case in validation::CASES {
            let subset = if case.quick { "quick, full" } else { "full" };
            writeln!(out, "{:<12} {} ({subset})", case.name, case.summary)
                .map_err(UsageError::stdout)?;
        }
        return Ok(Outcome::Passed);
    }
    let cases: Vec<&'static Case> = match &args.case {
        Some(name) => vec![validation::case(name).ok_or_else(|| {
            UsageError(format!(
                "'{name}' is not a validation case: expected one of {}",
                validation::names()
            ))
        })?],
        None => validation::CASES
            .iter()
            .filter(|c| args.full || c.quick)
            .collect(),
    };
    let engines = match args.engine.as_str() {
        "both" => EngineChoice::position_based().collect(),
        other => match EngineChoice::parse(other) {
            Ok(engine) if engine != EngineChoice::Auto => {
                super::simulation_args::available(engine)?;
                vec![engine]
            }
            _ => {
                let names: Vec<&str> = EngineChoice::engines().map(|e| e.name()).collect();
                return Err(UsageError(format!(
                    "--engine: '{other}' is not an engine to validate: expected both, {}",
                    names.join(", ")
                )));
            }
        },
    };
    if let Some(path) = &args.json {
        // Fail now, not after the suite ran, when the file cannot be written.
        std::fs::write(path, "")
            .map_err(|e| UsageError(format!("--json {}: {e}", path.display())))?;
    }
    let threads = args.threads.map_or_else(
        || std::thread::available_parallelism().map_or(1, |n| n.get()),
        |n| n as usize,
    );
    let session = match &args.record {
        Some(path) => Some(Session::open(
            Destination::File {
                path: path.clone(),
                flag: "--record",
            },
            0,
            true,
        )?),
        None => None,
    };
    let started = Instant::now();
    let mut watch = session.as_ref().map(Recording::new);
    let checks = {
        let watch: &mut dyn Watch = match &mut watch {
            Some(recording) => recording,
            None => &mut Unwatched,
        };
        run(&cases, &engines, threads, args.full, watch)
    };
    let last_frame = watch.as_ref().map_or(0, |w| w.last_frame);
    drop(watch);
    let seconds = started.elapsed().as_secs_f64();
    let interrupted = checks.is_none();
    let checks = checks.unwrap_or_default();
    write_table(&checks, out).map_err(UsageError::stdout)?;
    let passed = checks.iter().filter(|c| c.passed == Some(true)).count();
    let failed = checks.iter().filter(|c| c.passed == Some(false)).count();
    writeln!(
        out,
        "\n{passed} checks passed, {failed} failed, {} reported, in {seconds:.0} s",
        checks.len() - passed - failed
    )
    .map_err(UsageError::stdout)?;
    if let Some(path) = &args.json {
        let document = serde_json::json!({
            "suite": if args.full { "full" } else { "quick" },
            "seconds": seconds,
            "passed": failed == 0 && !interrupted,
            "checks": checks,
        });
        let text = serde_json::to_string_pretty(&document).expect("checks serialise");
        std::fs::write(path, text + "\n")
            .map_err(|e| UsageError(format!("--json {}: {e}", path.display())))?;
    }
    if let Some(session) = session {
        session.close(last_frame, out)?;
    }
    Ok(if interrupted {
        Outcome::Interrupted
    } else if failed == 0 {
        Outcome::Passed
    } else {
        Outcome::Failed
    })
}

/// Every case on every engine: the checks, or `None` when Ctrl-C stopped the suite.
fn run(
    cases: &[&'static Case],
    engines: &[EngineChoice],
    threads: usize,
    full: bool,
    watch: &mut dyn Watch,
) -> Option<Vec<Check>> {
    let mut checks = Vec::new();
    for case in cases {
        for &engine in engines {
            let mut trial = Trial::new(engine, threads, full, watch);
            checks.extend(validation::run(case, &mut trial)?);
        }
    }
    Some(checks)
}

/// The checks as a Markdown table: for a static case the engine's answer, the exact solution of
/// the same discrete problem and theory's, and the three errors between them; the criterion
/// names the one it is on.
fn write_table(checks: &[Check], out: &mut impl Write) -> std::io::Result<()> {
    writeln!(
        out,
        "| case | engine | quantity | theory | source | exact on the mesh | measured | solver's error | mesh's error | against theory | criterion | result |"
    )?;
    writeln!(
        out,
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"
    )?;
    let maybe = |x: Option<f64>| x.map_or("—".to_owned(), number);
    for c in checks {
        let result = match c.passed {
            Some(true) => "pass",
            Some(false) => "**FAIL**",
            None => "—",
        };
        let total = match (c.discrete, c.judged) {
            (Some(_), _) | (None, Judged::Total) => {
                if c.discrete.is_some() && c.reference.is_finite() {
                    number(((c.measured - c.reference) / c.reference).abs())
                } else {
                    number(c.error)
                }
            }
            _ => "—".to_owned(),
        };
        writeln!(
            out,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {total} | {} | {result} |",
            c.case,
            c.engine,
            c.quantity,
            number(c.reference),
            c.source,
            maybe(c.discrete),
            number(c.measured),
            maybe(c.solver_error),
            maybe(c.mesh_error),
            c.criterion
        )?;
    }
    Ok(())
}

/// Four significant digits, or "—" for a number that is not one.
fn number(x: f64) -> String {
    if !x.is_finite() {
        "—".into()
    } else if x == 0.0 {
        "0".into()
    } else if (1e-3..1e4).contains(&x.abs()) {
        let digits = (3 - x.abs().log10().floor() as i32).max(0) as usize;
        format!("{x:.digits$}")
    } else {
        format!("{x:.3e}")
    }
}

/// Every run logged to a recording, under `case/engine/run/`.
struct Recording<'s> {
    session: &'s Session,
    recorder: Option<Recorder<'s>>,
    last_frame: u64,
}

impl<'s> Recording<'s> {
    fn new(session: &'s Session) -> Recording<'s> {
        Recording {
            session,
            recorder: None,
            last_frame: 0,
        }
    }
}

impl Watch for Recording<'_> {
    fn begin(&mut self, label: &str, scene: &Scene, simulation: &Simulation) {
        let root = format!("{label}/");
        let mut recorder = Recorder::new(
            self.session.rec(),
            &root,
            scene,
            simulation,
            ArrowsMode::None,
            0,
        );
        recorder.log_frame(simulation, &Metrics::measure(simulation));
        self.recorder = Some(recorder);
    }

    fn frame(&mut self, simulation: &Simulation, metrics: &Metrics) -> bool {
        if let Some(recorder) = &mut self.recorder {
            recorder.log_frame(simulation, metrics);
        }
        self.last_frame = self.last_frame.max(simulation.frame());
        !self.session.should_stop()
    }
}
