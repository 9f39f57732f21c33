//! `tetlab lesson`: a lesson run headless. Each step's actions and frames run in order, its text
//! and its expected observations (checked) are printed, and with `--record` everything the lesson
//! shows is logged to a Rerun recording: the simulation, the comparison when a step shows one
//! (under `compare/`), and the text of each step (`lesson`).

use super::UsageError;
use crate::record::{ArrowsMode, Destination, Ending, Recorder, Session, send_layout};
use std::io::Write;
use std::ops::ControlFlow;
use std::path::PathBuf;
use tetlab_core::constraint_file::ConstraintFile;
use tetlab_core::simulation::EngineChoice;
use tetlab_core::teaching::lesson::{Action, BUILTIN, Lesson, LessonRun};

/// Options of `tetlab lesson`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The lesson: a number (1 is the first built-in lesson) or a lesson file (.toml).
    #[arg(value_name = "N|FILE", required_unless_present = "list")]
    lesson: Option<String>,
    /// List the built-in lessons.
    #[arg(long, conflicts_with_all = ["lesson", "record"])]
    list: bool,
    /// Record what the lesson shows to this file (.rrd).
    #[arg(long, value_name = "FILE.rrd")]
    record: Option<PathBuf>,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
    /// A constraint file whose family joins the lesson's active families; a file with the name
    /// of one the lesson brings is your answer to its exercise, and replaces it from the step
    /// that checks it; repeatable.
    #[arg(long = "constraint-file", value_name = "FILE", conflicts_with = "list")]
    constraint_files: Vec<PathBuf>,
    /// The engine instead of the lesson's: auto, reference, fast, newton or gpu, as for `tetlab
    /// run`.
    #[arg(long, value_parser = EngineChoice::parse, conflicts_with = "list")]
    engine: Option<EngineChoice>,
    /// Threads for the fast engine (1..=256) [default: every core].
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=256), conflicts_with = "list")]
    threads: Option<u64>,
    /// The neo-Hookean material instead of the lesson's: E=PA,nu=N, as for `tetlab run`.
    #[arg(long, value_name = "E=PA,nu=N", value_parser = tetlab_core::constraints::material::Material::parse, conflicts_with = "list")]
    material: Option<tetlab_core::constraints::material::Material>,
    /// Project each family's constraints in an order drawn from this seed, as for `tetlab run`
    /// [default: the mesh's order].
    #[arg(long, value_name = "S", conflicts_with = "list")]
    order_seed: Option<u64>,
    /// Let perturbations launch the body, whatever the lesson says (edits settle unless the
    /// lesson sets settle_edits = false).
    #[arg(long, conflicts_with = "list")]
    no_settle_edits: bool,
}

/// Whether every expected observation of the lesson was observed.
pub enum Outcome {
    /// All observed (or only listed).
    Observed,
    /// At least one was not; the report says which.
    NotObserved,
    /// Stopped by Ctrl-C while recording; the recording holds what ran.
    Interrupted,
}

/// Frames and seconds the lesson has run, across resets.
#[derive(Default)]
struct Clock {
    frame: u64,
    time: f64,
}

impl Clock {
    fn tick(&mut self, dt: f64) {
        self.frame += 1;
        self.time += dt;
    }
}

/// Runs (and optionally records) the lesson, printing each step and its checks to `out`.
pub fn run(args: &Args, out: &mut impl Write) -> Result<Outcome, UsageError> {
    if args.list {
        for (k, builtin) in BUILTIN.iter().enumerate() {
            let header = builtin.header().map_err(|e| UsageError(e.to_string()))?;
            let missing = header
                .missing_mesh()
                .map(|mesh| format!("; needs {mesh}, which is not there"))
                .unwrap_or_default();
            writeln!(
                out,
                "{:>2}  {}  ({}{missing})",
                k + 1,
                header.title,
                builtin.file
            )
            .map_err(UsageError::stdout)?;
        }
        return Ok(Outcome::Observed);
    }
    let spec = args.lesson.as_deref().expect("clap requires a lesson");
    let mut lesson = Lesson::find(spec).map_err(|e| UsageError(e.to_string()))?;
    if let Some(material) = args.material {
        lesson.settings.material = material;
    }
    // A file named after one of the lesson's is an answer to its exercise, taken up at the
    // exercise; any other joins the active families now.
    let mut answers = Vec::new();
    for path in &args.constraint_files {
        let files = ConstraintFile::load_all(path)
            .map_err(|e| UsageError(format!("--constraint-file {e}")))?;
        for file in files {
            if lesson
                .file_families
                .iter()
                .any(|&f| lesson.families.name(f) == file.name)
            {
                answers.push(file);
            } else {
                let family = lesson.families.register(file).map_err(|e| {
                    UsageError(format!("--constraint-file {}: {e}", path.display()))
                })?;
                lesson.settings.active.set(family, true);
            }
        }
    }
    if let Some(engine) = args.engine {
        super::simulation_args::available(engine)?;
        lesson.settings.engine = engine;
    }
    if args.order_seed.is_some() {
        lesson.settings.order_seed = args.order_seed;
    }
    if args.no_settle_edits {
        lesson.settings.settle_edits = false;
    }
    let mut run = LessonRun::new(&lesson);
    run.simulation.set_threads(args.threads.map_or_else(
        || std::thread::available_parallelism().map_or(1, |n| n.get()),
        |t| t as usize,
    ));
    for answer in answers {
        run.hand_in(&lesson, answer)
            .map_err(|e| UsageError(format!("--constraint-file {e}")))?;
    }
    super::simulation_args::warn_if_unstable(&run.simulation);
    let frames: u64 = lesson.steps.iter().map(|s| s.frames).sum();
    let compares = lesson
        .steps
        .iter()
        .flat_map(|s| &s.actions)
        .any(|a| matches!(a, Action::Compare(Some(_))));
    let session = match &args.record {
        Some(path) => {
            let destination = Destination::File {
                path: path.clone(),
                flag: "--record",
            };
            Some(Session::open(destination, frames, args.quiet)?)
        }
        None => None,
    };
    let rec = session.as_ref().map(Session::rec);
    if let Some(rec) = rec {
        let roots: &[&str] = if compares { &["", "compare/"] } else { &[""] };
        send_layout(rec, roots, &[], false, false);
    }
    // The recording's clock runs on through resets: frame k is the k-th frame the lesson ran.
    let mut clock = Clock::default();
    let mut recorder = rec.map(|rec| {
        Recorder::new(
            rec,
            "",
            run.scene(),
            &run.simulation,
            ArrowsMode::Selected,
            run.tet,
        )
    });
    let mut comparison_recorder: Option<Recorder> = None;
    run.measure().map_err(|d| UsageError(d.to_string()))?;
    if let Some(recorder) = &mut recorder {
        recorder.log_frame_at(0, 0.0, &run.simulation, run.metrics().0);
    }

    writeln!(out, "# {}", lesson.title).map_err(UsageError::stdout)?;
    let engine = format!(
        "engine {}{}{}",
        run.simulation.describe_engine(),
        super::simulation_args::describe_order(run.simulation.settings()),
        super::simulation_args::describe_settling(run.simulation.resolved())
    );
    writeln!(out, "\n{engine}").map_err(UsageError::stdout)?;
    let mut all_observed = true;
    for (k, step) in lesson.steps.iter().enumerate() {
        writeln!(
            out,
            "\n## step {} of {}\n\n{}\n",
            k + 1,
            lesson.steps.len(),
            step.text
        )
        .map_err(UsageError::stdout)?;
        if let Some(rec) = rec {
            rec.set_time_sequence("frame", clock.frame as i64);
            rec.set_duration_secs("sim_time", clock.time);
            let text = format!(
                "# {}\n\n{engine}\n\n## step {} of {}\n\n{}",
                lesson.title,
                k + 1,
                lesson.steps.len(),
                step.text
            );
            rec.log("lesson", &rerun::TextDocument::from_markdown(text))
                .ok();
        }
        let outcome = run.run_step(step, |run| {
            clock.tick(run.simulation.settings().dt);
            if let (Some(rec), Some(recorder)) = (rec, &mut recorder) {
                recorder.set_tet(run.tet);
                let (metrics, comparison_metrics) = run.metrics();
                recorder.log_frame_at(clock.frame, clock.time, &run.simulation, metrics);
                if run.comparison.is_none() && comparison_recorder.take().is_some() {
                    rec.log("compare", &rerun::Clear::recursive()).ok();
                }
                if let (Some(comparison), Some(comparison_metrics)) =
                    (&run.comparison, comparison_metrics)
                {
                    let second = comparison_recorder.get_or_insert_with(|| {
                        Recorder::new(
                            rec,
                            "compare/",
                            run.scene(),
                            comparison,
                            ArrowsMode::Selected,
                            run.tet,
                        )
                    });
                    second.set_tet(run.tet);
                    second.log_frame_at(clock.frame, clock.time, comparison, comparison_metrics);
                }
            }
            match &session {
                Some(session) if session.should_stop() => ControlFlow::Break(()),
                Some(session) => {
                    session.advance();
                    ControlFlow::Continue(())
                }
                None => ControlFlow::Continue(()),
            }
        });
        let outcome = match outcome {
            Ok(Some(outcome)) => outcome,
            Ok(None) => break,
            Err(divergence) => {
                let failure = UsageError(format!(
                    "lesson {}, step {}: {divergence}",
                    lesson.source.display(),
                    k + 1
                ));
                return Err(match session {
                    Some(session) => session.close_after(clock.frame, failure),
                    None => failure,
                });
            }
        };
        if step.frames > 0 {
            writeln!(out, "(ran {} frames)", step.frames).map_err(UsageError::stdout)?;
            for line in run.energy().lines() {
                writeln!(out, "{line}").map_err(UsageError::stdout)?;
            }
        }
        for (expectation, value, observed) in &outcome.checks {
            all_observed &= observed;
            let measured = match value {
                Some(v) => format!("measured {v}"),
                None => "no comparison is shown".to_owned(),
            };
            let verdict = if *observed {
                "observed:"
            } else {
                "NOT OBSERVED:"
            };
            writeln!(out, "{verdict} {expectation} ({measured})").map_err(UsageError::stdout)?;
        }
        // An exercise's grade: which particles held, and where a wrong one is furthest off.
        for family in step.exercises() {
            let families = run.simulation.families();
            let Some(grade) = tetlab_core::constraint_file::grade::of_family(families, family)
            else {
                continue;
            };
            for (line, _) in grade.lines() {
                writeln!(out, "  grade: {line}").map_err(UsageError::stdout)?;
            }
        }
    }
    if let Some(session) = session
        && let Ending::Interrupted = session.close(clock.frame, out)?
    {
        return Ok(Outcome::Interrupted);
    }
    Ok(if all_observed {
        Outcome::Observed
    } else {
        Outcome::NotObserved
    })
}
