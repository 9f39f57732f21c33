//! `tetlab check-gradients`: every family's analytic gradient against central differences on
//! seeded random configurations — the figures of `docs/gradients.md`.

use super::UsageError;
use serde::Serialize;
use std::io::Write;
use tetlab_core::constraints::Family;
use tetlab_core::verify::{CONDITIONING, random_check};

/// Options of `tetlab check-gradients`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Well-conditioned configurations to compare per family.
    #[arg(long, default_value_t = 10_000, value_parser = clap::value_parser!(u32).range(1..=10_000_000))]
    samples: u32,
    /// Seed of the random configurations.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Print one JSON object per family instead of a table.
    #[arg(long)]
    json: bool,
}

#[derive(Serialize)]
struct Row {
    constraint: &'static str,
    compared: usize,
    skipped_near_degenerate: usize,
    max_relative_error: f64,
    mean_relative_error: f64,
}

/// Runs the check for every family and writes one row each.
pub fn run(args: &Args, out: &mut impl Write) -> Result<(), UsageError> {
    let rows: Vec<Row> = Family::all()
        .map(|family| {
            let r = random_check(family, args.samples as usize, args.seed);
            Row {
                constraint: family.name(),
                compared: r.compared,
                skipped_near_degenerate: r.skipped,
                max_relative_error: r.max_relative_error,
                mean_relative_error: r.mean_relative_error,
            }
        })
        .collect();
    write(args, &rows, out).map_err(UsageError::stdout)
}

fn write(args: &Args, rows: &[Row], out: &mut impl Write) -> std::io::Result<()> {
    if args.json {
        for row in rows {
            serde_json::to_writer(&mut *out, row)?;
            writeln!(out)?;
        }
        return Ok(());
    }
    writeln!(
        out,
        "seed {}; a configuration is skipped when an edge is shorter than {CONDITIONING} of the \
         longest or (height) the face's edges meet at a sine below {CONDITIONING}",
        args.seed
    )?;
    let w = rows.iter().map(|r| r.constraint.len()).max().unwrap_or(0) + 2;
    writeln!(
        out,
        "{:<w$}{:>10}{:>10}{:>22}{:>22}",
        "family", "compared", "skipped", "max relative error", "mean relative error"
    )?;
    for r in rows {
        writeln!(
            out,
            "{:<w$}{:>10}{:>10}{:>22.3e}{:>22.3e}",
            r.constraint,
            r.compared,
            r.skipped_near_degenerate,
            r.max_relative_error,
            r.mean_relative_error
        )?;
    }
    Ok(())
}
