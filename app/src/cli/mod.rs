//! Argument parsing and dispatch for the `tetlab` subcommands.
//!
//! Every error a user can cause ends here as one line on stderr naming the offending input, and
//! exit status 2; nothing is written to stdout.

mod args;
mod bench;
mod check_gradients;
mod gradient;
#[cfg(not(target_arch = "wasm32"))]
mod inspect;
#[cfg(not(target_arch = "wasm32"))]
mod lesson;
mod modes;
#[cfg(not(target_arch = "wasm32"))]
mod record;
mod run;
mod simulation_args;
#[cfg(not(target_arch = "wasm32"))]
mod validate;
mod workbench_frame;

use clap::{Parser, Subcommand};
use std::io::Write;
use std::process::ExitCode;

/// tetlab: a workbench for position-based dynamics on tetrahedra. Without a subcommand it opens
/// the interactive workbench.
#[derive(Debug, Parser)]
#[command(name = "tetlab", version, about, propagate_version = true)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Evaluate one constraint (a family or a constraint file) and its gradient at given points,
    /// checked by finite differences.
    Gradient(gradient::Args),
    /// Compare every analytic gradient with central differences and automatic differentiation
    /// on random configurations, or check your own (--constraint-file).
    CheckGradients(check_gradients::Args),
    /// The energy of some families on one tet, its Hessian (checked) and its eigenmodes: classes,
    /// projection, frequencies, eigenvectors.
    Modes(modes::Args),
    /// Run a scene headless and print its metrics per frame (--json) or a summary.
    Run(run::Args),
    /// Time the solver on a scene: projections, ns per projection, frames per second, memory.
    Bench(bench::Args),
    /// Run a scene headless and log it to a Rerun recording (.rrd) or a running viewer.
    #[cfg(not(target_arch = "wasm32"))]
    Record(record::Args),
    /// Summarise a Rerun recording: entities, frames, metrics.
    #[cfg(not(target_arch = "wasm32"))]
    Inspect(inspect::Args),
    /// Run a lesson headless: its steps, their text and checked observations (--record to log it).
    #[cfg(not(target_arch = "wasm32"))]
    Lesson(lesson::Args),
    /// Check the physics against theory: patch test, bars against beam theory, stretch, large
    /// deformations, Cook's membrane, on both engines (exit 1 when a check fails).
    #[cfg(not(target_arch = "wasm32"))]
    Validate(validate::Args),
}

/// An error caused by the user's input: printed as `error: <message>`, exit status 2.
#[derive(Debug)]
pub struct UsageError(pub String);

impl UsageError {
    /// Writing to stdout failed. A closed pipe (`tetlab run --json | head`) is not an error: the
    /// reader has all it wanted, so [`main`] exits quietly.
    pub fn stdout(error: std::io::Error) -> UsageError {
        if error.kind() == std::io::ErrorKind::BrokenPipe {
            UsageError(String::new())
        } else {
            UsageError(format!("stdout: {error}"))
        }
    }
}

/// Parses the command line, runs the subcommand and turns its outcome into an exit status.
pub fn main() -> ExitCode {
    let argv = args::attach_values(
        args::attach_values(std::env::args_os(), "--points"),
        "--rest-shape",
    );
    let cli = match Cli::try_parse_from(argv) {
        Ok(cli) => cli,
        Err(err) => return report_clap_error(err),
    };
    let mut stdout = std::io::stdout().lock();
    let mut success = ExitCode::SUCCESS;
    let Some(command) = cli.command else {
        return match crate::gui::run_native() {
            Ok(()) => ExitCode::SUCCESS,
            Err(message) => {
                eprintln!("error: the workbench could not start: {message}");
                ExitCode::FAILURE
            }
        };
    };
    let outcome = match command {
        Command::Gradient(args) => gradient::run(&args, &mut stdout),
        Command::CheckGradients(args) => check_gradients::run(&args, &mut stdout).map(|agrees| {
            if !agrees {
                success = ExitCode::FAILURE;
            }
        }),
        Command::Modes(args) => modes::run(&args, &mut stdout),
        Command::Run(args) => run::run(&args, &mut stdout),
        Command::Bench(args) => bench::run(&args, &mut stdout),
        #[cfg(not(target_arch = "wasm32"))]
        Command::Record(args) => record::main(&args, &mut stdout).map(|ending| {
            if let crate::record::Ending::Interrupted = ending {
                success = ExitCode::from(crate::record::INTERRUPTED);
            }
        }),
        #[cfg(not(target_arch = "wasm32"))]
        Command::Inspect(args) => inspect::run(&args, &mut stdout),
        #[cfg(not(target_arch = "wasm32"))]
        Command::Lesson(args) => lesson::run(&args, &mut stdout).map(|outcome| match outcome {
            lesson::Outcome::Observed => {}
            lesson::Outcome::NotObserved => success = ExitCode::FAILURE,
            lesson::Outcome::Interrupted => success = ExitCode::from(crate::record::INTERRUPTED),
        }),
        #[cfg(not(target_arch = "wasm32"))]
        Command::Validate(args) => {
            validate::main(&args, &mut stdout).map(|outcome| match outcome {
                validate::Outcome::Passed => {}
                validate::Outcome::Failed => success = ExitCode::FAILURE,
                validate::Outcome::Interrupted => {
                    success = ExitCode::from(crate::record::INTERRUPTED)
                }
            })
        }
    };
    let flushed = outcome.and_then(|()| stdout.flush().map_err(UsageError::stdout));
    match flushed {
        Ok(()) => success,
        Err(UsageError(message)) if message.is_empty() => success,
        Err(UsageError(message)) => {
            eprintln!("error: {message}");
            ExitCode::from(2)
        }
    }
}

/// Help and version go to stdout with status 0; a parse error becomes one line on stderr.
fn report_clap_error(err: clap::Error) -> ExitCode {
    use clap::error::ErrorKind;
    match err.kind() {
        ErrorKind::DisplayHelp
        | ErrorKind::DisplayVersion
        | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
            // Printing help can only fail if stdout is gone; there is nobody left to tell.
            let _ = err.print();
            if err.kind() == ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand {
                ExitCode::from(2)
            } else {
                ExitCode::SUCCESS
            }
        }
        _ => {
            // clap's first paragraph says what is wrong and names the argument, sometimes on a
            // second line ("required arguments were not provided:\n  --constraint <..>").
            let rendered = err.render().to_string();
            let first_paragraph = rendered.split("\n\n").next().unwrap_or_default();
            let one_line: Vec<&str> = first_paragraph.split_whitespace().collect();
            eprintln!("{} (see --help)", one_line.join(" "));
            ExitCode::from(2)
        }
    }
}
