//! `tetlab check-gradients`: every family's analytic gradient against central differences on
//! seeded random configurations — the figures of `docs/gradients.md`; or, with
//! `--constraint-file`, a user's own gradient against automatic differentiation.

use super::UsageError;
use serde::Serialize;
use std::collections::BTreeMap;
use std::io::Write;
use std::path::PathBuf;
use tetlab_core::constraint_file::ConstraintFile;
use tetlab_core::constraint_file::check::{AGREEMENT, Reflection, Report, check};
use tetlab_core::constraints::Families;
use tetlab_core::constraints::verify::{CONDITIONING, random_check};

/// Options of `tetlab check-gradients`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Well-conditioned configurations to compare per family (or for the constraint file).
    #[arg(long, visible_alias = "configs", default_value_t = 10_000, value_parser = clap::value_parser!(u32).range(1..=10_000_000))]
    samples: u32,
    /// A constraint file (assets/constraints/*.toml): its own gradient against automatic
    /// differentiation and AD against central differences; exit status 1 when yours disagrees.
    #[arg(long, value_name = "FILE")]
    constraint_file: Option<PathBuf>,
    /// Seed of the random configurations.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Print one JSON object per family (one for the constraint file) instead of a table.
    #[arg(long)]
    json: bool,
}

#[derive(Serialize)]
struct Row {
    constraint: String,
    compared: usize,
    skipped_near_degenerate: usize,
    max_relative_error: f64,
    mean_relative_error: f64,
    /// The analytic gradient against automatic differentiation.
    max_error_against_automatic_differentiation: f64,
}

/// Runs the check for every family and writes one row each; or checks the constraint file.
/// `Ok(false)` when the file's gradient disagrees with automatic differentiation.
pub fn run(args: &Args, out: &mut impl Write) -> Result<bool, UsageError> {
    if let Some(path) = &args.constraint_file {
        return run_file(args, path, out);
    }
    let families = Families::builtin();
    let rows: Vec<Row> = families
        .all()
        .map(|family| {
            let r = random_check(&families, family, args.samples as usize, args.seed);
            Row {
                constraint: families.name(family).to_owned(),
                compared: r.compared,
                skipped_near_degenerate: r.skipped,
                max_relative_error: r.max_relative_error,
                mean_relative_error: r.mean_relative_error,
                max_error_against_automatic_differentiation: r.max_automatic_error,
            }
        })
        .collect();
    write(args, &rows, out).map_err(UsageError::stdout)?;
    Ok(true)
}

/// What `--constraint-file --json` prints.
#[derive(Serialize)]
struct FileOutput {
    constraint_file: String,
    name: String,
    agrees: bool,
    compared: usize,
    skipped_near_degenerate: usize,
    /// Keyed p0…; null for a particle the file gives no gradient for.
    max_relative_error: BTreeMap<String, Option<f64>>,
    worst: Option<WorstOutput>,
    automatic_vs_finite_difference: f64,
    translation_invariant: bool,
    rotation_invariant: bool,
    reflection: &'static str,
    near_degenerate: usize,
    undefined_near_degenerate: usize,
}

#[derive(Serialize)]
struct WorstOutput {
    particle: String,
    points: Vec<[f64; 3]>,
    rest: f64,
    relative_error: f64,
    command: String,
}

fn run_file(args: &Args, path: &std::path::Path, out: &mut impl Write) -> Result<bool, UsageError> {
    let file = ConstraintFile::load(path).map_err(|e| UsageError(e.to_string()))?;
    let report = check(&file, args.samples as usize, args.seed);
    if report.compared == 0 {
        return Err(UsageError(format!(
            "{}: C or its gradient is undefined at every random configuration tried",
            path.display()
        )));
    }
    let output = file_output(path, &file, &report);
    let written = if args.json {
        serde_json::to_writer(&mut *out, &output)
            .map_err(std::io::Error::from)
            .and_then(|()| writeln!(out))
    } else {
        write_file_report(args, &output, &report, out)
    };
    written.map_err(UsageError::stdout)?;
    Ok(output.agrees)
}

fn file_output(path: &std::path::Path, file: &ConstraintFile, report: &Report) -> FileOutput {
    let worst = report
        .worst
        .as_ref()
        .filter(|w| w.relative_error > AGREEMENT)
        .map(|w| WorstOutput {
            particle: format!("p{}", w.particle),
            points: w.points.iter().map(|p| p.to_array()).collect(),
            rest: w.rest,
            relative_error: w.relative_error,
            command: format!(
                "tetlab gradient --constraint-file {} --points {} --rest {:?}",
                path.display(),
                w.points
                    .iter()
                    .map(|p| format!("{:?},{:?},{:?}", p.x, p.y, p.z))
                    .collect::<Vec<_>>()
                    .join(" "),
                w.rest
            ),
        });
    FileOutput {
        constraint_file: path.display().to_string(),
        name: file.name.clone(),
        agrees: report.agrees(),
        compared: report.compared,
        skipped_near_degenerate: report.skipped,
        max_relative_error: report
            .max_relative_error
            .iter()
            .enumerate()
            .map(|(k, e)| (format!("p{k}"), *e))
            .collect(),
        worst,
        automatic_vs_finite_difference: report.automatic_vs_finite_difference,
        translation_invariant: report.translation_invariant(),
        rotation_invariant: report.rotation_invariant(),
        reflection: report.reflection.describe(),
        near_degenerate: report.near_degenerate,
        undefined_near_degenerate: report.undefined,
    }
}

fn write_file_report(
    args: &Args,
    o: &FileOutput,
    report: &Report,
    out: &mut impl Write,
) -> std::io::Result<()> {
    let yes = |b: bool| if b { "yes" } else { "no" };
    writeln!(out, "constraint file {}: {}", o.constraint_file, o.name)?;
    writeln!(
        out,
        "{} random configurations compared, seed {} ({} skipped as near-degenerate)",
        o.compared, args.seed, o.skipped_near_degenerate
    )?;
    writeln!(out)?;
    writeln!(
        out,
        "your gradient against automatic differentiation (AD), largest relative error:"
    )?;
    for (particle, error) in &o.max_relative_error {
        match error {
            Some(e) if *e <= AGREEMENT => writeln!(out, "  {particle}  {e:.2e}  agrees")?,
            Some(e) => writeln!(out, "  {particle}  {e:.2e}  WRONG")?,
            None => writeln!(out, "  {particle}  not given, not checked")?,
        }
    }
    writeln!(
        out,
        "AD against central differences: {:.2e}",
        o.automatic_vs_finite_difference
    )?;
    writeln!(
        out,
        "translation invariant (sum of the gradients = 0): {} ({:.1e})",
        yes(o.translation_invariant),
        report.translation
    )?;
    writeln!(
        out,
        "rotation invariant (sum of p x gradient = 0): {} ({:.1e})",
        yes(o.rotation_invariant),
        report.rotation
    )?;
    match report.reflection {
        Reflection::Untried => writeln!(out, "a reflection (x -> -x): {}", o.reflection)?,
        _ => writeln!(out, "a reflection (x -> -x) leaves C {}", o.reflection)?,
    }
    writeln!(
        out,
        "near-degenerate configurations: {}; C or its gradient undefined at {} (flagged, never NaN)",
        o.near_degenerate, o.undefined_near_degenerate
    )?;
    writeln!(out)?;
    match &o.worst {
        None if o.max_relative_error.values().all(Option::is_none) => writeln!(
            out,
            "the file gives no gradient: nothing of yours to check (add [gradient] p0 = \"...\")"
        ),
        None => writeln!(
            out,
            "agrees: your gradient matches AD within {AGREEMENT:.0e}"
        ),
        Some(w) => {
            writeln!(
                out,
                "DISAGREES: {} is off by {:.3} of the gradient's size; see it with\n  {}",
                w.particle, w.relative_error, w.command
            )
        }
    }
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
        "seed {}; a configuration is skipped when two points are closer than {CONDITIONING} of the \
         largest distance or a triangle of three has an angle whose sine is below {CONDITIONING}",
        args.seed
    )?;
    let w = rows.iter().map(|r| r.constraint.len()).max().unwrap_or(0) + 2;
    writeln!(
        out,
        "{:<w$}{:>10}{:>10}{:>22}{:>22}{:>16}",
        "family", "compared", "skipped", "max relative error", "mean relative error", "against AD"
    )?;
    for r in rows {
        writeln!(
            out,
            "{:<w$}{:>10}{:>10}{:>22.3e}{:>22.3e}{:>16.3e}",
            r.constraint,
            r.compared,
            r.skipped_near_degenerate,
            r.max_relative_error,
            r.mean_relative_error,
            r.max_error_against_automatic_differentiation
        )?;
    }
    writeln!(
        out,
        "(relative errors of the analytic gradient against central differences, and in the last \
         column against automatic differentiation)"
    )?;
    Ok(())
}
